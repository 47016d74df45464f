/*
 * The "needles" generator: long, thin triangles crossing the unit cube in
 * every direction. Each joins a uniformly random point on one face of the
 * cube to a uniformly random point on the opposite face (the pair of faces
 * chosen at random), the third vertex `width` from the first, at right
 * angles to the needle in a random direction. The needles are mostly
 * diagonal to the axes, so their boxes are huge for their area and overlap
 * everywhere: the case spatial splits are made for. They do not all meet
 * in one place because both ends are spread over whole faces.
 */
#include <errno.h>
#include <math.h>
#include <stdio.h>

#include "scene/scene_private.h"
#include "util/util.h"

#define NEEDLES_MAX_COUNT (UINT32_MAX / 3) /* three unshared vertices each */

static double random01(uint64_t *state)
{
	return (double)(util_splitmix64(state) >> 11) * 0x1.0p-53;
}

/* A uniformly random point on the face x[axis] = side of the unit cube. */
static void face_point(uint64_t *state, int axis, double side, double p[3])
{
	for (int k = 0; k < 3; k++)
		p[k] = k == axis ? side : random01(state);
}

/* Unit vector at right angles to d (|d| > 0): a random direction with its
 * component along d removed; retried in the rare case it was parallel. */
static void perpendicular(uint64_t *state, const double d[3], double out[3])
{
	double dd = d[0] * d[0] + d[1] * d[1] + d[2] * d[2], len;

	do {
		double r[3], dot = 0.0;

		for (int k = 0; k < 3; k++)
			r[k] = 2.0 * random01(state) - 1.0;
		for (int k = 0; k < 3; k++)
			dot += r[k] * d[k];
		for (int k = 0; k < 3; k++)
			out[k] = r[k] - dot / dd * d[k];
		len = sqrt(out[0] * out[0] + out[1] * out[1] + out[2] * out[2]);
	} while (!(len > 1e-6));
	for (int k = 0; k < 3; k++)
		out[k] /= len;
}

static void needle(uint64_t *state, double width, float *v)
{
	int axis = (int)(util_splitmix64(state) % 3);
	double side = util_splitmix64(state) & 1 ? 1.0 : 0.0;
	double a[3], b[3], d[3], n[3];

	face_point(state, axis, side, a);
	face_point(state, axis, 1.0 - side, b);
	for (int k = 0; k < 3; k++)
		d[k] = b[k] - a[k];
	perpendicular(state, d, n);
	for (int k = 0; k < 3; k++) {
		v[k] = (float)a[k];
		v[3 + k] = (float)b[k];
		v[6 + k] = (float)(a[k] + width * n[k]);
	}
}

int scene_gen_needles(const bvhlab_gen_params *params, bvhlab_scene **out, char *source,
                      size_t source_size, bvhlab_error *err)
{
	bvhlab_scene *scene = NULL;
	uint64_t state = params->seed;
	int ret;

	if (params->count < 1 || params->count > NEEDLES_MAX_COUNT) {
		scene_error(err, "needles: count must be 1 to %u triangles, got %u",
		            NEEDLES_MAX_COUNT, params->count);
		return -EINVAL;
	}
	if (!(params->width > 0.0 && params->width <= 1.0)) {
		scene_error(err, "needles: width must be > 0 and at most 1 (the cube's side), "
		            "got %g", params->width);
		return -EINVAL;
	}
	ret = scene_alloc(3 * params->count, params->count, &scene, err);
	if (ret)
		return ret;
	for (uint32_t t = 0; t < params->count; t++) {
		needle(&state, params->width, scene->vertices + 9 * (size_t)t);
		for (uint32_t j = 0; j < 3; j++)
			scene->indices[3 * (size_t)t + j] = 3 * t + j;
	}
	snprintf(source, source_size, "needles count=%u seed=%llu width=%g", params->count,
	         (unsigned long long)params->seed, params->width);
	*out = scene;
	return 0;
}
