/*
 * bvhlab — the one read interface of a tree (ABI 1.5's open tree): a
 * node's children, its box (lo, hi) and its leaf range. Everything in the
 * core that walks a tree (validate, compare, metrics, EPO, the traversals,
 * the tracer's views and uploads) reads it through these, so a tree of any
 * width is a tree like any other; only here is the layout spelt out.
 *
 * Binary stays the fast path: its inner node has count 0 and two children,
 * and the first test of tree_is_binary_inner costs what `count == 0` did.
 */
#ifndef BVHLAB_TREE_VIEW_H
#define BVHLAB_TREE_VIEW_H

#include <stdbool.h>
#include <stdint.h>

#include <bvhlab/tree.h>

/* The tree's branching factor; a zeroed width reads as binary. */
static inline uint32_t tree_width(const bvhlab_tree *t)
{
	return t->width > 2 ? t->width : 2;
}

static inline bool tree_is_binary_inner(const bvhlab_node *n)
{
	return n->count == 0;
}

static inline bool tree_is_leaf(const bvhlab_node *n)
{
	return n->count != 0 && !(n->count & BVHLAB_NODE_INNER);
}

/* How many children an inner node has; 0 for a leaf. */
static inline uint32_t tree_child_count(const bvhlab_node *n)
{
	if (n->count == 0)
		return 2;
	return n->count & BVHLAB_NODE_INNER ? n->count & ~BVHLAB_NODE_INNER : 0;
}

/* The i-th child (i < tree_child_count) of an inner node. */
static inline uint32_t tree_child(const bvhlab_node *n, uint32_t i)
{
	return n->first + i;
}

/* One past the last child's index (64 bits: a bad `first` cannot wrap). */
static inline uint64_t tree_children_end(const bvhlab_node *n)
{
	return (uint64_t)n->first + tree_child_count(n);
}

/* A leaf's primitives: prim_index[tree_leaf_first .. + tree_leaf_count). */
static inline uint32_t tree_leaf_first(const bvhlab_node *n)
{
	return n->first;
}

static inline uint32_t tree_leaf_count(const bvhlab_node *n)
{
	return tree_is_leaf(n) ? n->count : 0;
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
 * The binary expansion of a tree, in a malloc'd array of *count nodes
 * over the same prim_index: each k-wide node becomes a binary node whose
 * children split its child list in halves (a half of one child is that
 * child), boxes the union of theirs; a binary tree comes out as it is, up
 * to node order. For consumers whose layout is binary (the device
 * tracer); the same leaves, so the same hits. 0, -EINVAL (links out of
 * the array), -ENOMEM.
 */
int tree_binary_nodes(const bvhlab_tree *t, bvhlab_node **nodes, uint32_t *count);

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
