/*
 * Two-level traversal (trace_instances.h): the top tree walked with a
 * stack, nearest child box first, or without one through its parent links
 * (the stackless traversal); at a leaf each instance's bottom tree is
 * traced by the one-level traversal (trace_ray_view: stack, stackless or
 * wide) with the ray in the instance's space and the best t so far as its
 * tmax. Carrying the ray into an instance and keeping the best hit are
 * this file's alone, whichever traversal walks either level.
 */
#include <errno.h>
#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "trace/trace_batch.h"
#include "trace/trace_instances.h"
#include "trace/trace_kernel.h"
#include "tree/tree_view.h"
#include "util/util.h"

/* Deep enough for any top tree of CONFIG_MAX_INSTANCES boxes a builder
 * makes (depth < 64 * 8); a deeper one is walked no further. */
#define TOP_STACK 512

static void inst_hit_init(const bvhlab_ray *ray, struct trace_inst_hit *out)
{
	out->hit.t = ray->tmax;
	out->hit.u = out->hit.v = 0.0f;
	out->hit.prim = BVHLAB_NO_HIT;
	out->instance = BVHLAB_NO_HIT;
}

/* The ray in instance i's space; the same t reaches the same point. */
static void local_ray(const struct scene_instance *in, const bvhlab_ray *ray, float tmax,
                      bvhlab_ray *out)
{
	double o[3] = {ray->org[0], ray->org[1], ray->org[2]};
	double d[3] = {ray->dir[0], ray->dir[1], ray->dir[2]}, lo[3], ld[3];
	scene_matrix_apply(in->inv, o, 1.0, lo);
	scene_matrix_apply(in->inv, d, 0.0, ld);
	for (int k = 0; k < 3; k++) {
		out->org[k] = (float)lo[k];
		out->dir[k] = (float)ld[k];
	}
	out->tmin = ray->tmin;
	/* One ulp further, so a hit at exactly the best t is seen and the
	 * tie can go to the smaller (instance, primitive). */
	out->tmax = nextafterf(tmax, INFINITY);
}

/* A hit h in instance i replaces the best one if nearer, or as near and
 * earlier in (instance, primitive) order. */
static void offer(struct trace_inst_hit *best, const bvhlab_hit *h, uint32_t i)
{
	if (h->prim == BVHLAB_NO_HIT || h->t > best->hit.t)
		return;
	if (h->t == best->hit.t && best->hit.prim != BVHLAB_NO_HIT &&
	    (i > best->instance || (i == best->instance && h->prim >= best->hit.prim)))
		return;
	best->hit = *h;
	best->instance = i;
}

static void enter_instance(const struct trace_two_level *tl, uint32_t i, const bvhlab_ray *ray,
                           struct trace_inst_hit *best, bvhlab_trace_stats *stats)
{
	const struct scene_instance *in = &tl->inst->instances[i];
	const bvhlab_tree *tree = &tl->bottom[in->mesh];
	struct trace_view plain = trace_view_plain(tree);
	bvhlab_trace_stats st = {0};
	bvhlab_ray r;
	bvhlab_hit h;
	if (tree->node_count == 0)
		return;
	local_ray(in, ray, best->hit.t, &r);
	trace_ray_view(tl->views ? tl->traversal : BVHLAB_TRAVERSAL_STACK, tree,
	               tl->inst->meshes[in->mesh], tl->views ? &tl->views[in->mesh] : &plain, &r,
	               false, &h, &st);
	offer(best, &h, i);
	if (stats) { /* one two-level ray, however many instances it enters */
		stats->nodes_visited += st.nodes_visited;
		stats->tris_tested += st.tris_tested;
	}
}

/* A top leaf's instances, each traced. */
static void enter_leaf(const struct trace_two_level *tl, const bvhlab_node *n,
                       const bvhlab_ray *ray, struct trace_inst_hit *best,
                       bvhlab_trace_stats *stats)
{
	const bvhlab_tree *top = tl->top;
	uint32_t first = tree_leaf_first(n), end = first + tree_leaf_count(n);
	for (uint32_t s = first; s < end && s < top->index_count; s++)
		if (top->prim_index[s] < tl->inst->instance_count)
			enter_instance(tl, top->prim_index[s], ray, best, stats);
}

/* An inner node's children the ray enters, pushed farthest first. */
static uint32_t push_children(const ray_prep *p, const bvhlab_tree *top, const bvhlab_node *n,
                              float tmax, uint32_t *stack, uint32_t sp)
{
	uint32_t k = tree_child_count(n), hit[BVHLAB_MAX_WIDTH], m = 0;
	float t[BVHLAB_MAX_WIDTH];
	for (uint32_t c = 0; c < k; c++) {
		uint32_t child = tree_child(n, c);
		float tc = child < top->node_count ? box_enter(p, &top->nodes[child], tmax) : INFINITY;
		if (tc == INFINITY)
			continue;
		uint32_t j = m++; /* insertion by entry distance, nearest last */
		for (; j > 0 && t[j - 1] < tc; j--) {
			t[j] = t[j - 1];
			hit[j] = hit[j - 1];
		}
		t[j] = tc;
		hit[j] = child;
	}
	for (uint32_t j = 0; j < m && sp < TOP_STACK; j++)
		stack[sp++] = hit[j];
	return sp;
}

static void walk_stack(const struct trace_two_level *tl, const bvhlab_ray *ray,
                       struct trace_inst_hit *out, bvhlab_trace_stats *stats)
{
	const bvhlab_tree *top = tl->top;
	uint32_t stack[TOP_STACK], sp = 0;
	ray_prep p;
	if (!prep_box(ray, &p) || box_enter(&p, &top->nodes[0], out->hit.t) == INFINITY)
		return;
	stack[sp++] = 0;
	while (sp > 0) {
		const bvhlab_node *n = &top->nodes[stack[--sp]];
		if (stats)
			stats->nodes_visited++;
		if (box_enter(&p, n, out->hit.t) == INFINITY)
			continue; /* a nearer hit came since it was pushed */
		if (!tree_is_leaf(n))
			sp = push_children(&p, top, n, out->hit.t, stack, sp);
		else
			enter_leaf(tl, n, ray, out, stats);
	}
}

/* The stackless walk's leaf: what it needs to trace the leaf's instances. */
struct top_leaf {
	const struct trace_two_level *tl;
	const bvhlab_ray *ray;
	struct trace_inst_hit *best;
	bvhlab_trace_stats *stats;
};

static bool stackless_leaf(void *ctx, const bvhlab_node *n)
{
	struct top_leaf *c = ctx;
	enter_leaf(c->tl, n, c->ray, c->best, c->stats);
	return false;
}

void trace_two_level_closest(const struct trace_two_level *tl, const bvhlab_ray *ray,
                             struct trace_inst_hit *out, bvhlab_trace_stats *stats)
{
	inst_hit_init(ray, out);
	if (tl->top->node_count == 0)
		return;
	if (tl->views && tl->traversal == BVHLAB_TRAVERSAL_STACKLESS) {
		struct top_leaf c = {tl, ray, out, stats};
		trace_walk_stackless(tl->top, tl->top_parents, ray, &out->hit, stackless_leaf, &c,
		                     stats);
	} else {
		walk_stack(tl, ray, out, stats);
	}
}

void trace_two_level_hit(const struct trace_two_level *tl, const bvhlab_ray *ray,
                         bvhlab_hit *hit, bvhlab_trace_stats *stats)
{
	struct trace_inst_hit h;
	trace_two_level_closest(tl, ray, &h, stats);
	*hit = h.hit;
	if (stats)
		stats->rays++;
}

/* Mesh m's copies for the traversal. */
static int prepare_mesh(struct trace_two_level *tl, uint32_t m)
{
	const bvhlab_tree *tree = &tl->bottom[m];
	const bvhlab_scene *mesh = tl->inst->meshes[m];
	int r = trace_view_copy(tree, mesh, &tl->views[m]);
	if (r == 0 && tl->traversal == BVHLAB_TRAVERSAL_STACKLESS) {
		r = bvhlab_tree_parents(tree, &tl->parents[m]);
		tl->views[m].parents = tl->parents[m];
	}
	if (r == 0 && trace_is_wide(tl->traversal) && tree->node_count)
		r = trace_view_wide(tree, mesh, tl->traversal, &tl->views[m]);
	return r;
}

int trace_two_level_prepare(struct trace_two_level *tl, int traversal)
{
	uint32_t meshes = tl->inst->mesh_count;
	if (traversal != BVHLAB_TRAVERSAL_STACK && traversal != BVHLAB_TRAVERSAL_STACKLESS &&
	    !trace_is_wide(traversal))
		return -EINVAL;
	tl->traversal = traversal;
	tl->views = calloc(meshes ? meshes : 1, sizeof(*tl->views));
	tl->parents = calloc(meshes ? meshes : 1, sizeof(*tl->parents));
	int r = tl->views && tl->parents ? 0 : -ENOMEM;
	if (r == 0 && traversal == BVHLAB_TRAVERSAL_STACKLESS)
		r = bvhlab_tree_parents(tl->top, &tl->top_parents);
	for (uint32_t m = 0; r == 0 && m < meshes; m++)
		r = prepare_mesh(tl, m);
	if (r < 0)
		trace_two_level_release(tl);
	return r;
}

void trace_two_level_release(struct trace_two_level *tl)
{
	for (uint32_t m = 0; tl->views && m < tl->inst->mesh_count; m++)
		trace_view_free(&tl->views[m]);
	for (uint32_t m = 0; tl->parents && m < tl->inst->mesh_count; m++)
		free(tl->parents[m]);
	free(tl->views);
	free(tl->parents);
	free(tl->top_parents);
	tl->views = NULL;
	tl->parents = NULL;
	tl->top_parents = NULL;
	tl->traversal = BVHLAB_TRAVERSAL_STACK;
}

void trace_two_level_brute(const struct scene_instanced *inst, const bvhlab_ray *ray,
                           struct trace_inst_hit *out)
{
	ray_prep p;
	inst_hit_init(ray, out);
	if (!prep_box(ray, &p))
		return;
	for (uint32_t i = 0; i < inst->instance_count; i++) {
		bvhlab_node box = {0};
		bvhlab_aabb b;
		scene_instanced_box(inst, i, &b);
		memcpy(box.lo, b.lo, sizeof(box.lo));
		memcpy(box.hi, b.hi, sizeof(box.hi));
		if (box_enter(&p, &box, out->hit.t) == INFINITY)
			continue;
		bvhlab_ray r;
		bvhlab_hit h;
		local_ray(&inst->instances[i], ray, out->hit.t, &r);
		bvhlab_trace_brute(inst->meshes[inst->instances[i].mesh], &r, &h);
		offer(out, &h, i);
	}
}

/* A float in [0, 1) from the generator's 24 high bits. */
static float uniform(uint64_t *state)
{
	return (float)(util_splitmix64(state) >> 40) * (1.0f / 16777216.0f);
}

void trace_two_level_ray(const struct scene_instanced *inst, const bvhlab_aabb *bounds,
                         uint64_t seed, uint32_t i, bvhlab_ray *ray)
{
	uint64_t state = seed ^ ((uint64_t)i * 0xd1b54a32d192ed03u);
	float z = 2.0f * uniform(&state) - 1.0f, phi = 6.28318531f * uniform(&state);
	float r = sqrtf(fmaxf(0.0f, 1.0f - z * z)), dir[3] = {r * cosf(phi), r * sinf(phi), z};
	bvhlab_aabb aim = *bounds;
	if ((i & 1) && inst->instance_count) /* odd rays at one instance, so many hit */
		scene_instanced_box(inst, (uint32_t)(util_splitmix64(&state) % inst->instance_count),
		                    &aim);
	float diag2 = 0.0f;
	for (int k = 0; k < 3; k++)
		diag2 += (bounds->hi[k] - bounds->lo[k]) * (bounds->hi[k] - bounds->lo[k]);
	float radius = diag2 > 0.0f ? 0.75f * sqrtf(diag2) : 1.0f;
	for (int k = 0; k < 3; k++) {
		float c = 0.5f * (bounds->lo[k] + bounds->hi[k]);
		float target = aim.lo[k] + uniform(&state) * (aim.hi[k] - aim.lo[k]);
		ray->org[k] = c + radius * dir[k];
		ray->dir[k] = target - ray->org[k];
	}
	ray->tmin = 0.0f;
	ray->tmax = INFINITY;
}

static bool same_as_flat(const struct trace_inst_hit *a, const bvhlab_hit *b)
{
	double ta = a->hit.t, tb = b->t;
	if ((a->hit.prim == BVHLAB_NO_HIT) != (b->prim == BVHLAB_NO_HIT))
		return false;
	return b->prim == BVHLAB_NO_HIT || fabs(ta - tb) <= 1e-4 * fmax(fabs(ta), fabs(tb));
}

void trace_two_level_check(const struct trace_two_level *tl, const bvhlab_scene *flat,
                           uint32_t count, uint64_t seed, uint64_t *mismatches,
                           uint64_t *flat_mismatches)
{
	bvhlab_aabb bounds;
	const bvhlab_node *root = &tl->top->nodes[0];
	memcpy(bounds.lo, root->lo, sizeof(bounds.lo));
	memcpy(bounds.hi, root->hi, sizeof(bounds.hi));
	*mismatches = 0;
	if (flat_mismatches)
		*flat_mismatches = 0;
	for (uint32_t i = 0; i < count; i++) {
		bvhlab_ray ray;
		struct trace_inst_hit a, b;
		trace_two_level_ray(tl->inst, &bounds, seed, i, &ray);
		trace_two_level_closest(tl, &ray, &a, NULL);
		trace_two_level_brute(tl->inst, &ray, &b);
		*mismatches += a.instance != b.instance || a.hit.prim != b.hit.prim ||
		               (a.hit.prim != BVHLAB_NO_HIT && a.hit.t != b.hit.t);
		if (flat && flat_mismatches) {
			bvhlab_hit f;
			bvhlab_trace_brute(flat, &ray, &f);
			*flat_mismatches += !same_as_flat(&a, &f);
		}
	}
}
