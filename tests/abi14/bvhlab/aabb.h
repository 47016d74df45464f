/*
 * bvhlab — box helpers, header-only: the one definition of an empty box,
 * growing a box, its centre and its surface area, for the core, the tests
 * and plugins alike.
 *
 * The operation order is the SAH kernel's and is part of the contract:
 * min/max are comparisons (a < b ? a : b), not fminf/fmaxf, so a compiler
 * turns them into single minps/maxps instructions and a SIMD version that
 * does the same per lane gives the same floats, hence the same tree. With
 * finite inputs (loaders reject NaN and infinite coordinates) they equal
 * fminf/fmaxf, signed zeros included. The half area is dx*dy + dy*dz + dz*dx
 * in that order; reordering it changes rounding and can change a split.
 */
#ifndef BVHLAB_AABB_H
#define BVHLAB_AABB_H

#include <math.h>
#include <stdbool.h>

#include "types.h"

BVHLAB_BEGIN_DECLS

/* Smaller of a and b; b when they compare equal (see the top of this file). */
static inline float bvhlab_minf(float a, float b)
{
	return a < b ? a : b;
}

/* Larger of a and b; b when they compare equal. */
static inline float bvhlab_maxf(float a, float b)
{
	return a > b ? a : b;
}

/*
 * Each helper comes in two forms: on a bvhlab_aabb, and on a box given by
 * its corners lo[3], hi[3] (a node's box, a builder's bins, any layout that
 * is not a bvhlab_aabb). The bvhlab_aabb forms call the corner forms.
 */

/* lo = +inf, hi = -inf: growing it by anything gives that thing's box. */
static inline void bvhlab_box_empty(float *lo, float *hi)
{
	for (int k = 0; k < 3; k++) {
		lo[k] = INFINITY;
		hi[k] = -INFINITY;
	}
}

static inline void bvhlab_aabb_empty(bvhlab_aabb *b)
{
	bvhlab_box_empty(b->lo, b->hi);
}

/* True for a box that contains nothing: lo > hi on some axis, or a NaN. */
static inline bool bvhlab_aabb_is_empty(const bvhlab_aabb *b)
{
	return !(b->lo[0] <= b->hi[0] && b->lo[1] <= b->hi[1] && b->lo[2] <= b->hi[2]);
}

/* Grows the box lo[3], hi[3] to contain the box blo[3], bhi[3]. */
static inline void bvhlab_box_grow(float *lo, float *hi, const float *blo, const float *bhi)
{
	for (int k = 0; k < 3; k++) {
		lo[k] = bvhlab_minf(lo[k], blo[k]);
		hi[k] = bvhlab_maxf(hi[k], bhi[k]);
	}
}

/* Grows b to contain the point p[3]. */
static inline void bvhlab_aabb_grow_point(bvhlab_aabb *b, const float *p)
{
	for (int k = 0; k < 3; k++) {
		b->lo[k] = bvhlab_minf(b->lo[k], p[k]);
		b->hi[k] = bvhlab_maxf(b->hi[k], p[k]);
	}
}

/* Grows b to contain the box given by its corners lo[3] and hi[3] (a node's
 * box, or any other layout that is not a bvhlab_aabb). */
static inline void bvhlab_aabb_grow_corners(bvhlab_aabb *b, const float *lo, const float *hi)
{
	bvhlab_box_grow(b->lo, b->hi, lo, hi);
}

/* Grows b to contain the box p. */
static inline void bvhlab_aabb_grow(bvhlab_aabb *b, const bvhlab_aabb *p)
{
	bvhlab_aabb_grow_corners(b, p->lo, p->hi);
}

/* The box centre on one axis: how builders define a primitive's centroid. */
static inline float bvhlab_aabb_center(const bvhlab_aabb *b, int axis)
{
	return 0.5f * (b->lo[axis] + b->hi[axis]);
}

/* Half the surface area, in float: the factor 2 cancels in every SAH ratio.
 * Not for empty boxes. */
static inline float bvhlab_half_area(const float *lo, const float *hi)
{
	float dx = hi[0] - lo[0], dy = hi[1] - lo[1], dz = hi[2] - lo[2];
	return dx * dy + dy * dz + dz * dx;
}

static inline float bvhlab_aabb_half_area(const bvhlab_aabb *b)
{
	return bvhlab_half_area(b->lo, b->hi);
}

/* The full surface area 2(xy + yz + zx) of the box with corners lo[3],
 * hi[3], in double; an inverted (empty) or NaN extent counts as 0 rather
 * than making the area negative or NaN. The reported SAH cost is computed
 * with it, the same for every builder. */
static inline double bvhlab_box_area(const float *lo, const float *hi)
{
	double d[3];
	for (int k = 0; k < 3; k++) {
		d[k] = (double)hi[k] - (double)lo[k];
		if (!(d[k] > 0.0))
			d[k] = 0.0;
	}
	return 2.0 * (d[0] * d[1] + d[1] * d[2] + d[2] * d[0]);
}

BVHLAB_END_DECLS

#endif /* BVHLAB_AABB_H */
