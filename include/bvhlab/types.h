/*
 * bvhlab — basic geometric types shared by the plugin ABI and the core API.
 *
 * Every type here is plain data with a fixed layout; the layouts are part of
 * ABI v1 (see builder.h) and are checked at compile time. Every bvhlab
 * header includes this one, and with it the two macros that let C++
 * include them: BVHLAB_BEGIN_DECLS/BVHLAB_END_DECLS (extern "C") and
 * BVHLAB_STATIC_ASSERT (static_assert in C++, _Static_assert in C11).
 */
#ifndef BVHLAB_TYPES_H
#define BVHLAB_TYPES_H

#include <stddef.h>
#include <stdint.h>

#ifdef __cplusplus
#define BVHLAB_BEGIN_DECLS extern "C" {
#define BVHLAB_END_DECLS }
#define BVHLAB_STATIC_ASSERT(cond, msg) static_assert(cond, msg)
#else
#define BVHLAB_BEGIN_DECLS
#define BVHLAB_END_DECLS
#define BVHLAB_STATIC_ASSERT(cond, msg) _Static_assert(cond, msg)
#endif

BVHLAB_BEGIN_DECLS

/* An axis-aligned box. An empty box has lo = +inf and hi = -inf. */
typedef struct bvhlab_aabb {
	float lo[3];
	float hi[3];
} bvhlab_aabb;

/*
 * The one node layout every builder emits (32 bytes, two per cache line).
 *
 * count == 0: binary inner node; its children are nodes[first] and the node
 *             after it.
 * count has BVHLAB_NODE_INNER set (since ABI 1.5, trees wider than 2):
 *             inner node of k = count & ~BVHLAB_NODE_INNER children, the k
 *             consecutive nodes from nodes[first], 2 <= k <= the tree's
 *             width (bvhlab_build_output.width).
 * otherwise:  leaf of `count` primitives, prim_index[first .. first + count).
 * The root is nodes[0]. Boxes are conservative: a node's box contains the
 * boxes of its children, or of its primitives.
 */
typedef struct bvhlab_node {
	float lo[3];    /* box minimum */
	uint32_t first; /* first child (inner) or first prim_index slot (leaf) */
	float hi[3];    /* box maximum */
	uint32_t count; /* 0 for an inner node, else the leaf's primitive count */
} bvhlab_node;

/* The inner-node mark of a wide node's count (ABI 1.5), and the widest tree. */
#define BVHLAB_NODE_INNER 0x80000000u
#define BVHLAB_MAX_WIDTH 8

BVHLAB_STATIC_ASSERT(sizeof(bvhlab_node) == 32, "bvhlab_node must be 32 bytes");
BVHLAB_STATIC_ASSERT(offsetof(bvhlab_node, first) == 12, "bvhlab_node.first at 12");
BVHLAB_STATIC_ASSERT(offsetof(bvhlab_node, hi) == 16, "bvhlab_node.hi at 16");
BVHLAB_STATIC_ASSERT(offsetof(bvhlab_node, count) == 28, "bvhlab_node.count at 28");
BVHLAB_STATIC_ASSERT(sizeof(bvhlab_aabb) == 24, "bvhlab_aabb must be 24 bytes");

/* A ray segment org + t * dir for t in [tmin, tmax]. */
typedef struct bvhlab_ray {
	float org[3];
	float tmin;
	float dir[3];
	float tmax;
} bvhlab_ray;

#define BVHLAB_NO_HIT UINT32_MAX

/* Closest-hit result: prim is BVHLAB_NO_HIT when the ray missed. */
typedef struct bvhlab_hit {
	float t;
	float u, v; /* barycentrics of the hit on triangle `prim` */
	uint32_t prim;
} bvhlab_hit;

/* Error text filled by core functions that fail; always NUL-terminated. */
typedef struct bvhlab_error {
	char message[512];
} bvhlab_error;

BVHLAB_END_DECLS

#endif /* BVHLAB_TYPES_H */
