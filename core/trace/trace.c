/*
 * bvhlab — the core's stack-based ray traversal of the standard layout and
 * the brute-force reference (the shared kernel is in trace_kernel.h).
 *
 * Every builder's tree is measured with this traverser, so it has to be
 * correct on any valid tree (any depth, any node order) and reasonably fast:
 * per-ray constants are computed once, the stack lives on the C stack and
 * nothing is allocated unless a tree is deeper than that stack.
 */
#include <stdlib.h>
#include <string.h>

#include "trace/trace_kernel.h"
#include "tree/tree_view.h"


#define LOCAL_STACK 64
#define BRUTE_BLOCK 16

typedef struct stack_entry {
	uint32_t node;
	float t; /* entry distance of the node's box, to skip it once beaten */
} stack_entry;

typedef struct trace_state {
	const bvhlab_tree *tree;
	const bvhlab_scene *scene;
	const bvhlab_node *node_array; /* the tree's, or an aligned copy */
	const float *verts; /* vertex copy in slot order, or NULL */
	const ray_prep *p;
	bvhlab_hit *hit;
	uint64_t nodes, tris;
	bool any;  /* any-hit: the first hit ends the traversal */
	bool done;
} trace_state;

/* Ray-space 2D vertices of a block of triangles, structure of arrays. */
typedef struct sheared_block {
	float x[3][BRUTE_BLOCK], y[3][BRUTE_BLOCK];
	int pass[BRUTE_BLOCK];
} sheared_block;

static void shear_block(const ray_prep *p, const bvhlab_scene *scene, uint32_t base,
                        uint32_t m, sheared_block *b)
{
	const uint32_t *idx = scene->indices + 3 * (size_t)base;
	uint32_t i;
	int j;

	for (i = 0; i < m; i++) {
		for (j = 0; j < 3; j++) {
			const float *v = scene->vertices + 3 * (size_t)idx[3 * i + j];
			float z = v[p->kz] - p->org[p->kz];

			b->x[j][i] = v[p->kx] - p->org[p->kx] - p->sx * z;
			b->y[j][i] = v[p->ky] - p->org[p->ky] - p->sy * z;
		}
	}
}

/*
 * The sign test of isect() over a block, branch-free so the compiler
 * vectorises it. It performs exactly isect()'s float operations, so it only
 * drops triangles isect() would drop; any zero edge goes to isect(), whose
 * double fallback may change the decision.
 */
static void sign_block(sheared_block *b)
{
	int i;

	for (i = 0; i < BRUTE_BLOCK; i++) {
		float e0 = b->x[2][i] * b->y[1][i] - b->y[2][i] * b->x[1][i];
		float e1 = b->x[0][i] * b->y[2][i] - b->y[0][i] * b->x[2][i];
		float e2 = b->x[1][i] * b->y[0][i] - b->y[1][i] * b->x[0][i];
		int zero = (e0 == 0.0f) | (e1 == 0.0f) | (e2 == 0.0f);
		int neg = (e0 < 0.0f) | (e1 < 0.0f) | (e2 < 0.0f);
		int pos = (e0 > 0.0f) | (e1 > 0.0f) | (e2 > 0.0f);

		b->pass[i] = zero | !(neg & pos);
	}
}

/* Brute force is the reference the validation trusts, and over a few
 * million triangles it dominates validation time: hence the blocking. */
static void brute_all(const bvhlab_scene *scene, const ray_prep *p, bvhlab_hit *hit)
{
	sheared_block b;
	uint32_t base, i, m;

	memset(&b, 0, sizeof(b));
	for (base = 0; base < scene->triangle_count; base += m) {
		m = scene->triangle_count - base;
		m = m < BRUTE_BLOCK ? m : BRUTE_BLOCK;
		shear_block(p, scene, base, m, &b);
		sign_block(&b);
		for (i = 0; i < m; i++)
			if (b.pass[i])
				isect_prim(p, scene, base + i, hit);
	}
}

static void leaf(trace_state *s, const bvhlab_node *n)
{
	const bvhlab_tree *tree = s->tree;
	uint32_t first = tree_leaf_first(n), count = tree_leaf_count(n), i;

	/* An invalid tree must not make the traverser read out of bounds; what
	 * it skips shows up as a mismatch in bvhlab_validate_rays. */
	if (first > tree->index_count || count > tree->index_count - first)
		return;
	for (i = first; i < first + count; i++) {
		if (tree->prim_index[i] >= s->scene->triangle_count)
			continue;
		s->tris++;
		if (isect_slot(s->p, tree, s->scene, s->verts, i, s->hit) && s->any) {
			s->done = true;
			return;
		}
	}
}

/* Why a traversal ended early. */
enum { TRACE_OK, TRACE_INVALID, TRACE_NOMEM };

/* Moves the stack to the heap, twice as large. A valid tree never has more
 * pending nodes than nodes, so more means a cycle: give up. */
static int grow_stack(stack_entry **stack, uint32_t *cap, uint32_t node_count)
{
	uint32_t new_cap = *cap * 2;
	stack_entry *grown;

	if (*cap > node_count)
		return TRACE_INVALID;
	grown = malloc((size_t)new_cap * sizeof(*grown));
	if (!grown)
		return TRACE_NOMEM;
	memcpy(grown, *stack, (size_t)*cap * sizeof(*grown));
	if (*cap != LOCAL_STACK)
		free(*stack);
	*stack = grown;
	*cap = new_cap;
	return TRACE_OK;
}

/* Pushes one stack entry, growing the stack when full. */
static bool push(trace_state *s, stack_entry e, stack_entry **stack, uint32_t *sp, uint32_t *cap,
                 int *fail)
{
	if (*sp == *cap) {
		*fail = grow_stack(stack, cap, s->tree->node_count);
		if (*fail != TRACE_OK)
			return false;
	}
	(*stack)[(*sp)++] = e;
	return true;
}

/* What entering node n reads next: its children's boxes or its triangles. */
static inline void prefetch_next(const trace_state *s, const bvhlab_node *n)
{
	if (!tree_is_leaf(n))
		__builtin_prefetch(&s->node_array[tree_child(n, 0)]);
	else if (s->verts)
		__builtin_prefetch(s->verts + 9 * (size_t)tree_leaf_first(n));
}

/*
 * Picks the next node below an inner node: the nearer child, pushing the
 * farther one. Returns false when neither child is hit, or when the pushed
 * entry could not be stored (*fail says why).
 */
static bool descend(trace_state *s, const bvhlab_node *n, uint32_t *node, stack_entry **stack,
                    uint32_t *sp, uint32_t *cap, int *fail)
{
	const bvhlab_node *nodes = s->node_array;
	uint32_t near = tree_child(n, 0), far = tree_child(n, 1);
	float tn, tf;

	if (tree_children_end(n) > s->tree->node_count)
		return false;
	tn = box_enter(s->p, &nodes[near], s->hit->t);
	tf = box_enter(s->p, &nodes[far], s->hit->t);
	if (tf < tn) {
		float t = tn;

		tn = tf;
		tf = t;
		near = far;
		far = tree_child(n, 0);
	}
	if (tn == INFINITY)
		return false;
	/* The far child's next reads are fetched now, while the near subtree
	 * is walked: the walk is bound by memory latency, not arithmetic. */
	if (tf != INFINITY)
		prefetch_next(s, &nodes[far]);
	prefetch_next(s, &nodes[near]);
	if (tf != INFINITY && !push(s, (stack_entry){ far, tf }, stack, sp, cap, fail))
		return false;
	*node = near;
	return true;
}

/*
 * descend for a wider node: every child's box is tested, the hit ones are
 * sorted near to far, the nearest is taken and the rest pushed, farthest
 * first. The same closest hit as any order; near-first saves work.
 */
static bool descend_wide(trace_state *s, const bvhlab_node *n, uint32_t *node,
                         stack_entry **stack, uint32_t *sp, uint32_t *cap, int *fail)
{
	stack_entry hit[BVHLAB_MAX_WIDTH];
	uint32_t k = tree_child_count(n), m = 0;

	if (k > BVHLAB_MAX_WIDTH || tree_children_end(n) > s->tree->node_count)
		return false;
	for (uint32_t i = 0; i < k; i++) {
		stack_entry e = { tree_child(n, i), box_enter(s->p, &s->node_array[tree_child(n, i)],
		                                               s->hit->t) };
		uint32_t j = m++;

		if (e.t == INFINITY) {
			m--;
			continue;
		}
		for (; j > 0 && hit[j - 1].t < e.t; j--) /* far to near */
			hit[j] = hit[j - 1];
		hit[j] = e;
	}
	if (m == 0)
		return false;
	for (uint32_t i = 0; i + 1 < m; i++)
		if (!push(s, hit[i], stack, sp, cap, fail))
			return false;
	prefetch_next(s, &s->node_array[hit[m - 1].node]);
	*node = hit[m - 1].node;
	return true;
}

static bool pop(trace_state *s, const stack_entry *stack, uint32_t *sp, uint32_t *node)
{
	while (*sp) {
		const stack_entry *e = &stack[--*sp];

		if (e->t <= s->hit->t * FAR_SCALE) {
			*node = e->node;
			return true;
		}
	}
	return false;
}

static void traverse(trace_state *s)
{
	const bvhlab_tree *tree = s->tree;
	stack_entry local[LOCAL_STACK], *stack = local;
	uint32_t sp = 0, cap = LOCAL_STACK, node = 0;
	int fail = TRACE_OK;

	if (box_enter(s->p, &s->node_array[0], s->hit->t) == INFINITY)
		return;
	for (;;) {
		const bvhlab_node *n = &s->node_array[node];

		/* A valid tree visits each node at most once per ray; more means a
		 * cycle, and stopping keeps an invalid tree from hanging us. */
		if (++s->nodes > tree->node_count)
			break;
		if (tree_is_binary_inner(n)) {
			if (descend(s, n, &node, &stack, &sp, &cap, &fail))
				continue;
		} else if (!tree_is_leaf(n)) {
			if (descend_wide(s, n, &node, &stack, &sp, &cap, &fail))
				continue;
		} else {
			leaf(s, n);
			if (s->done)
				break;
		}
		if (fail == TRACE_NOMEM) {
			brute_all(s->scene, s->p, s->hit); /* slow, but still exact */
			break;
		} else if (fail == TRACE_INVALID) {
			break;
		}
		if (!pop(s, stack, &sp, &node))
			break;
	}
	if (stack != local)
		free(stack);
}

bool bvhlab_intersect_triangle(const bvhlab_ray *ray, const bvhlab_scene *scene,
                               uint32_t prim, bvhlab_hit *hit)
{
	ray_prep p;

	if (!prep_ray(ray, &p))
		return false;
	return isect_prim(&p, scene, prim, hit);
}

static void hit_init(const bvhlab_ray *ray, bvhlab_hit *hit)
{
	hit->t = ray->tmax;
	hit->u = hit->v = 0.0f;
	hit->prim = BVHLAB_NO_HIT;
}

/* Stats: nodes_visited counts the nodes entered (root included, each inner
 * node's child boxes are tested from it), tris_tested the triangle tests. */
void trace_ray_stack(const bvhlab_tree *tree, const bvhlab_scene *scene,
                     const struct trace_view *view, const bvhlab_ray *ray, bool any,
                     bvhlab_hit *hit, bvhlab_trace_stats *stats)
{
	trace_state s = { tree, scene, view->nodes, view->tris, NULL, hit, 0, 0, any, false };
	ray_prep p;

	hit_init(ray, hit);
	if (prep_ray(ray, &p) && tree->node_count > 0) {
		s.p = &p;
		traverse(&s);
	}
	if (stats) {
		stats->rays++;
		stats->nodes_visited += s.nodes;
		stats->tris_tested += s.tris;
	}
}

void bvhlab_trace_closest(const bvhlab_tree *tree, const bvhlab_scene *scene,
                          const bvhlab_ray *ray, bvhlab_hit *hit, bvhlab_trace_stats *stats)
{
	struct trace_view v = trace_view_plain(tree);
	trace_ray_stack(tree, scene, &v, ray, false, hit, stats);
}

/* Occlusion rays only need to know that something is in the way, so the
 * first triangle hit ends the walk (the hit is not the closest one). */
bool bvhlab_trace_any(const bvhlab_tree *tree, const bvhlab_scene *scene,
                      const bvhlab_ray *ray, bvhlab_hit *hit, bvhlab_trace_stats *stats)
{
	struct trace_view v = trace_view_plain(tree);
	trace_ray_stack(tree, scene, &v, ray, true, hit, stats);
	return hit->prim != BVHLAB_NO_HIT;
}

void bvhlab_trace_brute(const bvhlab_scene *scene, const bvhlab_ray *ray, bvhlab_hit *hit)
{
	ray_prep p;

	hit_init(ray, hit);
	if (prep_ray(ray, &p))
		brute_all(scene, &p, hit);
}

