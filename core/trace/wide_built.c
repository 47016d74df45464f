/*
 * A wide tree traced as it was built: each inner node of a tree of width
 * 3 to `lanes` becomes one wide node with a lane per child, in the
 * builder's (or the collapse stage's) order, so what is measured is that
 * tree and not a re-collapse of it. A leaf child becomes a leaf lane whose
 * triangles are copied in groups of TRI_LANES, NaN past the leaf's count.
 * The layout is trace_wide.h's for 4 lanes (struct wide_node, wide_tris)
 * and trace_wide8.h's for 8; here both are walked as arrays of words:
 * a node is box[6][lanes], child[lanes], count[lanes]; a group
 * v[9][TRI_LANES], prim[TRI_LANES].
 */
#include <errno.h>
#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "trace/trace_wide.h"
#include "tree/tree_view.h"
#include "util/util.h"

struct built {
	const bvhlab_tree *tree;
	const bvhlab_scene *scene;
	uint32_t lanes;
	uint32_t *nodes, *tris; /* words */
	uint32_t node_count, node_cap, groups, group_cap, depth;
	uint8_t *seen;
};

static uint32_t *node_words(struct built *b, uint32_t id)
{
	return b->nodes + (size_t)id * 8 * b->lanes;
}

static void set_box(struct built *b, uint32_t *w, uint32_t lane, const bvhlab_node *n)
{
	float *box = (float *)(void *)w;
	for (int k = 0; k < 3; k++) {
		box[k * b->lanes + lane] = n ? n->lo[k] : INFINITY;
		box[(3 + k) * b->lanes + lane] = n ? n->hi[k] : -INFINITY;
	}
}

/* Group lane `lane`: slot's triangle, or NaN vertices when !used. */
static void group_lane(struct built *b, uint32_t *g, uint32_t lane, uint32_t slot, bool used)
{
	const bvhlab_scene *s = b->scene;
	uint32_t prim = used ? b->tree->prim_index[slot] : BVHLAB_NO_HIT;
	float *v = (float *)(void *)g;
	g[9 * TRI_LANES + lane] = prim;
	for (int j = 0; j < 3; j++) {
		const float *p = prim < s->triangle_count
		                         ? s->vertices + 3 * (size_t)s->indices[3 * (size_t)prim + j]
		                         : NULL;
		for (int k = 0; k < 3; k++)
			v[(3 * j + k) * TRI_LANES + lane] = p ? p[k] : NAN;
	}
}

/* Lane `lane` of node w as the tree's leaf n, its triangles copied. */
static int leaf_lane(struct built *b, uint32_t *w, uint32_t lane, const bvhlab_node *n)
{
	uint32_t first = tree_leaf_first(n), count = tree_leaf_count(n), L = b->lanes, G = TRI_LANES;
	uint64_t need = ((uint64_t)count + G - 1) / G;
	if (first > b->tree->index_count || count > b->tree->index_count - first ||
	    need > b->group_cap - b->groups)
		return -EINVAL;
	w[6 * L + lane] = b->groups;
	w[7 * L + lane] = count;
	for (uint32_t k = 0; k < count; k += G) {
		uint32_t *g = b->tris + (size_t)b->groups++ * 10 * G;
		for (uint32_t i = 0; i < G; i++)
			group_lane(b, g, i, first + k + i, k + i < count);
	}
	return 0;
}

/* Fills wide node id from tree node `node`'s children, pushing the inner
 * ones (their wide ids taken in order) onto todo. */
static int fill(struct built *b, uint32_t id, uint32_t node, uint32_t level, uint32_t *todo,
                uint32_t *sp)
{
	const bvhlab_node *n = &b->tree->nodes[node];
	uint32_t k = tree_child_count(n), L = b->lanes, *w = node_words(b, id);
	if (k > L)
		return -ERANGE;
	if (tree_children_end(n) > b->tree->node_count || tree_child(n, 0) == 0)
		return -EINVAL;
	b->depth = level > b->depth ? level : b->depth;
	for (uint32_t i = 0; i < L; i++) {
		const bvhlab_node *c = i < k ? &b->tree->nodes[tree_child(n, i)] : NULL;
		set_box(b, w, i, c);
		w[6 * L + i] = 0;
		w[7 * L + i] = WIDE_EMPTY;
		if (!c)
			continue;
		if (b->seen[tree_child(n, i)]++)
			return -EINVAL;
		if (tree_is_leaf(c)) {
			int r = leaf_lane(b, w, i, c);
			if (r < 0)
				return r;
			continue;
		}
		if (b->node_count == b->node_cap)
			return -EINVAL;
		w[6 * L + i] = b->node_count;
		w[7 * L + i] = 0;
		todo[3 * *sp] = b->node_count++;
		todo[3 * *sp + 1] = tree_child(n, i);
		todo[3 * (*sp)++ + 2] = level + 1;
	}
	return 0;
}

/* Inner nodes and triangle groups the copy needs (a leaf root: one node). */
static void count_built(const bvhlab_tree *t, uint32_t *inner, uint32_t *groups)
{
	uint64_t in = 0, g = 0;
	for (uint32_t i = 0; i < t->node_count; i++) {
		in += tree_child_count(&t->nodes[i]) > 0;
		g += (tree_leaf_count(&t->nodes[i]) + (uint64_t)TRI_LANES - 1) / TRI_LANES;
	}
	*inner = in ? (in < UINT32_MAX ? (uint32_t)in : UINT32_MAX) : 1;
	*groups = g < UINT32_MAX ? (uint32_t)g : UINT32_MAX;
}

/* The root as a wide node: its children, or itself as one leaf lane. */
static int walk(struct built *b, uint32_t *todo)
{
	uint32_t sp = 0, *root = node_words(b, 0);
	b->node_count = 1;
	b->depth = 1;
	if (tree_is_leaf(&b->tree->nodes[0])) {
		for (uint32_t i = 0; i < b->lanes; i++) {
			set_box(b, root, i, i ? NULL : &b->tree->nodes[0]);
			root[6 * b->lanes + i] = 0;
			root[7 * b->lanes + i] = WIDE_EMPTY;
		}
		return leaf_lane(b, root, 0, &b->tree->nodes[0]);
	}
	int r = fill(b, 0, 0, 1, todo, &sp);
	while (r == 0 && sp > 0) {
		sp--;
		r = fill(b, todo[3 * sp], todo[3 * sp + 1], todo[3 * sp + 2], todo, &sp);
	}
	return r;
}

int wide_built_init(struct wide_built *out, const bvhlab_tree *tree, const bvhlab_scene *scene,
                    uint32_t lanes)
{
	struct built b = {.tree = tree, .scene = scene, .lanes = lanes};
	memset(out, 0, sizeof(*out));
	if (tree->node_count == 0 || (lanes != 4 && lanes != 8))
		return -EINVAL;
	count_built(tree, &b.node_cap, &b.group_cap);
	b.nodes = util_big_alloc(b.node_cap, 32 * (size_t)lanes);
	b.tris = util_big_alloc(b.group_cap, sizeof(struct wide_tris));
	b.seen = calloc(tree->node_count, 1);
	uint32_t *todo = malloc(3 * sizeof(*todo) * (size_t)b.node_cap);
	int r = b.nodes && b.tris && b.seen && todo ? walk(&b, todo) : -ENOMEM;
	free(todo);
	free(b.seen);
	if (r < 0) {
		free(b.nodes);
		free(b.tris);
		return r;
	}
	*out = (struct wide_built){.nodes = b.nodes, .tris = b.tris, .node_count = b.node_count,
	                           .tri_groups = b.groups, .depth = b.depth};
	return 0;
}
