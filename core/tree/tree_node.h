/*
 * bvhlab — the tree interface's node reads (ABI 1.5's open tree), in the C
 * that OpenCL C also is: one definition for the host (tree_view.h, which
 * includes this) and the device (core/trace/trace_cl.cl, whose program
 * starts with this file), so the host's traversals and the device's read a
 * node's children, box and leaf range the same way. Only here, and in
 * tree_view.h's whole-tree services, is the layout spelt out.
 *
 * On the host a node is bvhlab_node (include/bvhlab/types.h); on the device
 * the struct of the same 32 bytes (lo, first, hi, count; tree_view.h checks
 * the offsets against TREE_NODE_FIRST and TREE_NODE_COUNT). Pointers to
 * nodes carry TREE_GLOBAL: __global on the device, nothing on the host.
 *
 * Binary stays the fast path: its inner node has count 0 and two children,
 * and the first test of tree_is_binary_inner costs what `count == 0` did.
 */
#ifndef BVHLAB_TREE_NODE_H
#define BVHLAB_TREE_NODE_H

/* The inner-node mark of a wide node's count and the widest tree
 * (BVHLAB_NODE_INNER and BVHLAB_MAX_WIDTH; tree_view.h checks they agree). */
#define TREE_NODE_INNER 0x80000000u
#define TREE_MAX_WIDTH 8
/* A node as 8 words: lo at 0..2, first at 3, hi at 4..6, count at 7. */
#define TREE_NODE_WORDS 8
#define TREE_NODE_FIRST 3
#define TREE_NODE_COUNT 7

#ifdef __OPENCL_VERSION__
#define TREE_GLOBAL __global
typedef uint tree_u32;
typedef ulong tree_u64;
typedef struct tree_node {
	float lo[3];
	uint first;
	float hi[3];
	uint count;
} tree_node;
#else
#include <stdbool.h>
#include <stdint.h>

#include <bvhlab/types.h>
#define TREE_GLOBAL
typedef uint32_t tree_u32;
typedef uint64_t tree_u64;
typedef bvhlab_node tree_node;
#endif

static inline bool tree_is_binary_inner(const TREE_GLOBAL tree_node *n)
{
	return n->count == 0;
}

static inline bool tree_is_leaf(const TREE_GLOBAL tree_node *n)
{
	return n->count != 0 && !(n->count & TREE_NODE_INNER);
}

/* How many children an inner node has; 0 for a leaf. */
static inline tree_u32 tree_child_count(const TREE_GLOBAL tree_node *n)
{
	if (n->count == 0)
		return 2;
	return n->count & TREE_NODE_INNER ? n->count & ~TREE_NODE_INNER : 0;
}

/* The i-th child (i < tree_child_count) of an inner node. */
static inline tree_u32 tree_child(const TREE_GLOBAL tree_node *n, tree_u32 i)
{
	return n->first + i;
}

/* One past the last child's index (64 bits: a bad `first` cannot wrap). */
static inline tree_u64 tree_children_end(const TREE_GLOBAL tree_node *n)
{
	return (tree_u64)n->first + tree_child_count(n);
}

/* A leaf's primitives: prim_index[tree_leaf_first .. + tree_leaf_count). */
static inline tree_u32 tree_leaf_first(const TREE_GLOBAL tree_node *n)
{
	return n->first;
}

static inline tree_u32 tree_leaf_count(const TREE_GLOBAL tree_node *n)
{
	return tree_is_leaf(n) ? n->count : 0;
}

/* The box as floats: lo[k] at k, hi[k] at 4 + k (the slab test's planes). */
static inline const TREE_GLOBAL float *tree_box(const TREE_GLOBAL tree_node *n)
{
	return (const TREE_GLOBAL float *)(const TREE_GLOBAL void *)n;
}

#endif /* BVHLAB_TREE_NODE_H */
