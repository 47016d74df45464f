/*
 * Procedural scenes: geodesic icosphere, random triangle soup, a dense
 * object inside a huge sparse "stadium", and a noise terrain.
 *
 * Everything random comes from splitmix64 seeded by params->seed, so a
 * scene is the same on every machine and C library.
 */
#include <errno.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "scene/scene_private.h"
#include "util/util.h"

/* Uniform in [0, 1). */
static double random01(uint64_t *state)
{
	return (double)(util_splitmix64(state) >> 11) * 0x1.0p-53;
}

#define SOURCE_SIZE 96 /* room for a generator's `source` description */

static uint32_t *put_tri(uint32_t *t, uint32_t a, uint32_t b, uint32_t c)
{
	t[0] = a;
	t[1] = b;
	t[2] = c;
	return t + 3;
}

/* ---- icosphere ------------------------------------------------------------ */

#define ICO_T 1.6180339887498949 /* golden ratio */

static const double ico_vertices[12][3] = {
	{ -1, ICO_T, 0 }, { 1, ICO_T, 0 }, { -1, -ICO_T, 0 }, { 1, -ICO_T, 0 },
	{ 0, -1, ICO_T }, { 0, 1, ICO_T }, { 0, -1, -ICO_T }, { 0, 1, -ICO_T },
	{ ICO_T, 0, -1 }, { ICO_T, 0, 1 }, { -ICO_T, 0, -1 }, { -ICO_T, 0, 1 },
};

/* Counter-clockwise seen from outside. */
static const uint8_t ico_faces[20][3] = {
	{ 0, 11, 5 }, { 0, 5, 1 },  { 0, 1, 7 },   { 0, 7, 10 }, { 0, 10, 11 },
	{ 1, 5, 9 },  { 5, 11, 4 }, { 11, 10, 2 }, { 10, 7, 6 }, { 7, 1, 8 },
	{ 3, 9, 4 },  { 3, 4, 2 },  { 3, 2, 6 },   { 3, 6, 8 },  { 3, 8, 9 },
	{ 4, 9, 5 },  { 2, 4, 11 }, { 6, 2, 10 },  { 8, 6, 7 },  { 9, 8, 1 },
};

/* Limits that keep 20 f^2 triangles and 10 f^2 + 2 vertices in uint32_t. */
#define ICO_MAX_FREQUENCY 14654u

/*
 * Global numbering, so that points on a shared edge get one index: the 12
 * corners, then f - 1 points per icosahedron edge, then each face's inner
 * points. 10 f^2 + 2 vertices in all.
 */
struct ico_layout {
	uint32_t f;
	uint8_t edge_of[12][12]; /* corner pair -> edge id */
};

static void ico_number_edges(struct ico_layout *lay)
{
	uint8_t next = 0;

	memset(lay->edge_of, 0xff, sizeof(lay->edge_of));
	for (int t = 0; t < 20; t++) {
		for (int k = 0; k < 3; k++) {
			int a = ico_faces[t][k], b = ico_faces[t][(k + 1) % 3];

			if (lay->edge_of[a][b] == 0xff) {
				lay->edge_of[a][b] = next;
				lay->edge_of[b][a] = next++;
			}
		}
	}
}

/* Point k of f along corner a -> b, counted from a. */
static uint32_t ico_edge_point(const struct ico_layout *lay, int a, int b, uint32_t k)
{
	uint32_t from_low = a < b ? k : lay->f - k;

	return 12 + lay->edge_of[a][b] * (lay->f - 1) + from_low - 1;
}

/* The global index of point (i, j) = A + i/f (B - A) + j/f (C - A) of a face. */
static uint32_t ico_index(const struct ico_layout *lay, int face, uint32_t i, uint32_t j)
{
	const uint8_t *c = ico_faces[face];
	uint32_t f = lay->f, row;

	if (i == 0 && j == 0)
		return c[0];
	if (i == f || j == f)
		return c[i == f ? 1 : 2];
	if (j == 0)
		return ico_edge_point(lay, c[0], c[1], i);
	if (i == 0)
		return ico_edge_point(lay, c[0], c[2], j);
	if (i + j == f)
		return ico_edge_point(lay, c[1], c[2], j);
	/* Inner rows i = 1 .. f - 2 hold f - 1 - i points each. */
	row = (i - 1) * (f - 1) - (i - 1) * i / 2;
	return 12 + 30 * (f - 1) + (uint32_t)face * ((f - 1) * (f - 2) / 2) + row + j - 1;
}

static void ico_put_vertex(float *out, const uint8_t *c, double wi, double wj)
{
	const double *a = ico_vertices[c[0]], *b = ico_vertices[c[1]], *d = ico_vertices[c[2]];
	double p[3], len = 0;

	for (int k = 0; k < 3; k++) {
		p[k] = a[k] + wi * (b[k] - a[k]) + wj * (d[k] - a[k]);
		len += p[k] * p[k];
	}
	len = sqrt(len);
	for (int k = 0; k < 3; k++)
		out[k] = (float)(p[k] / len);
}

static uint32_t *ico_face(const struct ico_layout *lay, int face, float *vertices,
                          uint32_t *tri)
{
	uint32_t f = lay->f;

	for (uint32_t i = 0; i <= f; i++) {
		for (uint32_t j = 0; i + j <= f; j++) {
			float *v = vertices + 3 * (size_t)ico_index(lay, face, i, j);

			ico_put_vertex(v, ico_faces[face], (double)i / f, (double)j / f);
		}
	}
	/* Same winding as the face: "up" triangles, and the "down" ones between. */
	for (uint32_t i = 0; i < f; i++) {
		for (uint32_t j = 0; i + j < f; j++) {
			uint32_t p = ico_index(lay, face, i, j), q = ico_index(lay, face, i + 1, j);
			uint32_t r = ico_index(lay, face, i, j + 1);

			tri = put_tri(tri, p, q, r);
			if (i + j + 1 < f)
				tri = put_tri(tri, q, ico_index(lay, face, i + 1, j + 1), r);
		}
	}
	return tri;
}

/* Fills 10 f^2 + 2 vertices and 20 f^2 triangles on the unit sphere. */
static void ico_fill(uint32_t f, float *vertices, uint32_t *indices)
{
	struct ico_layout lay = { .f = f };

	ico_number_edges(&lay);
	for (int t = 0; t < 20; t++)
		indices = ico_face(&lay, t, vertices, indices);
}

static int gen_icosphere(const bvhlab_gen_params *params, bvhlab_scene **out, char *source,
                         bvhlab_error *err)
{
	uint32_t f = params->frequency;
	bvhlab_scene *scene = NULL;
	int ret;

	if (f < 1 || f > ICO_MAX_FREQUENCY) {
		scene_error(err, "icosphere: frequency must be 1 to %u (20 * f^2 triangles), "
		                 "got %u", ICO_MAX_FREQUENCY, f);
		return -EINVAL;
	}
	ret = scene_alloc(10 * f * f + 2, 20 * f * f, &scene, err);
	if (ret)
		return ret;
	ico_fill(f, scene->vertices, scene->indices);
	snprintf(source, SOURCE_SIZE, "icosphere frequency=%u", f);
	*out = scene;
	return 0;
}

/* ---- soup ----------------------------------------------------------------- */

#define SOUP_MAX_COUNT (UINT32_MAX / 3) /* three unshared vertices each */

static void soup_fill(bvhlab_scene *scene, uint64_t seed)
{
	uint64_t state = seed;
	float *v = scene->vertices;
	uint32_t *tri = scene->indices;

	for (uint32_t t = 0; t < scene->triangle_count; t++) {
		double centre[3], size;

		for (int k = 0; k < 3; k++)
			centre[k] = random01(&state);
		/* Log-uniform sizes from 0.002 to 0.128: mixed scales are what
		 * make a soup hard to split well. */
		size = 0.002 * exp2(6.0 * random01(&state));
		for (int j = 0; j < 3; j++)
			for (int k = 0; k < 3; k++)
				*v++ = (float)(centre[k] + size * (2.0 * random01(&state) - 1.0));
		tri = put_tri(tri, 3 * t, 3 * t + 1, 3 * t + 2);
	}
}

static int gen_soup(const bvhlab_gen_params *params, bvhlab_scene **out, char *source,
                    bvhlab_error *err)
{
	bvhlab_scene *scene = NULL;
	int ret;

	if (params->count < 1 || params->count > SOUP_MAX_COUNT) {
		scene_error(err, "soup: count must be 1 to %u triangles, got %u", SOUP_MAX_COUNT,
		            params->count);
		return -EINVAL;
	}
	ret = scene_alloc(3 * params->count, params->count, &scene, err);
	if (ret)
		return ret;
	soup_fill(scene, params->seed);
	snprintf(source, SOURCE_SIZE, "soup count=%u seed=%llu", params->count,
	         (unsigned long long)params->seed);
	*out = scene;
	return 0;
}

/* ---- stadium -------------------------------------------------------------- */

/*
 * The "teapot in a stadium": a lumpy sphere of radius ~1 at the origin, on
 * a ground plane 1200 units wide, inside a tiered ring 1000 units across.
 * The ring is a surface of revolution of STADIUM_PROFILE points swept in
 * STADIUM_SEGMENTS steps.
 */
#define STADIUM_SEGMENTS 32
#define STADIUM_PROFILE 10
#define STADIUM_GROUND 8 /* ground cells per side */
#define STADIUM_FLOOR -1.25f

static const float stadium_profile[STADIUM_PROFILE][2] = { /* radius, height */
	{ 350, STADIUM_FLOOR }, { 350, 15 }, { 390, 15 }, { 390, 45 }, { 430, 45 },
	{ 430, 75 },            { 470, 75 }, { 470, 105 }, { 500, 105 }, { 500, 160 },
};

#define STADIUM_VERTICES \
	(STADIUM_SEGMENTS * STADIUM_PROFILE + (STADIUM_GROUND + 1) * (STADIUM_GROUND + 1))
#define STADIUM_TRIANGLES \
	(2 * STADIUM_SEGMENTS * (STADIUM_PROFILE - 1) + 2 * STADIUM_GROUND * STADIUM_GROUND)

/* Pushes the unit sphere in and out by a few random smooth waves. */
static void blob_shape(float *v, uint32_t count, uint64_t *state)
{
	double dir[3][3], freq[3], phase[3];

	for (int w = 0; w < 3; w++) {
		for (int k = 0; k < 3; k++)
			dir[w][k] = 2.0 * random01(state) - 1.0;
		freq[w] = 2.0 + 4.0 * random01(state);
		phase[w] = 6.283185307179586 * random01(state);
	}
	for (uint32_t i = 0; i < count; i++, v += 3) {
		double r = 1.0;

		for (int w = 0; w < 3; w++)
			r += 0.06 * sin(freq[w] * (dir[w][0] * v[0] + dir[w][1] * v[1] +
			                           dir[w][2] * v[2]) + phase[w]);
		for (int k = 0; k < 3; k++)
			v[k] = (float)(v[k] * r);
	}
}

/* Two triangles a-b-d, a-d-c for the quad with rows a b / c d. */
static uint32_t *put_quad(uint32_t *t, uint32_t a, uint32_t b, uint32_t c, uint32_t d)
{
	return put_tri(put_tri(t, a, b, d), a, d, c);
}

static uint32_t *stadium_ring(float *v, uint32_t *t, uint32_t base, uint64_t *state)
{
	for (int s = 0; s < STADIUM_SEGMENTS; s++) {
		double angle = 6.283185307179586 * s / STADIUM_SEGMENTS;
		/* Uneven tiers, so that no two scenes share split planes by chance. */
		double jitter = 1.0 + 0.05 * (random01(state) - 0.5);

		for (int p = 0; p < STADIUM_PROFILE; p++, v += 3) {
			double r = stadium_profile[p][0] * jitter;

			v[0] = (float)(r * cos(angle));
			v[1] = p ? (float)(stadium_profile[p][1] * jitter) : STADIUM_FLOOR;
			v[2] = (float)(r * sin(angle));
		}
	}
	for (uint32_t s = 0; s < STADIUM_SEGMENTS; s++) {
		uint32_t a = base + s * STADIUM_PROFILE;
		uint32_t b = base + (s + 1) % STADIUM_SEGMENTS * STADIUM_PROFILE;

		for (uint32_t p = 0; p + 1 < STADIUM_PROFILE; p++)
			t = put_quad(t, a + p, b + p, a + p + 1, b + p + 1);
	}
	return t;
}

static void stadium_ground(float *v, uint32_t *t, uint32_t base)
{
	const uint32_t n = STADIUM_GROUND + 1;

	for (uint32_t i = 0; i < n; i++) {
		for (uint32_t j = 0; j < n; j++, v += 3) {
			v[0] = -600.0f + 1200.0f * (float)i / STADIUM_GROUND;
			v[1] = STADIUM_FLOOR;
			v[2] = -600.0f + 1200.0f * (float)j / STADIUM_GROUND;
		}
	}
	for (uint32_t i = 0; i < STADIUM_GROUND; i++)
		for (uint32_t j = 0; j < STADIUM_GROUND; j++)
			t = put_quad(t, base + i * n + j, base + i * n + j + 1,
			             base + (i + 1) * n + j, base + (i + 1) * n + j + 1);
}

static int gen_stadium(const bvhlab_gen_params *params, bvhlab_scene **out, char *source,
                       bvhlab_error *err)
{
	/* The closest icosphere to `count` triangles. */
	uint32_t f = (uint32_t)lround(sqrt(params->count / 20.0));
	uint32_t ico_v, ico_t;
	bvhlab_scene *scene = NULL;
	uint64_t state = params->seed;
	int ret;

	f = f < 1 ? 1 : f;
	if (params->count < 1 || f > ICO_MAX_FREQUENCY - 1) {
		scene_error(err, "stadium: count (triangles of the object) must be 1 to %u, got %u",
		            20 * (ICO_MAX_FREQUENCY - 1) * (ICO_MAX_FREQUENCY - 1), params->count);
		return -EINVAL;
	}
	ico_v = 10 * f * f + 2;
	ico_t = 20 * f * f;
	ret = scene_alloc(ico_v + STADIUM_VERTICES, ico_t + STADIUM_TRIANGLES, &scene, err);
	if (ret)
		return ret;
	ico_fill(f, scene->vertices, scene->indices);
	blob_shape(scene->vertices, ico_v, &state);
	stadium_ground(scene->vertices + 3 * (size_t)ico_v, scene->indices + 3 * (size_t)ico_t,
	               ico_v);
	ico_v += (STADIUM_GROUND + 1) * (STADIUM_GROUND + 1);
	ico_t += 2 * STADIUM_GROUND * STADIUM_GROUND;
	stadium_ring(scene->vertices + 3 * (size_t)ico_v, scene->indices + 3 * (size_t)ico_t, ico_v,
	             &state);
	snprintf(source, SOURCE_SIZE, "stadium count=%u seed=%llu", params->count,
	         (unsigned long long)params->seed);
	*out = scene;
	return 0;
}

/* ---- terrain -------------------------------------------------------------- */

#define TERRAIN_MAX_SIZE 46340u /* 2 * size^2 triangles fit in uint32_t */
#define TERRAIN_OCTAVES 5

/* Value noise: a seeded random height at each lattice point. */
static double lattice(uint64_t seed, int64_t x, int64_t z)
{
	uint64_t state = seed ^ ((uint64_t)x * 0x9e3779b97f4a7c15ull) ^
	                 ((uint64_t)z * 0xc2b2ae3d27d4eb4full);

	return random01(&state);
}

static double smooth_noise(uint64_t seed, double x, double z)
{
	double fx = floor(x), fz = floor(z);
	double u = x - fx, w = z - fz;
	int64_t ix = (int64_t)fx, iz = (int64_t)fz;
	double a = lattice(seed, ix, iz), b = lattice(seed, ix + 1, iz);
	double c = lattice(seed, ix, iz + 1), d = lattice(seed, ix + 1, iz + 1);

	/* Smoothstep weights: no creases along lattice lines. */
	u = u * u * (3 - 2 * u);
	w = w * w * (3 - 2 * w);
	return (a + (b - a) * u) * (1 - w) + (c + (d - c) * u) * w;
}

static float terrain_height(uint64_t seed, double x, double z)
{
	double h = 0, amplitude = 0.12, frequency = 4;

	for (int o = 0; o < TERRAIN_OCTAVES; o++, amplitude *= 0.5, frequency *= 2)
		h += amplitude * smooth_noise(seed + (uint64_t)o, x * frequency, z * frequency);
	return (float)h;
}

/* A unit square in x and z, heights up to about 0.23 in y. */
static void terrain_fill(bvhlab_scene *scene, uint32_t size, uint64_t seed)
{
	const uint32_t n = size + 1;
	float *v = scene->vertices;
	uint32_t *t = scene->indices;

	for (uint32_t i = 0; i < n; i++) {
		for (uint32_t j = 0; j < n; j++, v += 3) {
			double x = (double)i / size, z = (double)j / size;

			v[0] = (float)(x - 0.5);
			v[1] = terrain_height(seed, x, z);
			v[2] = (float)(z - 0.5);
		}
	}
	/* Row order (j, then i+1) makes put_quad's triangles face +y. */
	for (uint32_t i = 0; i < size; i++) {
		for (uint32_t j = 0; j < size; j++) {
			uint32_t a = i * n + j, c = a + n;

			t = put_quad(t, a, a + 1, c, c + 1);
		}
	}
}

static int gen_terrain(const bvhlab_gen_params *params, bvhlab_scene **out, char *source,
                       bvhlab_error *err)
{
	uint32_t size = params->size;
	bvhlab_scene *scene = NULL;
	int ret;

	if (size < 1 || size > TERRAIN_MAX_SIZE) {
		scene_error(err, "terrain: size must be 1 to %u cells per side, got %u",
		            TERRAIN_MAX_SIZE, size);
		return -EINVAL;
	}
	ret = scene_alloc((size + 1) * (size + 1), 2 * size * size, &scene, err);
	if (ret)
		return ret;
	terrain_fill(scene, size, params->seed);
	snprintf(source, SOURCE_SIZE, "terrain size=%u seed=%llu", size,
	         (unsigned long long)params->seed);
	*out = scene;
	return 0;
}

/* ---- dispatch ------------------------------------------------------------- */

static int gen_needles(const bvhlab_gen_params *params, bvhlab_scene **out, char *source,
                       bvhlab_error *err)
{
	return scene_gen_needles(params, out, source, SOURCE_SIZE, err);
}

static int gen_room(const bvhlab_gen_params *params, bvhlab_scene **out, char *source,
                    bvhlab_error *err)
{
	return scene_gen_room(params, out, source, SOURCE_SIZE, err);
}

typedef int generate_fn(const bvhlab_gen_params *params, bvhlab_scene **out, char *source,
                        bvhlab_error *err);

static const struct {
	const char *name;
	generate_fn *generate;
} generators[] = {
	{ "icosphere", gen_icosphere },
	{ "soup", gen_soup },
	{ "stadium", gen_stadium },
	{ "terrain", gen_terrain },
	{ "needles", gen_needles },
	{ "room", gen_room },
};

int bvhlab_scene_generate(const char *generator, const bvhlab_gen_params *params,
                          bvhlab_scene **out, bvhlab_error *err)
{
	bvhlab_gen_params defaults;
	bvhlab_scene *scene = NULL;
	char source[SOURCE_SIZE];
	int ret;

	if (!params) {
		bvhlab_gen_params_init(&defaults);
		params = &defaults;
	}
	for (size_t i = 0; generator && i < sizeof(generators) / sizeof(generators[0]); i++) {
		if (strcmp(generator, generators[i].name) != 0)
			continue;
		ret = generators[i].generate(params, &scene, source, err);
		if (ret)
			return ret;
		ret = bvhlab_scene_set_name(scene, generator);
		if (ret || scene_set_source(scene, "%s", source)) {
			bvhlab_scene_destroy(scene);
			scene_error(err, "%s: out of memory", generator);
			return -ENOMEM;
		}
		bvhlab_scene_update(scene);
		*out = scene;
		return 0;
	}
	scene_error(err,
	            "unknown generator '%s' (known: icosphere, soup, stadium, terrain, needles, room)",
	            generator ? generator : "(null)");
	return -EINVAL;
}
