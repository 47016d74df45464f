/*
 * Ray generation: a pinhole camera's primary rays, and from their hits
 * cosine-weighted diffuse bounces, shadow rays toward a point light and
 * short ambient-occlusion rays. Every number here is derived from the
 * scene and a seed, so two builders are always measured with identical rays.
 */
#include <errno.h>
#include <math.h>
#include <stdlib.h>
#include <string.h>

#include <bvhlab/aabb.h>
#include <bvhlab/trace.h>

#include "util/util.h"

#define PI_F 3.14159265358979f
/* Fraction of the scene's diagonal a bounce starts above its surface:
 * enough to clear float rounding of the hit point, far below any feature. */
#define OFFSET_SCALE 1e-5f

static void sub3(const float a[3], const float b[3], float out[3])
{
	for (int k = 0; k < 3; k++)
		out[k] = a[k] - b[k];
}

static void cross3(const float a[3], const float b[3], float out[3])
{
	out[0] = a[1] * b[2] - a[2] * b[1];
	out[1] = a[2] * b[0] - a[0] * b[2];
	out[2] = a[0] * b[1] - a[1] * b[0];
}

static float dot3(const float a[3], const float b[3])
{
	return a[0] * b[0] + a[1] * b[1] + a[2] * b[2];
}

/* False (and v untouched) for a zero or non-finite vector. */
static bool normalize3(float v[3])
{
	float len = sqrtf(dot3(v, v));
	if (!(len > 0.0f) || !isfinite(len))
		return false;
	for (int k = 0; k < 3; k++)
		v[k] /= len;
	return true;
}

void bvhlab_camera_frame(const bvhlab_aabb *bounds, bvhlab_camera *camera)
{
	float dir[3] = {1.0f, 0.6f, 1.4f}, centre[3] = {0, 0, 0}, radius = 1.0f;
	memset(camera, 0, sizeof(*camera));
	camera->up[1] = 1.0f;
	camera->fov_deg = 45.0f;
	if (bvhlab_aabb_is_empty(bounds)) {
		camera->position[2] = 1.0f;
		return;
	}
	float diag[3];
	sub3(bounds->hi, bounds->lo, diag);
	for (int k = 0; k < 3; k++)
		centre[k] = 0.5f * (bounds->lo[k] + bounds->hi[k]);
	radius = 0.5f * sqrtf(dot3(diag, diag));
	if (!(radius > 0.0f))
		radius = 1.0f;
	normalize3(dir);
	/* The sphere fits when its tangent cone's half-angle is half the fov. */
	float dist = radius / sinf(0.5f * camera->fov_deg * PI_F / 180.0f);
	for (int k = 0; k < 3; k++) {
		camera->target[k] = centre[k];
		camera->position[k] = centre[k] + dir[k] * dist;
	}
}

/* The camera's orthonormal basis scaled to the image plane at distance 1. */
static bool camera_basis(const bvhlab_camera *c, uint32_t w, uint32_t h, float fwd[3],
                         float right[3], float up[3])
{
	sub3(c->target, c->position, fwd);
	if (!normalize3(fwd) || !(c->fov_deg > 0.0f && c->fov_deg < 180.0f))
		return false;
	cross3(fwd, c->up, right);
	if (!normalize3(right))
		return false;
	cross3(right, fwd, up);
	float half_h = tanf(0.5f * c->fov_deg * PI_F / 180.0f);
	float half_w = half_h * (float)w / (float)h;
	for (int k = 0; k < 3; k++) {
		right[k] *= half_w;
		up[k] *= half_h;
	}
	return true;
}

int bvhlab_rays_primary(const bvhlab_camera *camera, uint32_t width, uint32_t height,
                        bvhlab_ray **rays)
{
	float fwd[3], right[3], up[3];
	*rays = NULL;
	if (width == 0 || height == 0 || !camera_basis(camera, width, height, fwd, right, up))
		return -EINVAL;
	bvhlab_ray *r = malloc((size_t)width * height * sizeof(*r));
	if (!r)
		return -ENOMEM;
	for (uint32_t y = 0; y < height; y++) {
		float sy = 1.0f - 2.0f * ((float)y + 0.5f) / (float)height;
		for (uint32_t x = 0; x < width; x++) {
			float sx = 2.0f * ((float)x + 0.5f) / (float)width - 1.0f;
			bvhlab_ray *ray = &r[(size_t)y * width + x];
			for (int k = 0; k < 3; k++) {
				ray->org[k] = camera->position[k];
				ray->dir[k] = fwd[k] + sx * right[k] + sy * up[k];
			}
			normalize3(ray->dir);
			ray->tmin = 0.0f;
			ray->tmax = INFINITY;
		}
	}
	*rays = r;
	return 0;
}

void bvhlab_triangle_normal(const bvhlab_scene *scene, uint32_t prim, float normal[3])
{
	const uint32_t *idx = scene->indices + 3 * (size_t)prim;
	const float *v0 = scene->vertices + 3 * (size_t)idx[0];
	const float *v1 = scene->vertices + 3 * (size_t)idx[1];
	const float *v2 = scene->vertices + 3 * (size_t)idx[2];
	float e1[3], e2[3];
	sub3(v1, v0, e1);
	sub3(v2, v0, e2);
	cross3(e1, e2, normal);
	if (!normalize3(normal))
		normal[0] = normal[1] = normal[2] = 0.0f;
}

/* Uniform in [0, 1) from the top 24 bits: exactly representable floats. */
static float uniform(uint64_t *state)
{
	return (float)(util_splitmix64(state) >> 40) * (1.0f / 16777216.0f);
}

/* Any unit vector perpendicular to n (Duff et al. 2017, branchless ONB). */
static void tangents(const float n[3], float t[3], float b[3])
{
	float sign = copysignf(1.0f, n[2]);
	float a = -1.0f / (sign + n[2]);
	float c = n[0] * n[1] * a;
	t[0] = 1.0f + sign * n[0] * n[0] * a;
	t[1] = sign * c;
	t[2] = -sign * n[0];
	b[0] = c;
	b[1] = sign + n[1] * n[1] * a;
	b[2] = -n[1];
}

/* Cosine-weighted direction around n (Malley: uniform disc, lifted). */
static void cosine_dir(const float n[3], uint64_t *state, float dir[3])
{
	float t[3], b[3];
	float r = sqrtf(uniform(state)), phi = 2.0f * PI_F * uniform(state);
	float x = r * cosf(phi), y = r * sinf(phi), z = sqrtf(fmaxf(0.0f, 1.0f - x * x - y * y));
	tangents(n, t, b);
	for (int k = 0; k < 3; k++)
		dir[k] = x * t[k] + y * b[k] + z * n[k];
	normalize3(dir);
}

static float scene_offset(const bvhlab_scene *scene)
{
	float diag[3];
	if (bvhlab_aabb_is_empty(&scene->bounds))
		return OFFSET_SCALE;
	sub3(scene->bounds.hi, scene->bounds.lo, diag);
	float len = sqrtf(dot3(diag, diag));
	return len > 0.0f ? len * OFFSET_SCALE : OFFSET_SCALE;
}

/* Where secondary rays leave a hit: the hit point lifted by offset along
 * the geometric normal turned to face the incoming ray (n, p); false when
 * the triangle has no normal. */
static bool hit_frame(const bvhlab_scene *scene, const bvhlab_ray *in, const bvhlab_hit *hit,
                      float offset, float n[3], float p[3])
{
	bvhlab_triangle_normal(scene, hit->prim, n);
	if (n[0] == 0.0f && n[1] == 0.0f && n[2] == 0.0f)
		return false;
	if (dot3(n, in->dir) > 0.0f)
		for (int k = 0; k < 3; k++)
			n[k] = -n[k];
	for (int k = 0; k < 3; k++)
		p[k] = in->org[k] + hit->t * in->dir[k] + offset * n[k];
	return true;
}

/* What one kind of secondary ray makes of a hit frame: per_hit rays. */
struct secondary {
	uint32_t per_hit;
	uint64_t state;      /* the random directions' */
	float tmax;          /* ao: the rays' length */
	const float *light;  /* shadow: the point light, or NULL */
};

/* The rays of one hit frame into out; false when there are none (a hit
 * on the light itself). */
static bool emit(struct secondary *k, const float n[3], const float p[3], bvhlab_ray *out)
{
	for (uint32_t j = 0; j < k->per_hit; j++) {
		memcpy(out[j].org, p, 3 * sizeof(*p));
		out[j].tmin = 0.0f;
		out[j].tmax = k->tmax;
		if (!k->light) {
			cosine_dir(n, &k->state, out[j].dir);
			continue;
		}
		/* Toward the light and no further: what lies behind it casts no shadow. */
		sub3(k->light, p, out[j].dir);
		float dist = sqrtf(dot3(out[j].dir, out[j].dir));
		if (!normalize3(out[j].dir))
			return false;
		out[j].tmax = dist;
	}
	return true;
}

/* Secondary rays of kind k from every hit of the primary rays. */
static int secondary_rays(const bvhlab_scene *scene, const bvhlab_ray *primary,
                          const bvhlab_hit *hits, size_t count, struct secondary *k,
                          bvhlab_ray **rays, size_t *ray_count)
{
	size_t n_hits = 0, n = 0;
	*rays = NULL;
	*ray_count = 0;
	for (size_t i = 0; i < count; i++)
		n_hits += hits[i].prim != BVHLAB_NO_HIT;
	if (n_hits == 0 || k->per_hit == 0)
		return 0;
	bvhlab_ray *out = malloc(n_hits * k->per_hit * sizeof(*out));
	if (!out)
		return -ENOMEM;
	float offset = scene_offset(scene), nrm[3], p[3];
	for (size_t i = 0; i < count; i++) {
		if (hits[i].prim != BVHLAB_NO_HIT &&
		    hit_frame(scene, &primary[i], &hits[i], offset, nrm, p) &&
		    emit(k, nrm, p, out + n))
			n += k->per_hit;
	}
	if (n == 0) {
		free(out);
		out = NULL;
	}
	*rays = out;
	*ray_count = n;
	return 0;
}

int bvhlab_rays_diffuse(const bvhlab_scene *scene, const bvhlab_ray *primary,
                        const bvhlab_hit *hits, size_t count, uint32_t per_hit, uint64_t seed,
                        bvhlab_ray **rays, size_t *ray_count)
{
	struct secondary k = {.per_hit = per_hit, .state = seed, .tmax = INFINITY};
	return secondary_rays(scene, primary, hits, count, &k, rays, ray_count);
}

int bvhlab_rays_shadow(const bvhlab_scene *scene, const bvhlab_ray *primary,
                       const bvhlab_hit *hits, size_t count, const float light[3],
                       bvhlab_ray **rays, size_t *ray_count)
{
	struct secondary k = {.per_hit = 1, .light = light};
	return secondary_rays(scene, primary, hits, count, &k, rays, ray_count);
}

int bvhlab_rays_ao(const bvhlab_scene *scene, const bvhlab_ray *primary,
                   const bvhlab_hit *hits, size_t count, float length, uint64_t seed,
                   bvhlab_ray **rays, size_t *ray_count)
{
	/* scene_offset is OFFSET_SCALE of the diagonal (or OFFSET_SCALE itself). */
	float diagonal = scene_offset(scene) / OFFSET_SCALE;
	struct secondary k = {.per_hit = 1, .state = seed, .tmax = length * diagonal};
	return secondary_rays(scene, primary, hits, count, &k, rays, ray_count);
}

void bvhlab_light_frame(const bvhlab_aabb *bounds, float light[3])
{
	float c[3] = {0, 0, 0}, diag[3] = {1, 1, 1};
	if (!bvhlab_aabb_is_empty(bounds)) {
		sub3(bounds->hi, bounds->lo, diag);
		for (int k = 0; k < 3; k++)
			c[k] = 0.5f * (bounds->lo[k] + bounds->hi[k]);
	}
	float len = sqrtf(dot3(diag, diag));
	/* Above the scene and off to the camera's side, so shadows fall across
	 * what the camera sees instead of straight down behind everything. */
	light[0] = c[0] + 0.3f * len;
	light[1] = c[1] + len;
	light[2] = c[2] + 0.5f * len;
}

