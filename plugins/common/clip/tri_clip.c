/*
 * Triangle clipping for spatial splits (see tri_clip.h), on the shared
 * plane clipper of <bvhlab/clip.h>.
 */
#include <math.h>

#include "tri_clip.h"

void tri_poly_clip_box(tri_poly *p, const bvhlab_aabb *box)
{
	double lo[3], hi[3];

	for (int k = 0; k < 3; k++) {
		lo[k] = box->lo[k];
		hi[k] = box->hi[k];
	}
	bvhlab_poly_clip_box(p, lo, hi);
}

void tri_poly_split(const tri_poly *p, int axis, double pos, tri_poly *left,
                    tri_poly *right)
{
	bvhlab_poly_clip(p, axis, pos, -1.0, left);
	bvhlab_poly_clip(p, axis, pos, 1.0, right);
}

/* Largest float <= x, smallest float >= x. */
static float down(double x)
{
	float f = (float)x;

	return (double)f > x ? nextafterf(f, -INFINITY) : f;
}

static float up(double x)
{
	float f = (float)x;

	return (double)f < x ? nextafterf(f, INFINITY) : f;
}

void tri_poly_bounds(const tri_poly *p, const bvhlab_aabb *within, bvhlab_aabb *out)
{
	for (int k = 0; k < 3; k++) {
		double lo = INFINITY, hi = -INFINITY;

		for (int i = 0; i < p->n; i++) {
			lo = p->v[i][k] < lo ? p->v[i][k] : lo;
			hi = p->v[i][k] > hi ? p->v[i][k] : hi;
		}
		out->lo[k] = p->n ? down(lo) : INFINITY;
		out->hi[k] = p->n ? up(hi) : -INFINITY;
		if (p->n && out->lo[k] < within->lo[k])
			out->lo[k] = within->lo[k];
		if (p->n && out->hi[k] > within->hi[k])
			out->hi[k] = within->hi[k];
	}
}

void tri_clip_split(const float *vertices, const uint32_t *tri, const bvhlab_aabb *box,
                    int axis, float pos, bvhlab_aabb *left, bvhlab_aabb *right)
{
	tri_poly p, l, r;

	bvhlab_poly_triangle(&p, vertices, tri);
	tri_poly_clip_box(&p, box);
	tri_poly_split(&p, axis, pos, &l, &r);
	tri_poly_bounds(&l, box, left);
	tri_poly_bounds(&r, box, right);
}
