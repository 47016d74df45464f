/*
 * The stackless traversal: down into the near child, back up through the
 * parent links (Hapala, Davidovic, Wald, Havran and Slusallek, "Efficient
 * Stack-less BVH Traversal for Ray Tracing", SCCG 2011). GPU ray tracers
 * use it where a per-ray stack costs registers or local memory; here it is
 * the second traversal the harness can measure trees with.
 *
 * Going down, the near child is tried first, then the far one. Coming up
 * from a child, the walk knows where it was: from the near child it still
 * has to try the far one, from the far child it goes on up. That needs the
 * near/far decision to come out the same both times, so it depends only on
 * the ray and the two child boxes (their centres along the ray direction),
 * not on distances that shrink as hits are found. A wider node's children
 * are tried in the order of their box centres along the ray (the first one
 * on a tie), coming up from one the walk goes on with the next in that
 * order: the same rule, k children instead of two.
 */
#include <errno.h>
#include <stdlib.h>

#include <bvhlab/trace.h>

#include "trace/trace_kernel.h"
#include "tree/tree_view.h"

#define NONE UINT32_MAX

int bvhlab_tree_parents(const bvhlab_tree *tree, uint32_t **parents)
{
	uint32_t n = tree->node_count;
	uint32_t *par = malloc((n ? n : 1) * sizeof(*par));
	*parents = NULL;
	if (!par)
		return -ENOMEM;
	for (uint32_t i = 0; i < n; i++)
		par[i] = NONE;
	for (uint32_t i = 0; i < n; i++) {
		const bvhlab_node *nd = &tree->nodes[i];
		if (tree_is_leaf(nd))
			continue;
		/* The root (0) is nobody's child; a child with a parent already is
		 * shared or part of a cycle: either way not a tree. */
		bool bad = tree_child(nd, 0) == 0 || tree_children_end(nd) > n;
		for (uint32_t k = 0; !bad && k < tree_child_count(nd); k++)
			bad = par[tree_child(nd, k)] != NONE;
		if (bad) {
			free(par);
			return -EINVAL;
		}
		for (uint32_t k = 0; k < tree_child_count(nd); k++)
			par[tree_child(nd, k)] = i;
	}
	*parents = par;
	return 0;
}

/* The near child of an inner node: the one whose box centre comes first
 * along the ray (the first child on a tie). */
static inline uint32_t near_child(const ray_prep *p, const bvhlab_node *nodes,
                                  const bvhlab_node *n)
{
	uint32_t first = tree_child(n, 0), second = tree_child(n, 1);
	const bvhlab_node *a = &nodes[first], *b = &nodes[second];
	float d = 0.0f;
	for (int k = 0; k < 3; k++)
		d += ((b->lo[k] + b->hi[k]) - (a->lo[k] + a->hi[k])) * p->dir[k];
	return d < 0.0f ? second : first;
}

/* A wide node's child's place in the ray order (twice its centre's). */
static inline float centre_key(const ray_prep *p, const bvhlab_node *b)
{
	float d = 0.0f;
	for (int k = 0; k < 3; k++)
		d += (b->lo[k] + b->hi[k]) * p->dir[k];
	return d;
}

/* The child of wide node n after `after` in the ray order (by key, then by
 * index), the first one for NONE; NONE past the last. */
static uint32_t next_wide(const ray_prep *p, const bvhlab_node *nodes, const bvhlab_node *n,
                          uint32_t after)
{
	float ka = after == NONE ? 0.0f : centre_key(p, &nodes[after]), kb = 0.0f;
	uint32_t best = NONE;
	for (uint32_t i = 0; i < tree_child_count(n); i++) {
		uint32_t c = tree_child(n, i);
		float k = centre_key(p, &nodes[c]);
		if (after != NONE && !(k > ka || (k == ka && c > after)))
			continue;
		if (best == NONE || k < kb || (k == kb && c < best))
			best = c, kb = k;
	}
	return best;
}

struct walk {
	const bvhlab_tree *tree;
	const bvhlab_node *node_array;
	const uint32_t *parents;
	const bvhlab_scene *scene;
	const float *tris;
	const ray_prep *p;
	bvhlab_hit *hit;
	uint64_t nodes, tests;
	bool any;
	/* A leaf of something else than triangles (a two-level top's
	 * instances), or NULL: see trace_walk_stackless. */
	bool (*on_leaf)(void *ctx, const bvhlab_node *n);
	void *ctx;
};

/* Tests a leaf's triangles; true when an any-hit walk may stop. */
static bool leaf(struct walk *w, const bvhlab_node *n)
{
	const bvhlab_tree *tree = w->tree;
	uint32_t first = tree_leaf_first(n), count = tree_leaf_count(n);
	if (first > tree->index_count || count > tree->index_count - first)
		return false;
	for (uint32_t i = first; i < first + count; i++) {
		if (tree->prim_index[i] >= w->scene->triangle_count)
			continue;
		w->tests++;
		if (isect_slot(w->p, tree, w->scene, w->tris, i, w->hit) && w->any)
			return true;
	}
	return false;
}

static inline bool enters(const struct walk *w, uint32_t node)
{
	return box_enter(w->p, &w->node_array[node], w->hit->t) != INFINITY;
}

/* The first child of inner node n after `after` (NONE: from the start) in
 * the ray order that the ray enters, into *node; false when none is left. */
static bool enter_next(struct walk *w, const bvhlab_node *n, uint32_t after, uint32_t *node)
{
	if (tree_is_binary_inner(n)) {
		uint32_t near = near_child(w->p, w->node_array, n);
		uint32_t far = near == tree_child(n, 0) ? tree_child(n, 1) : tree_child(n, 0);
		if (after == NONE && enters(w, near)) {
			*node = near;
			return true;
		}
		if ((after == NONE || after == near) && enters(w, far)) {
			*node = far;
			return true;
		}
		return false;
	}
	for (uint32_t c = next_wide(w->p, w->node_array, n, after); c != NONE;
	     c = next_wide(w->p, w->node_array, n, c))
		if (enters(w, c)) {
			*node = c;
			return true;
		}
	return false;
}

/* From a node whose subtree is done, up to the next sibling to enter;
 * false when the walk is back at the root. */
static bool climb(struct walk *w, uint32_t *node)
{
	uint32_t at = *node;
	while (at != 0) {
		uint32_t parent = w->parents[at];
		if (enter_next(w, &w->node_array[parent], at, node))
			return true;
		at = parent;
	}
	return false;
}

static void walk(struct walk *w)
{
	const bvhlab_node *nodes = w->node_array;
	uint32_t node = 0;
	if (!enters(w, 0))
		return;
	for (;;) {
		const bvhlab_node *n = &nodes[node];
		/* Each node is entered at most once on a tree; more means the
		 * links are not one, and stopping keeps a bad tree from hanging. */
		if (++w->nodes > w->tree->node_count)
			return;
		if (!tree_is_leaf(n)) {
			if (enter_next(w, n, NONE, &node))
				continue;
		} else if (w->on_leaf ? w->on_leaf(w->ctx, n) : leaf(w, n)) {
			return;
		}
		if (!climb(w, &node))
			return;
	}
}

void trace_ray_stackless(const bvhlab_tree *tree, const bvhlab_scene *scene,
                         const struct trace_view *view, const bvhlab_ray *ray, bool any_hit,
                         bvhlab_hit *hit, bvhlab_trace_stats *stats)
{
	ray_prep p;
	struct walk w = {tree, view->nodes, view->parents, scene, view->tris, &p, hit, 0, 0,
	                 any_hit, NULL, NULL};
	hit->t = ray->tmax;
	hit->u = hit->v = 0.0f;
	hit->prim = BVHLAB_NO_HIT;
	if (prep_ray(ray, &p) && tree->node_count > 0)
		walk(&w);
	if (stats) {
		stats->rays++;
		stats->nodes_visited += w.nodes;
		stats->tris_tested += w.tests;
	}
}

void trace_walk_stackless(const bvhlab_tree *tree, const uint32_t *parents,
                          const bvhlab_ray *ray, bvhlab_hit *hit,
                          bool (*on_leaf)(void *ctx, const bvhlab_node *n), void *ctx,
                          bvhlab_trace_stats *stats)
{
	ray_prep p;
	struct walk w = {tree, tree->nodes, parents, NULL, NULL, &p, hit, 0, 0, false, on_leaf,
	                 ctx};
	if (prep_box(ray, &p) && tree->node_count > 0)
		walk(&w);
	if (stats)
		stats->nodes_visited += w.nodes;
}

bool bvhlab_trace_stackless(const bvhlab_tree *tree, const uint32_t *parents,
                            const bvhlab_scene *scene, const bvhlab_ray *ray, bool any_hit,
                            bvhlab_hit *hit, bvhlab_trace_stats *stats)
{
	struct trace_view v = trace_view_plain(tree);
	v.parents = parents;
	trace_ray_stackless(tree, scene, &v, ray, any_hit, hit, stats);
	return hit->prim != BVHLAB_NO_HIT;
}
