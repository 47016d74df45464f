/*
 * bvhlab — clipping a convex polygon by axis-aligned planes, header-only:
 * the one clipper of the validator's coverage check (core/tree) and of the
 * spatial-split builders (plugins/common/clip), so what a builder cuts and
 * what the validator measures are computed alike.
 *
 * Sutherland-Hodgman in double, so clipping a float triangle by a few
 * planes does not drift; a point on the plane is kept and a crossing gets
 * x[axis] = at exactly, so pieces either side of one plane share it.
 */
#ifndef BVHLAB_CLIP_H
#define BVHLAB_CLIP_H

#include <math.h>
#include <stddef.h>
#include <stdint.h>
#include <string.h>

#include "types.h"

BVHLAB_BEGIN_DECLS

/* A triangle clipped by the 6 planes of a box has at most 9 corners and
 * each further plane adds at most one; corners past this many are dropped. */
#define BVHLAB_POLY_MAX 16

/* A convex polygon; n == 0 is empty. */
typedef struct bvhlab_poly {
	int n;                          /* corners in use */
	double v[BVHLAB_POLY_MAX][3];   /* corners, in order around the polygon */
} bvhlab_poly;

/* The part of p with sign * (x[axis] - at) >= 0 into out (sign +1 keeps
 * what lies at or above the plane, -1 what lies at or below it). */
static inline void bvhlab_poly_clip(const bvhlab_poly *p, int axis, double at, double sign,
                                    bvhlab_poly *out)
{
	out->n = 0;
	for (int i = 0; i < p->n; i++) {
		const double *a = p->v[i], *b = p->v[i + 1 < p->n ? i + 1 : 0];
		double da = sign * (a[axis] - at), db = sign * (b[axis] - at);

		if (da >= 0.0 && out->n < BVHLAB_POLY_MAX)
			memcpy(out->v[out->n++], a, sizeof(out->v[0]));
		if (((da < 0.0 && db > 0.0) || (da > 0.0 && db < 0.0)) &&
		    out->n < BVHLAB_POLY_MAX) {
			double t = da / (da - db), *c = out->v[out->n++];

			for (int k = 0; k < 3; k++)
				c[k] = a[k] + t * (b[k] - a[k]);
			c[axis] = at;
		}
	}
}

/* Triangle `tri` (three vertex indices into vertices[3 * i]) as a polygon. */
static inline void bvhlab_poly_triangle(bvhlab_poly *p, const float *vertices,
                                        const uint32_t *tri)
{
	p->n = 3;
	for (int j = 0; j < 3; j++)
		for (int k = 0; k < 3; k++)
			p->v[j][k] = vertices[3 * (size_t)tri[j] + k];
}

/* Keeps the part of p inside the closed box lo[3], hi[3], in place. */
static inline void bvhlab_poly_clip_box(bvhlab_poly *p, const double lo[3], const double hi[3])
{
	bvhlab_poly tmp;

	for (int k = 0; k < 3 && p->n > 0; k++) {
		bvhlab_poly_clip(p, k, lo[k], 1.0, &tmp);
		bvhlab_poly_clip(&tmp, k, hi[k], -1.0, p);
	}
}

/* Area of p (one side), from the fan of triangles about its first corner. */
static inline double bvhlab_poly_area(const bvhlab_poly *p)
{
	double s[3] = { 0.0, 0.0, 0.0 };

	for (int i = 1; i + 1 < p->n; i++) {
		const double *a = p->v[0], *b = p->v[i], *c = p->v[i + 1];
		double e[3] = { b[0] - a[0], b[1] - a[1], b[2] - a[2] };
		double f[3] = { c[0] - a[0], c[1] - a[1], c[2] - a[2] };

		s[0] += e[1] * f[2] - e[2] * f[1];
		s[1] += e[2] * f[0] - e[0] * f[2];
		s[2] += e[0] * f[1] - e[1] * f[0];
	}
	return 0.5 * sqrt(s[0] * s[0] + s[1] * s[1] + s[2] * s[2]);
}

BVHLAB_END_DECLS

#endif /* BVHLAB_CLIP_H */
