/*
 * Triangle clipping for spatial splits (see tri_clip.h): Sutherland-Hodgman
 * against axis-aligned planes, in double.
 */
#include <math.h>
#include <string.h>

#include "tri_clip.h"

void tri_poly_triangle(tri_poly *p, const float *vertices, const uint32_t *tri)
{
	p->n = 3;
	for (int j = 0; j < 3; j++)
		for (int k = 0; k < 3; k++)
			p->v[j][k] = vertices[3 * (size_t)tri[j] + k];
}

/* The part of p with sign * (x[axis] - at) >= 0. */
static void clip_plane(const tri_poly *p, int axis, double at, double sign, tri_poly *out)
{
	out->n = 0;
	for (int i = 0; i < p->n; i++) {
		const double *a = p->v[i], *b = p->v[i + 1 < p->n ? i + 1 : 0];
		double da = sign * (a[axis] - at), db = sign * (b[axis] - at);

		if (da >= 0.0 && out->n < TRI_POLY_MAX)
			memcpy(out->v[out->n++], a, sizeof(out->v[0]));
		if (((da < 0.0 && db > 0.0) || (da > 0.0 && db < 0.0)) && out->n < TRI_POLY_MAX) {
			double t = da / (da - db), *c = out->v[out->n++];

			for (int k = 0; k < 3; k++)
				c[k] = a[k] + t * (b[k] - a[k]);
			c[axis] = at;
		}
	}
}

void tri_poly_clip_box(tri_poly *p, const bvhlab_aabb *box)
{
	tri_poly tmp;

	for (int k = 0; k < 3 && p->n > 0; k++) {
		clip_plane(p, k, box->lo[k], 1.0, &tmp);
		clip_plane(&tmp, k, box->hi[k], -1.0, p);
	}
}

void tri_poly_split(const tri_poly *p, int axis, double pos, tri_poly *left,
                    tri_poly *right)
{
	clip_plane(p, axis, pos, -1.0, left);
	clip_plane(p, axis, pos, 1.0, right);
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

double tri_poly_area(const tri_poly *p)
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

void tri_clip_split(const float *vertices, const uint32_t *tri, const bvhlab_aabb *box,
                    int axis, float pos, bvhlab_aabb *left, bvhlab_aabb *right)
{
	tri_poly p, l, r;

	tri_poly_triangle(&p, vertices, tri);
	tri_poly_clip_box(&p, box);
	tri_poly_split(&p, axis, pos, &l, &r);
	tri_poly_bounds(&l, box, left);
	tri_poly_bounds(&r, box, right);
}
