/*
 * bvhlab — validation of a built tree: structural checks, then sampled rays
 * compared with brute force.
 *
 * The structural check must survive any tree a buggy builder can emit:
 * indices out of range, cycles, shared children, garbage counts. It walks
 * the tree with an explicit stack and a visited bitmap, so it neither loops
 * nor recurses on a malicious tree, and it is O(nodes + primitives).
 * The first problem found is reported, naming the node (and primitive).
 */
#include <errno.h>
#include <inttypes.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include <bvhlab/trace.h>
#include <bvhlab/tree.h>

#include "exec/exec.h"
#include "tree/tree_view.h"
#include "tree/validate_clip.h"
#include "util/util.h"

#define NONE UINT32_MAX

/* Work (rays * triangles) above which the ray check uses threads. */
#define THREAD_WORK (1u << 22)
#define MAX_THREADS 64

typedef struct vstate {
	const bvhlab_tree *tree;
	const bvhlab_build_input *input;
	bool allow_duplicates;
	bvhlab_error *err;
	uint64_t *visited;   /* bitmap over nodes */
	uint32_t *stack;     /* every node is pushed at most once: node_count entries */
	uint32_t sp;
	uint32_t reached;
	uint32_t *slot_leaf; /* leaf using each prim_index slot, or NONE */
	uint32_t *prim_leaf; /* first leaf referencing each primitive, or NONE */
} vstate;

#define FAIL(st, ...) \
	(snprintf((st)->err->message, sizeof((st)->err->message), __VA_ARGS__), -EINVAL)

static int check_counts(vstate *st)
{
	const bvhlab_tree *t = st->tree;

	if (t->node_count == 0)
		return FAIL(st, "tree has no nodes (node_count 0): did build() set "
		            "output->node_count?");
	if (t->node_count > t->node_capacity)
		return FAIL(st, "node_count %" PRIu32 " exceeds node_capacity %" PRIu32,
		            t->node_count, t->node_capacity);
	if (t->index_count > t->index_capacity)
		return FAIL(st, "index_count %" PRIu32 " exceeds index_capacity %" PRIu32,
		            t->index_count, t->index_capacity);
	if (t->width == 1 || t->width > BVHLAB_MAX_WIDTH)
		return FAIL(st, "width %" PRIu32 " outside 2 .. %d (output->width)", t->width,
		            BVHLAB_MAX_WIDTH);
	return 0;
}

/* Scene coordinates are finite (the loaders refuse others), so a box with
 * NaN or an infinite bound is the builder's doing; it also makes every
 * surface area, and so the SAH cost, NaN. */
static bool non_finite(const float *lo, const float *hi)
{
	int k;

	for (k = 0; k < 3; k++)
		if (!isfinite(lo[k]) || !isfinite(hi[k]))
			return true;
	return false;
}

/* Exact comparison on purpose: builders must produce conservative boxes.
 * The first axis on which the child sticks out, or -1. */
static int outside_axis(const bvhlab_node *n, const float *lo, const float *hi)
{
	for (int k = 0; k < 3; k++)
		if (!(n->lo[k] <= lo[k] && hi[k] <= n->hi[k]))
			return k;
	return -1;
}

static bool test_and_set(uint64_t *bitmap, uint32_t i)
{
	uint64_t bit = (uint64_t)1 << (i & 63);
	bool was = bitmap[i >> 6] & bit;

	bitmap[i >> 6] |= bit;
	return was;
}

/* Marks a node reached (from `parent`, NONE for the root) and queues it. */
static int reach(vstate *st, uint32_t node, uint32_t parent)
{
	const bvhlab_node *n = &st->tree->nodes[node];

	if (test_and_set(st->visited, node))
		return FAIL(st, "node %" PRIu32 " reachable twice (cycle or shared child; "
		            "again from node %" PRIu32 ")", node, parent);
	if (non_finite(n->lo, n->hi))
		return FAIL(st, "node %" PRIu32 ": box has NaN or an infinite bound", node);
	int k = parent == NONE ? -1 : outside_axis(&st->tree->nodes[parent], n->lo, n->hi);
	if (k >= 0) {
		/* The bounds, so that a rounding slip (a few ulps) reads apart
		 * from a wrong box. */
		const bvhlab_node *p = &st->tree->nodes[parent];
		return FAIL(st, "node %" PRIu32 ": box does not contain child %" PRIu32 " (%c: child "
		            "[%.9g, %.9g], node [%.9g, %.9g])", parent, node, "xyz"[k],
		            (double)n->lo[k], (double)n->hi[k], (double)p->lo[k], (double)p->hi[k]);
	}
	st->stack[st->sp++] = node;
	st->reached++;
	return 0;
}

/*
 * The likely cause of a child index past the end, for the message: counts
 * a build() forgot, or a child list one short (a binary node's children
 * are the pair from nodes[first], both below node_count).
 */
static const char *child_hint(const bvhlab_tree *t, uint32_t node, uint64_t end)
{
	if (t->node_count == 1)
		return ": did build() set output->node_count to the nodes it wrote?";
	if (end == (uint64_t)t->node_count + 1)
		return ": children are consecutive from nodes[first]; is the last one counted "
		       "in node_count?";
	if (node > 0 && t->nodes[node].first < node)
		return ": an inner node's children come from 'first'; is this a leaf whose "
		       "count was left 0?";
	return ": a child index past the end (did build() count every node it wrote in "
	       "node_count?)";
}

static int check_inner(vstate *st, uint32_t node)
{
	const bvhlab_node *n = &st->tree->nodes[node];
	uint32_t k = tree_child_count(n), width = tree_width(st->tree);
	uint64_t end = tree_children_end(n);
	int rc = 0;

	if (k < 2 || k > width)
		return FAIL(st, "node %" PRIu32 ": %" PRIu32 " children in a %" PRIu32 "-wide tree "
		            "(count 0x%08" PRIx32 "; a wide inner node's count is BVHLAB_NODE_INNER "
		            "| children, 2 .. width)", node, k, width, n->count);
	if (end > st->tree->node_count)
		return FAIL(st, "node %" PRIu32 ": child index %" PRIu64 " out of range "
		            "(children %" PRIu32 " to %" PRIu64 ", node_count %" PRIu32 ")%s",
		            node, n->first >= st->tree->node_count ? n->first : end - 1, n->first,
		            end - 1, st->tree->node_count,
		            child_hint(st->tree, node, end));
	for (uint32_t i = 0; rc == 0 && i < k; i++)
		rc = reach(st, tree_child(n, i), node);
	return rc;
}

/* One prim_index slot of leaf `node`. */
static int check_slot(vstate *st, uint32_t node, uint32_t slot)
{
	const bvhlab_build_input *in = st->input;
	uint32_t prim = st->tree->prim_index[slot];
	const bvhlab_aabb *box;

	if (st->slot_leaf[slot] != NONE)
		return FAIL(st, "prim_index slot %" PRIu32 " used by two leaves (%" PRIu32
		            " and %" PRIu32 ")", slot, st->slot_leaf[slot], node);
	st->slot_leaf[slot] = node;
	if (prim >= in->prim_count)
		return FAIL(st, "node %" PRIu32 ": prim_index[%" PRIu32 "] = %" PRIu32
		            " out of range (prim_count %" PRIu32 ")", node, slot, prim, in->prim_count);
	if (st->prim_leaf[prim] != NONE && !st->allow_duplicates)
		return FAIL(st, "primitive %" PRIu32 " referenced twice (leaves %" PRIu32
		            " and %" PRIu32 ")", prim, st->prim_leaf[prim], node);
	if (st->prim_leaf[prim] == NONE)
		st->prim_leaf[prim] = node;
	box = &in->prim_bounds[prim];
	/* Spatial splits may clip a reference's box: validate_coverage judges it. */
	if (!st->allow_duplicates && outside_axis(&st->tree->nodes[node], box->lo, box->hi) >= 0)
		return FAIL(st, "node %" PRIu32 ": box does not contain primitive %" PRIu32, node,
		            prim);
	return 0;
}

/* The likely cause of a leaf range past index_count, for the message. */
static const char *leaf_hint(const bvhlab_tree *t, uint64_t end)
{
	if (t->index_count == 0)
		return ": did build() set output->index_count?";
	if (end == (uint64_t)t->index_count + 1)
		return ": a leaf range off by one? (a leaf holds prim_index[first .. first + "
		       "count), count primitives)";
	return "";
}

static int check_leaf(vstate *st, uint32_t node)
{
	const bvhlab_node *n = &st->tree->nodes[node];
	uint64_t end = (uint64_t)tree_leaf_first(n) + tree_leaf_count(n);
	uint32_t slot;
	int rc;

	/* count 0 is an inner node, so an empty leaf can only be one whose
	 * range lies (partly) outside the referenced slots. */
	if (end > st->tree->index_count)
		return FAIL(st, "node %" PRIu32 ": leaf range [%" PRIu32 ", %" PRIu64
		            ") exceeds index_count %" PRIu32 "%s", node, tree_leaf_first(n), end,
		            st->tree->index_count, leaf_hint(st->tree, end));
	for (slot = tree_leaf_first(n); slot < end; slot++) {
		rc = check_slot(st, node, slot);
		if (rc < 0)
			return rc;
	}
	return 0;
}

/* What the walk cannot see: nodes, primitives and slots nobody reached. */
static int check_leftovers(vstate *st)
{
	uint32_t i;

	if (st->reached != st->tree->node_count)
		for (i = 0; i < st->tree->node_count; i++)
			if (!(st->visited[i >> 6] & ((uint64_t)1 << (i & 63))))
				return FAIL(st, "node %" PRIu32 " is not reachable from the root "
				            "(orphan)%s", i, st->reached < st->tree->node_count / 2 ?
				            ": does node_count count more nodes than build() wrote?" : "");
	for (i = 0; i < st->input->prim_count; i++)
		if (st->prim_leaf[i] == NONE)
			return FAIL(st, "primitive %" PRIu32 " is referenced by no leaf", i);
	for (i = 0; i < st->tree->index_count; i++)
		if (st->slot_leaf[i] == NONE)
			return FAIL(st, "prim_index slot %" PRIu32 " is used by no leaf", i);
	return 0;
}

static int vstate_alloc(vstate *st)
{
	size_t words = ((size_t)st->tree->node_count + 63) / 64;

	st->visited = calloc(words, sizeof(uint64_t));
	st->stack = malloc((size_t)st->tree->node_count * sizeof(uint32_t));
	st->slot_leaf = malloc(((size_t)st->tree->index_count + 1) * sizeof(uint32_t));
	st->prim_leaf = malloc(((size_t)st->input->prim_count + 1) * sizeof(uint32_t));
	if (!st->visited || !st->stack || !st->slot_leaf || !st->prim_leaf) {
		snprintf(st->err->message, sizeof(st->err->message),
		         "out of memory validating a tree of %" PRIu32 " nodes (not checked, "
		         "so not found invalid)",
		         st->tree->node_count);
		return -ENOMEM;
	}
	memset(st->slot_leaf, 0xff, (size_t)st->tree->index_count * sizeof(uint32_t));
	memset(st->prim_leaf, 0xff, (size_t)st->input->prim_count * sizeof(uint32_t));
	return 0;
}

static void vstate_free(vstate *st)
{
	free(st->visited);
	free(st->stack);
	free(st->slot_leaf);
	free(st->prim_leaf);
}

static int walk(vstate *st)
{
	int rc = reach(st, 0, NONE);

	while (rc == 0 && st->sp > 0) {
		uint32_t node = st->stack[--st->sp];

		if (!tree_is_leaf(&st->tree->nodes[node]))
			rc = check_inner(st, node);
		else
			rc = check_leaf(st, node);
	}
	return rc;
}

int bvhlab_validate_tree(const bvhlab_tree *tree, const bvhlab_build_input *input,
                         bool allow_duplicates, bvhlab_error *err)
{
	bvhlab_error scratch;
	vstate st = { .tree = tree, .input = input, .allow_duplicates = allow_duplicates,
	              .err = err ? err : &scratch };
	int rc;

	st.err->message[0] = '\0';
	rc = check_counts(&st);
	if (rc < 0)
		return rc;
	rc = vstate_alloc(&st);
	if (rc < 0)
		goto out;
	rc = walk(&st);
	if (rc < 0)
		goto out;
	rc = check_leftovers(&st);
	if (rc == 0 && allow_duplicates)
		rc = validate_coverage(tree, input, st.slot_leaf, st.err);
out:
	vstate_free(&st);
	return rc;
}

/* ---- sampled rays --------------------------------------------------------- */

typedef struct ray_job {
	const bvhlab_tree *tree;
	const bvhlab_scene *scene;
	uint64_t seed;
	float center[3];
	float radius;
	float lo[3], size[3]; /* the box targets are drawn from */
	uint64_t mismatches[EXEC_MAX_MEMBERS]; /* per member of the team */
} ray_job;

static float uniform(uint64_t *state)
{
	return (float)(util_splitmix64(state) >> 40) * 0x1p-24f;
}

static void triangle_centroid(const bvhlab_scene *scene, uint32_t tri, float out[3])
{
	const uint32_t *idx = scene->indices + 3 * (size_t)tri;
	int k;

	for (k = 0; k < 3; k++)
		out[k] = (scene->vertices[3 * (size_t)idx[0] + k] +
		          scene->vertices[3 * (size_t)idx[1] + k] +
		          scene->vertices[3 * (size_t)idx[2] + k]) / 3.0f;
}

/*
 * Ray i depends only on (seed, i), so results do not depend on threading.
 * Origins lie on a sphere around the scene; even rays aim at a random point
 * of the bounds, odd ones at a random triangle's centroid, so many hit.
 */
static void make_ray(const ray_job *job, uint32_t i, bvhlab_ray *ray)
{
	uint64_t state = job->seed ^ ((uint64_t)i * 0xd1b54a32d192ed03u);
	float z = 2.0f * uniform(&state) - 1.0f, phi = 6.28318531f * uniform(&state);
	float r = sqrtf(fmaxf(0.0f, 1.0f - z * z)), target[3];
	float dir[3] = { r * cosf(phi), r * sinf(phi), z };
	int k;

	if ((i & 1) && job->scene->triangle_count > 0) {
		triangle_centroid(job->scene,
		                  (uint32_t)(util_splitmix64(&state) % job->scene->triangle_count), target);
	} else {
		for (k = 0; k < 3; k++)
			target[k] = job->lo[k] + uniform(&state) * job->size[k];
	}
	for (k = 0; k < 3; k++) {
		ray->org[k] = job->center[k] + job->radius * dir[k];
		ray->dir[k] = target[k] - ray->org[k];
	}
	ray->tmin = 0.0f;
	ray->tmax = INFINITY;
}

static bool same_hit(const bvhlab_hit *a, const bvhlab_hit *b)
{
	double ta = a->t, tb = b->t;

	if ((a->prim == BVHLAB_NO_HIT) != (b->prim == BVHLAB_NO_HIT))
		return false;
	return a->prim == BVHLAB_NO_HIT || fabs(ta - tb) <= 1e-4 * fmax(fabs(ta), fabs(tb));
}

static void run_rays(void *arg, uint32_t lo, uint32_t hi, uint32_t member)
{
	ray_job *job = arg;
	bvhlab_ray ray;
	bvhlab_hit a, b;

	for (uint32_t i = lo; i < hi; i++) {
		make_ray(job, i, &ray);
		bvhlab_trace_closest(job->tree, job->scene, &ray, &a, NULL);
		bvhlab_trace_brute(job->scene, &ray, &b);
		if (!same_hit(&a, &b))
			job->mismatches[member]++;
	}
}

/* Sphere and target box from the scene bounds, or the root box if those are
 * unset; a point-sized scene still gets a sphere of radius 1. */
static void ray_frame(const bvhlab_tree *tree, const bvhlab_scene *scene, ray_job *job)
{
	const float *lo = scene->bounds.lo, *hi = scene->bounds.hi;
	float diag2 = 0.0f;
	int k;

	if (!(lo[0] <= hi[0] && lo[1] <= hi[1] && lo[2] <= hi[2]) && tree->node_count > 0) {
		lo = tree->nodes[0].lo;
		hi = tree->nodes[0].hi;
	}
	for (k = 0; k < 3; k++) {
		bool ok = isfinite(lo[k]) && isfinite(hi[k]) && lo[k] <= hi[k];

		job->lo[k] = ok ? lo[k] : 0.0f;
		job->size[k] = ok ? hi[k] - lo[k] : 0.0f;
		job->center[k] = job->lo[k] + 0.5f * job->size[k];
		diag2 += job->size[k] * job->size[k];
	}
	job->radius = diag2 > 0.0f ? 0.75f * sqrtf(diag2) : 1.0f;
}

/* Threads for the check: the place's CPUs (the caller's CPU set, counted
 * as builds count it), when the work is worth them. */
static uint32_t ray_threads(const struct exec_place *place, const bvhlab_scene *scene,
                            uint32_t ray_count)
{
	uint32_t cpus = exec_place_cpus(place);

	if ((uint64_t)ray_count * scene->triangle_count < THREAD_WORK || cpus <= 1)
		return 1;
	cpus = cpus < MAX_THREADS ? cpus : MAX_THREADS;
	return cpus < ray_count ? cpus : ray_count;
}

/* The rays run on the executor, placed and pinned as a build's threads
 * are; a place that cannot be had leaves the caller alone with them. */
int bvhlab_validate_rays(const bvhlab_tree *tree, const bvhlab_scene *scene,
                         uint32_t ray_count, uint64_t seed, uint64_t *mismatches,
                         bvhlab_error *err)
{
	ray_job *job = calloc(1, sizeof(*job));
	struct exec_place place;
	bool placed = exec_place_begin(&place) == 0;
	uint32_t n = placed ? ray_threads(&place, scene, ray_count) : 1;

	*mismatches = 0;
	if (!job) {
		exec_place_end(&place);
		error_set(err, "out of memory for the ray check");
		return -ENOMEM;
	}
	if (err)
		err->message[0] = '\0';
	*job = (ray_job){ .tree = tree, .scene = scene, .seed = seed };
	ray_frame(tree, scene, job);
	/* Blocks of a quarter share: a thread slowed by others takes fewer. */
	uint32_t grain = ray_count / (4 * n) > 0 ? ray_count / (4 * n) : 1;
	if (placed)
		exec_for_each(&place, n, ray_count, grain, run_rays, job);
	else
		run_rays(job, 0, ray_count, 0);
	exec_place_end(&place);
	for (uint32_t i = 0; i < n; i++)
		*mismatches += job->mismatches[i];
	free(job);
	return 0;
}
