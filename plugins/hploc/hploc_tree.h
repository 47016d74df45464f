/*
 * H-PLOC's merge tree, as the CPU builder (hploc) and the device builder
 * (cl_hploc, which downloads it) both leave it, and its emission into the
 * output (hploc_emit.c, compiled into both plugins).
 *
 * A node of the merge tree is named by one word: HPLOC_LEAF | the
 * primitive's id for a primitive, else the slot of an inner record. Every
 * cluster has a representative, the sorted position of one of its
 * primitives; when clusters a (earlier in the order) and b merge, the
 * record of the merge goes to slot rep(b) and the merged cluster keeps
 * rep(a). Every position is given up at most once, so the n - 1 records
 * fill n slots with no counter, whatever order the merges happen in: the
 * slots depend on the merges alone, never on the threads.
 */
#ifndef BVHLAB_HPLOC_TREE_H
#define BVHLAB_HPLOC_TREE_H

#include <stdint.h>

#include <bvhlab/builder.h>

#define HPLOC_LEAF 0x80000000u      /* a node word naming a primitive */
#define HPLOC_COLLAPSED 0x40000000u /* in info: the SAH made the subtree one leaf */
#define HPLOC_PRIMS 0x3fffffffu     /* in info: primitives below */

/* An inner record (40 bytes; cl_hploc.cl's struct record). */
typedef struct hploc_rec {
	float lo[3];
	uint32_t left;  /* node word of the left (earlier) child */
	float hi[3];
	uint32_t right; /* node word of the right child */
	uint32_t info;  /* HPLOC_COLLAPSED | primitives */
	uint32_t desc;  /* output nodes below this one's own (0 when collapsed) */
} hploc_rec;

/* The merge tree of n >= 2 primitives, rooted at node word `root`. */
typedef struct hploc_tree {
	uint32_t n;
	const hploc_rec *rec;             /* [n] by slot */
	uint32_t root;
	const bvhlab_aabb *prim_bounds;   /* the primitives' boxes, for the leaves */
} hploc_tree;

/*
 * The tree into out (room for 2n - 1 nodes, n indices), collapse
 * applied: a node's children as a pair, the left child's subtree first.
 * Returns the node count.
 */
uint32_t hploc_emit(const hploc_tree *t, bvhlab_build_output *out);

#endif /* BVHLAB_HPLOC_TREE_H */
