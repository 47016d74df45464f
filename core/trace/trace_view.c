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
#include "trace/trace_wide8.h"
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

/* The binary copies added to a view (which keeps its wide nodes). */
static int add_copies(const bvhlab_tree *tree, const bvhlab_scene *scene, struct trace_view *v)
{
	int r = copy_nodes(tree, v);
	return r == 0 ? copy_tris(tree, scene, v) : r;
}

int trace_view_copy(const bvhlab_tree *tree, const bvhlab_scene *scene, struct trace_view *v)
{
	*v = trace_view_plain(tree);
	int r = add_copies(tree, scene, v);
	if (r < 0)
		trace_view_free(v);
	return r;
}

/* Whether every ray walks the wide nodes: a tree too deep for the wide
 * stack falls back to the stack traversal (trace_wide_body.h), which
 * then wants the binary copies. */
static bool wide_covers(const struct trace_view *v)
{
	if (v->wide8)
		return (uint64_t)v->wide8->depth * (WIDE8 - 1) + 1 <= WIDE8_STACK;
	return v->wide && (uint64_t)v->wide->depth * (WIDE - 1) + 1 <= WIDE_STACK;
}

/* The 4-lane nodes: the tree as built when wide4/wide8 get one of width
 * 3 or 4, else today's collapse (wide_bvh.c: a binary tree, or a tree
 * too wide for 4 lanes). */
static int view_wide4(const bvhlab_tree *tree, const bvhlab_scene *scene, bool built,
                      struct trace_view *v)
{
	struct wide_bvh *w = malloc(sizeof(*w));
	int r = w ? -ERANGE : -ENOMEM;
	if (w && built && tree_width(tree) <= 4) {
		struct wide_built b;
		r = wide_built_init(&b, tree, scene, 4);
		if (r == 0)
			*w = (struct wide_bvh){b.nodes, b.tris, b.node_count, b.tri_groups, b.depth};
	}
	if (r == -ERANGE)
		r = wide_bvh_init(w, tree, scene);
	if (r < 0) {
		free(w);
		return r;
	}
	v->wide = v->owned_wide = w;
	return 0;
}

/* The 8-lane nodes of a tree of width 5 to 8, as built. */
static int view_wide8(const bvhlab_tree *tree, const bvhlab_scene *scene, struct trace_view *v)
{
	struct wide8_bvh *w = malloc(sizeof(*w));
	struct wide_built b;
	int r = w ? wide_built_init(&b, tree, scene, WIDE8) : -ENOMEM;
	if (r < 0) {
		free(w);
		return r;
	}
	*w = (struct wide8_bvh){b.nodes, b.tris, b.node_count, b.tri_groups, b.depth};
	v->wide8 = v->owned_wide8 = w;
	v->wide8_isa = trace_wide8_pick();
	return 0;
}

int trace_view_wide(const bvhlab_tree *tree, const bvhlab_scene *scene, int traversal,
                    struct trace_view *v)
{
	int r = traversal == BVHLAB_TRAVERSAL_WIDE8 && tree_width(tree) > 4
	        ? view_wide8(tree, scene, v)
	        : view_wide4(tree, scene,
	                     traversal != BVHLAB_TRAVERSAL_WIDE && tree_width(tree) > 2, v);
	return r == 0 && !wide_covers(v) && !v->owned ? add_copies(tree, scene, v) : r;
}

void trace_view_free(struct trace_view *v)
{
	free(v->owned);
	free(v->owned_tris);
	if (v->owned_wide)
		wide_bvh_finish(v->owned_wide);
	free(v->owned_wide);
	if (v->owned_wide8) {
		free(v->owned_wide8->nodes);
		free(v->owned_wide8->tris);
	}
	free(v->owned_wide8);
	v->owned_wide8 = NULL;
	v->wide8 = NULL;
	v->owned = NULL;
	v->owned_tris = NULL;
	v->owned_wide = NULL;
	v->wide = NULL;
}
