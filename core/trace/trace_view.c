/*
 * The batch tracer's read-only copies of a tree, made once per batch and
 * never per ray: nodes placed so that sibling pairs start on a cache line,
 * and the triangles' vertices in leaf order. Neither changes what is
 * visited or computed (same floats, same order), only how far apart in
 * memory the things one step of a traversal reads lie.
 */
#include <errno.h>
#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "trace/trace_kernel.h"
#include "trace/trace_wide.h"
#include "tree/tree_view.h"

#define LINE 64

/*
 * Builders write the children of a node side by side, a binary node's two
 * from nodes[first], and the root alone at 0, so first is usually odd: in
 * the tree's own array (32-byte nodes, line-aligned) such a pair straddles
 * two cache lines, and each inner node costs two misses instead of one.
 * The copy starts half a line in when most pairs begin at odd indices.
 */
static size_t pair_offset(const bvhlab_tree *tree)
{
	uint64_t odd = 0, inner = 0;
	for (uint32_t i = 0; i < tree->node_count; i++) {
		if (tree_is_leaf(&tree->nodes[i]))
			continue;
		inner++;
		odd += tree_child(&tree->nodes[i], 0) & 1u;
	}
	return 2 * odd > inner ? sizeof(bvhlab_node) : 0;
}

static int copy_nodes(const bvhlab_tree *tree, struct trace_view *v)
{
	size_t off = pair_offset(tree), bytes = (size_t)tree->node_count * sizeof(bvhlab_node);
	void *mem = NULL;
	if (posix_memalign(&mem, LINE, bytes + off + LINE) != 0)
		return -ENOMEM;
	bvhlab_node *nodes = (bvhlab_node *)(void *)((char *)mem + off);
	memcpy(nodes, tree->nodes, bytes);
	v->nodes = nodes;
	v->owned = mem;
	return 0;
}

static int copy_tris(const bvhlab_tree *tree, const bvhlab_scene *scene, struct trace_view *v)
{
	size_t n = tree->index_count;
	float *t = malloc((n ? n : 1) * 9 * sizeof(*t));
	if (!t)
		return -ENOMEM;
	for (size_t i = 0; i < n; i++) {
		uint32_t prim = tree->prim_index[i];
		for (int j = 0; j < 3; j++) {
			const float *src = NULL;
			if (prim < scene->triangle_count)
				src = scene->vertices + 3 * (size_t)scene->indices[3 * (size_t)prim + j];
			for (int k = 0; k < 3; k++)
				t[9 * i + 3 * j + k] = src ? src[k] : NAN;
		}
	}
	v->tris = t;
	v->owned_tris = t;
	return 0;
}

int trace_view_copy(const bvhlab_tree *tree, const bvhlab_scene *scene, struct trace_view *v)
{
	*v = trace_view_plain(tree);
	int r = copy_nodes(tree, v);
	if (r == 0)
		r = copy_tris(tree, scene, v);
	if (r < 0)
		trace_view_free(v);
	return r;
}

int trace_view_wide(const bvhlab_tree *tree, const bvhlab_scene *scene, struct trace_view *v)
{
	struct wide_bvh *w = malloc(sizeof(*w));
	int r = w ? wide_bvh_init(w, tree, scene) : -ENOMEM;
	if (r < 0) {
		free(w);
		return r;
	}
	v->wide = v->owned_wide = w;
	return 0;
}

void trace_view_free(struct trace_view *v)
{
	free(v->owned);
	free(v->owned_tris);
	if (v->owned_wide)
		wide_bvh_finish(v->owned_wide);
	free(v->owned_wide);
	v->owned = NULL;
	v->owned_tris = NULL;
	v->owned_wide = NULL;
	v->wide = NULL;
}
