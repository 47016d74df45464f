/*
 * The compressed 8-wide node (CWBVH: Ylitie, Karras and Laine, "Efficient
 * Incoherent Ray Traversal on GPUs Through Compressed Wide BVHs", HPG
 * 2017), in the C that OpenCL C also is: one definition for the encoder
 * (cwbvh.c), its test and the device kernel (trace_cl_wide8.cl).
 *
 * 80 bytes a node, as in the paper: the children's boxes are 8-bit
 * offsets against the node's origin `p` on a power-of-two grid per axis
 * (scale 2^(e - 127), e the byte `e[k]`: a float's exponent field), the
 * children sit in the 8 slots by the octant their centre lies in from the
 * node's (so a ray visits them roughly near to far by its own octant), and
 * each slot has a meta byte: 0 an empty slot; CW_META_CHILD | (24 + slot)
 * an inner child, the node child_base + the inner children in the slots
 * before it (imask has a bit per inner slot); CW_META_CHILD | j (j < 8) a
 * leaf, the range leaf_base + j of the leaf-range array.
 *
 * The leaves differ from the paper's: there a leaf's meta holds its
 * triangles' offset from a per-node triangle base and their count (up to
 * 3, in unary), the triangles copied into a compressed array beside the
 * nodes. bvhlab keeps its leaves as they were built: a leaf range is the
 * source tree's (first, count) into prim_index, any count, the triangles
 * staying in the scene's arrays (the device tracer's slot-order copy), so
 * the triangle test is the stack kernel's, hit for hit. That costs one
 * 8-byte range a leaf and one more read per leaf entered.
 *
 * A plane is decoded as p + q * 2^(e - 127) in float (no fused
 * multiply-add: the encoder checks the very value the kernel computes),
 * and the encoder picks q so the decoded box holds the child's exact box:
 * lo rounded down, hi up. A larger box only costs extra visits; the slab
 * test is monotone in the planes, so no ray misses a box it entered before.
 */
#ifndef BVHLAB_CWBVH_NODE_H
#define BVHLAB_CWBVH_NODE_H

#define CW_WIDTH 8
/* A meta byte's mark of a used slot, and the bit of an inner child's
 * 24 + slot (a leaf's range offset stays below 24). */
#define CW_META_CHILD 0x20u
#define CW_META_INNER_BASE 24u
#define CW_NODE_BYTES 80

#ifdef __OPENCL_VERSION__
typedef uchar cw_u8;
typedef uint cw_u32;
#define CW_GLOBAL __global
#define CW_POPCOUNT(x) popcount(x)
#else
#include <stdint.h>
#include <string.h>
typedef uint8_t cw_u8;
typedef uint32_t cw_u32;
#define CW_GLOBAL
#define CW_POPCOUNT(x) ((cw_u32)__builtin_popcount(x))
#endif

typedef struct cw_node {
	float p[3];         /* the grid's origin: the children's least corner */
	cw_u8 e[3];         /* per axis, the scale's biased exponent (0: scale 0) */
	cw_u8 imask;        /* bit s: slot s holds an inner child */
	cw_u32 child_base;  /* the first inner child's node index */
	cw_u32 leaf_base;   /* the first leaf range's index */
	cw_u8 meta[8];      /* per slot: empty, inner or leaf (above) */
	cw_u8 qlo[3][8];    /* per axis and slot, the box's low plane on the grid */
	cw_u8 qhi[3][8];    /* ... and its high plane */
} cw_node;

/* The scale of axis k: the float whose exponent field is e (e = 0: 0). */
static inline float cw_scale(cw_u8 e)
{
#ifdef __OPENCL_VERSION__
	return as_float((uint)e << 23);
#else
	float f;
	cw_u32 bits = (cw_u32)e << 23;
	memcpy(&f, &bits, sizeof(f));
	return f;
#endif
}

/* Grid value q of axis k as the kernel reads it. */
static inline float cw_plane(const CW_GLOBAL cw_node *n, int k, cw_u8 q)
{
	return n->p[k] + (float)q * cw_scale(n->e[k]);
}

/* Whether slot s holds an inner child (then its node is child_base plus
 * the inner slots before s), a leaf (its range leaf_base + the low bits). */
static inline int cw_is_inner(cw_u8 meta)
{
	return (meta & CW_META_CHILD) && (meta & 31u) >= CW_META_INNER_BASE;
}

/* Slot s's child (a used slot): an inner one's node index, a leaf's range
 * index. */
static inline cw_u32 cw_child(const CW_GLOBAL cw_node *n, cw_u32 s)
{
	cw_u32 below = (cw_u32)n->imask & ((1u << s) - 1u);
	if (cw_is_inner(n->meta[s]))
		return n->child_base + CW_POPCOUNT(below);
	return n->leaf_base + (n->meta[s] & 31u);
}

#endif /* BVHLAB_CWBVH_NODE_H */
