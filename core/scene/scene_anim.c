/*
 * Posing a mesh at a moment of an animation (scene_anim.h). Every pose is
 * computed from the rest mesh, never from the previous frame, so frame k
 * is the same whichever frames were made before it.
 */
#include <errno.h>
#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "scene/scene_anim.h"
#include "scene/scene_private.h"

#define PI 3.14159265358979323846

static double extent_of(const bvhlab_scene *s)
{
	double d = 0;
	for (int k = 0; k < 3; k++) {
		double e = (double)s->bounds.hi[k] - s->bounds.lo[k];
		d += e > 0 ? e * e : 0;
	}
	return d > 0 ? sqrt(d) : 1;
}

/* A copy of base's arrays, names and counts. */
static int copy_scene(const bvhlab_scene *base, uint32_t vertices, bvhlab_scene **out,
                      bvhlab_error *err)
{
	int r = scene_alloc(vertices, base->triangle_count, out, err);
	if (r < 0)
		return r;
	(*out)->part_count = base->part_count;
	(*out)->name = base->name ? strdup(base->name) : NULL;
	(*out)->source = base->source ? strdup(base->source) : NULL;
	if ((base->name && !(*out)->name) || (base->source && !(*out)->source)) {
		bvhlab_scene_destroy(*out);
		*out = NULL;
		scene_error(err, "out of memory posing scene '%s'", base->name ? base->name : "");
		return -ENOMEM;
	}
	return 0;
}

int scene_anim_unshare(const bvhlab_scene *base, bvhlab_scene **out, bvhlab_error *err)
{
	if ((uint64_t)base->triangle_count * 3 > UINT32_MAX) {
		scene_error(err, "scene '%s': %u triangles are too many to explode", base->name,
		            base->triangle_count);
		return -EOVERFLOW;
	}
	int r = copy_scene(base, 3 * base->triangle_count, out, err);
	if (r < 0)
		return r;
	for (uint32_t k = 0; k < 3 * base->triangle_count; k++) {
		memcpy((*out)->vertices + 3 * (size_t)k, base->vertices + 3 * (size_t)base->indices[k],
		       3 * sizeof(float));
		(*out)->indices[k] = k;
	}
	bvhlab_scene_update(*out);
	return 0;
}

/* Area-weighted vertex normals (unit, or zero for an unused vertex). */
static float *vertex_normals(const bvhlab_scene *s)
{
	float *n = calloc(3 * (size_t)s->vertex_count, sizeof(*n));
	for (uint32_t t = 0; n && t < s->triangle_count; t++) {
		const uint32_t *ix = s->indices + 3 * (size_t)t;
		const float *a = s->vertices + 3 * (size_t)ix[0], *b = s->vertices + 3 * (size_t)ix[1],
		            *c = s->vertices + 3 * (size_t)ix[2];
		float e[3] = {b[0] - a[0], b[1] - a[1], b[2] - a[2]};
		float f[3] = {c[0] - a[0], c[1] - a[1], c[2] - a[2]};
		float x[3] = {e[1] * f[2] - e[2] * f[1], e[2] * f[0] - e[0] * f[2],
		              e[0] * f[1] - e[1] * f[0]};
		for (int j = 0; j < 3; j++)
			for (int k = 0; k < 3; k++)
				n[3 * (size_t)ix[j] + k] += x[k];
	}
	for (uint32_t v = 0; n && v < s->vertex_count; v++) {
		float *p = n + 3 * (size_t)v;
		double len = sqrt((double)p[0] * p[0] + (double)p[1] * p[1] + (double)p[2] * p[2]);
		for (int k = 0; k < 3 && len > 0; k++)
			p[k] = (float)(p[k] / len);
	}
	return n;
}

/* Displacement along the normals by a sine travelling along the box's
 * longest axis, two wavelengths over the animation, half the extent long. */
static int wave(bvhlab_scene *s, const bvhlab_scene *base, double amp, double t)
{
	float *n = vertex_normals(base);
	double ext = extent_of(base), ramp = t < 0.25 ? 4 * t : 1, lambda = ext / 2;
	int axis = 0;
	if (!n)
		return -ENOMEM;
	for (int k = 1; k < 3; k++)
		if (base->bounds.hi[k] - base->bounds.lo[k] >
		    base->bounds.hi[axis] - base->bounds.lo[axis])
			axis = k;
	for (uint32_t v = 0; v < s->vertex_count; v++) {
		float *p = s->vertices + 3 * (size_t)v;
		double u = p[axis] - base->bounds.lo[axis];
		double d = amp * ext * ramp * sin(2 * PI * (u / lambda - 2 * t));
		for (int k = 0; k < 3; k++)
			p[k] += (float)(d * n[3 * (size_t)v + k]);
	}
	free(n);
	return 0;
}

/* splitmix64: the k-th triangle's random numbers from the seed alone. */
static uint64_t mix(uint64_t x)
{
	x += 0x9e3779b97f4a7c15ULL;
	x = (x ^ (x >> 30)) * 0xbf58476d1ce4e5b9ULL;
	x = (x ^ (x >> 27)) * 0x94d049bb133111ebULL;
	return x ^ (x >> 31);
}

static double unit(uint64_t *state)
{
	*state = mix(*state);
	return (double)(*state >> 11) / 9007199254740992.0;
}

/* Triangle k's direction: away from the centre, turned by a random one. */
static void explode_dir(const bvhlab_scene *base, uint32_t k, uint64_t seed, double dir[3],
                        double *speed)
{
	const uint32_t *ix = base->indices + 3 * (size_t)k;
	uint64_t state = seed ^ mix(k);
	double len = 0;
	for (int a = 0; a < 3; a++) {
		double c = (base->vertices[3 * (size_t)ix[0] + a] + base->vertices[3 * (size_t)ix[1] + a] +
		            base->vertices[3 * (size_t)ix[2] + a]) / 3.0;
		double centre = 0.5 * ((double)base->bounds.lo[a] + base->bounds.hi[a]);
		dir[a] = (c - centre) / extent_of(base) + (unit(&state) - 0.5);
		len += dir[a] * dir[a];
	}
	len = len > 0 ? sqrt(len) : 1;
	for (int a = 0; a < 3; a++)
		dir[a] /= len;
	*speed = 0.5 + unit(&state);
}

static void explode(bvhlab_scene *s, const bvhlab_scene *base, double amp, uint64_t seed,
                    double t)
{
	double dist = amp * extent_of(base) * t;
	for (uint32_t k = 0; k < s->triangle_count; k++) {
		double dir[3], speed;
		explode_dir(base, k, seed, dir, &speed);
		for (int j = 0; j < 3; j++) {
			float *p = s->vertices + 3 * (size_t)s->indices[3 * (size_t)k + j];
			for (int a = 0; a < 3; a++)
				p[a] += (float)(dist * speed * dir[a]);
		}
	}
}

/* The rest placement moved t of the way to its offset. */
static void placement(const struct scene_motion *m, double t, bvhlab_transform *xf)
{
	*xf = m->rest;
	if (!m->rigid)
		return;
	xf->scale = m->rest.scale * (1 + (m->scale - 1) * t);
	for (int k = 0; k < 3; k++) {
		xf->rotate[k] += t * m->rotate[k];
		xf->translate[k] += t * m->translate[k];
	}
}

int scene_anim_pose(const bvhlab_scene *base, const struct scene_motion *m, double t,
                    bvhlab_scene **out, bvhlab_error *err)
{
	bvhlab_transform xf;
	int r = copy_scene(base, base->vertex_count, out, err);
	if (r < 0)
		return r;
	memcpy((*out)->vertices, base->vertices, 3 * (size_t)base->vertex_count * sizeof(float));
	memcpy((*out)->indices, base->indices, 3 * (size_t)base->triangle_count * sizeof(uint32_t));
	if (m->deform == SCENE_DEFORM_WAVE)
		r = wave(*out, base, m->amplitude > 0 ? m->amplitude : SCENE_WAVE_AMPLITUDE, t);
	else if (m->deform == SCENE_DEFORM_EXPLODE)
		explode(*out, base, m->amplitude > 0 ? m->amplitude : SCENE_EXPLODE_AMPLITUDE, m->seed,
		        t);
	if (r < 0) {
		bvhlab_scene_destroy(*out);
		*out = NULL;
		scene_error(err, "out of memory posing scene '%s'", base->name ? base->name : "");
		return r;
	}
	placement(m, t, &xf);
	bvhlab_scene_transform(*out, &xf);
	return 0;
}
