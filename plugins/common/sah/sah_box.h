/*
 * Box and centroid helpers of the SAH kernel's sources. Every helper fixes
 * its operation order: the trees are compared bit for bit across methods,
 * SIMD paths and schedulers.
 */
#ifndef BVHLAB_SAH_BOX_H
#define BVHLAB_SAH_BOX_H

#include <math.h>

#include "sah_types.h"

/* Comparisons rather than fminf/fmaxf: they compile to single min/max
 * instructions, and primitive boxes are never NaN. */
static inline float minf(float a, float b)
{
	return a < b ? a : b;
}

static inline float maxf(float a, float b)
{
	return a > b ? a : b;
}

static inline void box_empty(bvhlab_aabb *b)
{
	for (int k = 0; k < 3; k++) {
		b->lo[k] = INFINITY;
		b->hi[k] = -INFINITY;
	}
}

static inline void box_grow(bvhlab_aabb *b, const bvhlab_aabb *p)
{
	for (int k = 0; k < 3; k++) {
		b->lo[k] = minf(b->lo[k], p->lo[k]);
		b->hi[k] = maxf(b->hi[k], p->hi[k]);
	}
}

/* Half the surface area: the factor 2 cancels in every SAH ratio. */
static inline float box_half_area(const bvhlab_aabb *b)
{
	float dx = b->hi[0] - b->lo[0], dy = b->hi[1] - b->lo[1], dz = b->hi[2] - b->lo[2];
	return dx * dy + dy * dz + dz * dx;
}

/* The kernel's one definition of a centroid (see sah_prim). */
static inline float prim_centroid(const sah_prim *p, int axis)
{
	return 0.5f * (p->lo[axis] + p->hi[axis]);
}

static inline void prim_box(const sah_prim *p, bvhlab_aabb *box)
{
	for (int k = 0; k < 3; k++) {
		box->lo[k] = p->lo[k];
		box->hi[k] = p->hi[k];
	}
}

/* Grows b by the box of p. */
static inline void box_grow_prim(bvhlab_aabb *b, const sah_prim *p)
{
	for (int k = 0; k < 3; k++) {
		b->lo[k] = minf(b->lo[k], p->lo[k]);
		b->hi[k] = maxf(b->hi[k], p->hi[k]);
	}
}

/* Grows b by the centroid of p. */
static inline void box_grow_centroid(bvhlab_aabb *b, const sah_prim *p)
{
	for (int k = 0; k < 3; k++) {
		float c = prim_centroid(p, k);
		b->lo[k] = minf(b->lo[k], c);
		b->hi[k] = maxf(b->hi[k], c);
	}
}

#endif /* BVHLAB_SAH_BOX_H */
