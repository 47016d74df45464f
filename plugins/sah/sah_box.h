/*
 * The SAH kernel's one definition of a primitive's centroid, and its box
 * helpers on working records: the public bvhlab/aabb.h helpers, whose
 * operation order is the kernel's (the trees are compared bit for bit
 * across methods, SIMD paths and schedulers).
 */
#ifndef BVHLAB_SAH_BOX_H
#define BVHLAB_SAH_BOX_H

#include <bvhlab/aabb.h>

#include "sah_types.h"

/* The box centre, as bvhlab_aabb_center (see sah_prim). */
static inline float prim_centroid(const sah_prim *p, int axis)
{
	return 0.5f * (p->lo[axis] + p->hi[axis]);
}

/* Grows b by the centroid of p. */
static inline void box_grow_centroid(bvhlab_aabb *b, const sah_prim *p)
{
	const float c[3] = { prim_centroid(p, 0), prim_centroid(p, 1), prim_centroid(p, 2) };

	bvhlab_aabb_grow_point(b, c);
}

#endif /* BVHLAB_SAH_BOX_H */
