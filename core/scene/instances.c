/*
 * Two-level scenes: meshes kept once, instances placing them (instances.h).
 * Matrices are doubles here; rays are carried into an instance with the
 * inverse, so a two-level hit is the flattened scene's up to the floats
 * the flattened vertices are rounded to.
 */
#include <errno.h>
#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "scene/instances.h"
#include "scene/scene_private.h"
#include "util/util.h"

int scene_matrix_invert(const double m[12], double inv[12])
{
	double a = m[0], b = m[1], c = m[2], d = m[4], e = m[5], f = m[6];
	double g = m[8], h = m[9], k = m[10];
	double c0 = e * k - f * h, c1 = f * g - d * k, c2 = d * h - e * g;
	double det = a * c0 + b * c1 + c * c2;
	/* Relative to the matrix's size, so a tiny but sound scale is no error. */
	double size = 0;
	for (int i = 0; i < 12; i++)
		size = fmax(size, fabs(m[i]) * (i % 4 != 3));
	if (!isfinite(det) || size == 0 || fabs(det) <= 1e-12 * size * size * size)
		return -EINVAL;
	double r[9] = { c0, c * h - b * k, b * f - c * e, c1, a * k - c * g, c * d - a * f,
	                c2, b * g - a * h, a * e - b * d };
	for (int i = 0; i < 3; i++) {
		for (int j = 0; j < 3; j++)
			inv[4 * i + j] = r[3 * i + j] / det;
		inv[4 * i + 3] = -(inv[4 * i] * m[3] + inv[4 * i + 1] * m[7] + inv[4 * i + 2] * m[11]);
	}
	for (int i = 0; i < 12; i++)
		if (!isfinite(inv[i]) || !isfinite(m[i]))
			return -EINVAL;
	return 0;
}

void scene_instanced_init(struct scene_instanced *s, bvhlab_scene **meshes, uint32_t count)
{
	memset(s, 0, sizeof(*s));
	s->meshes = meshes;
	s->mesh_count = count;
}

static int grow(struct scene_instanced *s, uint64_t more, bvhlab_error *err)
{
	uint64_t want = (uint64_t)s->instance_count + more;
	if (want > UINT32_MAX) {
		scene_error(err, "more than %u instances", UINT32_MAX);
		return -EOVERFLOW;
	}
	if (want <= s->instance_capacity)
		return 0;
	uint64_t cap = s->instance_capacity ? 2 * (uint64_t)s->instance_capacity : 16;
	cap = cap < want ? want : cap > UINT32_MAX ? UINT32_MAX : cap;
	void *p = realloc(s->instances, (size_t)cap * sizeof(*s->instances));
	if (!p) {
		scene_error(err, "out of memory for %llu instances", (unsigned long long)want);
		return -ENOMEM;
	}
	s->instances = p;
	s->instance_capacity = (uint32_t)cap;
	return 0;
}

int scene_instanced_add(struct scene_instanced *s, uint32_t mesh, const double xf[12],
                        bvhlab_error *err)
{
	int r = grow(s, 1, err);
	if (r)
		return r;
	if (mesh >= s->mesh_count) {
		scene_error(err, "instance of mesh %u: there are %u meshes", mesh, s->mesh_count);
		return -EINVAL;
	}
	struct scene_instance *in = &s->instances[s->instance_count];
	in->mesh = mesh;
	memcpy(in->xf, xf, sizeof(in->xf));
	if (scene_matrix_invert(in->xf, in->inv)) {
		scene_error(err, "instance %u: its matrix is singular or not finite",
		            s->instance_count);
		return -EINVAL;
	}
	s->instance_count++;
	return 0;
}

/* A double in [0, 1) from the generator's 53 high bits. */
static double unit(uint64_t *state)
{
	return (double)(util_splitmix64(state) >> 11) * (1.0 / 9007199254740992.0);
}

int scene_instanced_scatter(struct scene_instanced *s, const struct scene_scatter *sc,
                            bvhlab_error *err)
{
	uint64_t state = sc->seed;
	int r = grow(s, sc->count, err);
	for (uint32_t i = 0; r == 0 && i < sc->count; i++) {
		bvhlab_transform xf;
		bvhlab_transform_init(&xf);
		for (int k = 0; k < 3; k++)
			xf.translate[k] = sc->lo[k] + (sc->hi[k] - sc->lo[k]) * unit(&state);
		xf.scale = sc->scale[0] + (sc->scale[1] - sc->scale[0]) * unit(&state);
		xf.rotate[1] = sc->random_y ? 360.0 * unit(&state) : 0.0;
		double m[12];
		scene_transform_matrix(&xf, m);
		r = scene_instanced_add(s, sc->mesh, m, err);
	}
	return r;
}

void scene_instanced_box(const struct scene_instanced *s, uint32_t i, bvhlab_aabb *out)
{
	const struct scene_instance *in = &s->instances[i];
	const bvhlab_aabb *b = &s->meshes[in->mesh]->bounds;
	float lo[3] = {INFINITY, INFINITY, INFINITY}, hi[3] = {-INFINITY, -INFINITY, -INFINITY};
	for (int c = 0; c < 8; c++) {
		double p[3] = { c & 1 ? b->hi[0] : b->lo[0], c & 2 ? b->hi[1] : b->lo[1],
		                c & 4 ? b->hi[2] : b->lo[2] }, q[3];
		scene_matrix_apply(in->xf, p, 1.0, q);
		for (int k = 0; k < 3; k++) {
			/* Rounded outwards: the float box holds the exact one. */
			lo[k] = fminf(lo[k], nextafterf((float)q[k], -INFINITY));
			hi[k] = fmaxf(hi[k], nextafterf((float)q[k], INFINITY));
		}
	}
	memcpy(out->lo, lo, sizeof(lo));
	memcpy(out->hi, hi, sizeof(hi));
}

uint64_t scene_instanced_unique_triangles(const struct scene_instanced *s)
{
	uint64_t t = 0;
	for (uint32_t m = 0; m < s->mesh_count; m++)
		t += s->meshes[m]->triangle_count;
	return t;
}

uint64_t scene_instanced_triangles(const struct scene_instanced *s)
{
	uint64_t t = 0;
	for (uint32_t i = 0; i < s->instance_count; i++)
		t += s->meshes[s->instances[i].mesh]->triangle_count;
	return t;
}

/* A mesh vertex p placed by instance in, rounded to floats. */
static void place_vertex(const struct scene_instance *in, const float *p, float out[3])
{
	double q[3] = { p[0], p[1], p[2] }, r[3];
	scene_matrix_apply(in->xf, q, 1.0, r);
	for (int k = 0; k < 3; k++)
		out[k] = (float)r[k];
}

/* Instance i's vertices, placed, at dst. */
static void place(const struct scene_instanced *s, uint32_t i, float *dst)
{
	const bvhlab_scene *m = s->meshes[s->instances[i].mesh];
	for (uint32_t v = 0; v < m->vertex_count; v++)
		place_vertex(&s->instances[i], m->vertices + 3 * (size_t)v, dst + 3 * (size_t)v);
}

int scene_instanced_flatten(const struct scene_instanced *s, const char *name,
                            bvhlab_scene **out, bvhlab_error *err)
{
	uint64_t v = 0, t = scene_instanced_triangles(s);
	for (uint32_t i = 0; i < s->instance_count; i++)
		v += s->meshes[s->instances[i].mesh]->vertex_count;
	if (v > UINT32_MAX || t > UINT32_MAX) {
		scene_error(err, "%s: flattened, %llu vertices and %llu triangles are past the "
		            "one-level limit of %u each", name, (unsigned long long)v,
		            (unsigned long long)t, UINT32_MAX);
		return -EOVERFLOW;
	}
	bvhlab_scene *scene = NULL;
	int r = scene_alloc((uint32_t)v, (uint32_t)t, &scene, err);
	if (r)
		return r;
	size_t vbase = 0, tbase = 0;
	for (uint32_t i = 0; i < s->instance_count; i++) {
		const bvhlab_scene *m = s->meshes[s->instances[i].mesh];
		place(s, i, scene->vertices + 3 * vbase);
		for (size_t k = 0; k < 3 * (size_t)m->triangle_count; k++)
			scene->indices[3 * tbase + k] = m->indices[k] + (uint32_t)vbase;
		vbase += m->vertex_count;
		tbase += m->triangle_count;
	}
	scene->part_count = s->instance_count;
	if (bvhlab_scene_set_name(scene, name) ||
	    scene_set_source(scene, "two-level scene, flattened")) {
		bvhlab_scene_destroy(scene);
		scene_error(err, "%s: out of memory", name);
		return -ENOMEM;
	}
	bvhlab_scene_update(scene);
	*out = scene;
	return 0;
}

void scene_instanced_finish(struct scene_instanced *s)
{
	for (uint32_t m = 0; s->meshes && m < s->mesh_count; m++)
		bvhlab_scene_destroy(s->meshes[m]);
	free(s->meshes);
	free(s->instances);
	memset(s, 0, sizeof(*s));
}
