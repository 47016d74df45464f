/*
 * bvhlab — the one read interface of a tree (ABI 1.5's open tree): a
 * node's children, its box (lo, hi) and its leaf range. Everything in the
 * core that walks a tree (validate, compare, metrics, EPO, the traversals
 * on the host and the device, the tracer's views) reads it through these,
 * so a tree of any width is a tree like any other. The node reads are
 * tree_node.h's, shared with the device tracer's kernels; here the host's
 * whole-tree services.
 */
#ifndef BVHLAB_TREE_VIEW_H
#define BVHLAB_TREE_VIEW_H

#include <stdbool.h>
#include <stdint.h>

#include <bvhlab/tree.h>

#include "tree/tree_node.h"

BVHLAB_STATIC_ASSERT(TREE_NODE_INNER == BVHLAB_NODE_INNER && TREE_MAX_WIDTH == BVHLAB_MAX_WIDTH,
                     "tree_node.h's constants are the ABI's");
BVHLAB_STATIC_ASSERT(offsetof(bvhlab_node, first) == 4 * TREE_NODE_FIRST &&
                     offsetof(bvhlab_node, count) == 4 * TREE_NODE_COUNT &&
                     sizeof(bvhlab_node) == 4 * TREE_NODE_WORDS, "tree_node.h's node layout");

/* The tree's branching factor; a zeroed width reads as binary. */
static inline uint32_t tree_width(const bvhlab_tree *t)
{
	return t->width > 2 ? t->width : 2;
}

/* Writes an inner node's child list (the one way a core stage makes one). */
static inline void tree_set_children(bvhlab_node *n, uint32_t first, uint32_t k)
{
	n->first = first;
	n->count = k == 2 ? 0 : BVHLAB_NODE_INNER | k;
}

/* ---- tree_view.c ---- */

/* 0 for a binary tree; otherwise -ENOTSUP with a message naming `stage`
 * and the tree's width (the binary-only stages: refinement, update). */
int tree_require_binary(const bvhlab_tree *t, const char *stage, bvhlab_error *err);

/*
 * The SAH weight of an inner node: its traversal cost, one half per child
 * box tested, so a binary node costs 1 (c_trav of the binary SAH) and a
 * k-wide node k/2. See bvhlab_tree_stats.
 */
static inline double tree_trav_cost(const bvhlab_node *n)
{
	return 0.5 * tree_child_count(n);
}

#endif /* BVHLAB_TREE_VIEW_H */
