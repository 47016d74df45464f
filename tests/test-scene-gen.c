/*
 * Procedural scenes, subdivision, bounds and degenerate counting, and the
 * per-primitive builder input (prims).
 */
#include <errno.h>
#include <math.h>
#include <stdlib.h>
#include <string.h>

#include <bvhlab/scene.h>

#include "scene/scene_private.h"
#include "testutil.h"

static bvhlab_scene *generate(const char *name, const bvhlab_gen_params *params)
{
	bvhlab_scene *s = NULL;
	bvhlab_error err = { "" };
	int ret = bvhlab_scene_generate(name, params, &s, &err);

	CHECK_INT(ret, 0);
	if (ret)
		fprintf(stderr, "  %s: %s\n", name, err.message);
	return s;
}

static bool indices_valid(const bvhlab_scene *s)
{
	for (size_t i = 0; i < 3 * (size_t)s->triangle_count; i++)
		if (s->indices[i] >= s->vertex_count)
			return false;
	return true;
}

static bool bounds_equal(const bvhlab_aabb *a, const bvhlab_aabb *b)
{
	return memcmp(a, b, sizeof(*a)) == 0;
}

static int cmp_u64(const void *a, const void *b)
{
	uint64_t x = *(const uint64_t *)a, y = *(const uint64_t *)b;

	return x < y ? -1 : x > y;
}

/* Closed and consistently wound: every directed edge exists exactly once and
 * its reverse too. */
static bool closed_manifold(const bvhlab_scene *s)
{
	size_t n = 3 * (size_t)s->triangle_count;
	uint64_t *edges = malloc(n * sizeof(uint64_t));
	bool ok = true;

	for (size_t i = 0; i < n; i++) {
		uint32_t a = s->indices[i], b = s->indices[i % 3 == 2 ? i - 2 : i + 1];
		edges[i] = (uint64_t)a << 32 | b;
	}
	qsort(edges, n, sizeof(uint64_t), cmp_u64);
	for (size_t i = 0; i < n && ok; i++) {
		uint64_t reverse = edges[i] << 32 | edges[i] >> 32;
		ok = (i == 0 || edges[i] != edges[i - 1]) &&
		     bsearch(&reverse, edges, n, sizeof(uint64_t), cmp_u64) != NULL;
	}
	free(edges);
	return ok;
}

/* Every triangle's normal points away from the origin. */
static bool faces_outward(const bvhlab_scene *s)
{
	for (size_t t = 0; t < s->triangle_count; t++) {
		const float *a = s->vertices + 3 * (size_t)s->indices[3 * t];
		const float *b = s->vertices + 3 * (size_t)s->indices[3 * t + 1];
		const float *c = s->vertices + 3 * (size_t)s->indices[3 * t + 2];
		double e1[3], e2[3], n[3];

		for (int k = 0; k < 3; k++)
			e1[k] = b[k] - a[k], e2[k] = c[k] - a[k];
		n[0] = e1[1] * e2[2] - e1[2] * e2[1];
		n[1] = e1[2] * e2[0] - e1[0] * e2[2];
		n[2] = e1[0] * e2[1] - e1[1] * e2[0];
		if (n[0] * a[0] + n[1] * a[1] + n[2] * a[2] <= 0)
			return false;
	}
	return true;
}

static double max_radius_error(const bvhlab_scene *s)
{
	double worst = 0;

	for (size_t i = 0; i < s->vertex_count; i++) {
		const float *v = s->vertices + 3 * i;
		double r = sqrt((double)v[0] * v[0] + (double)v[1] * v[1] + (double)v[2] * v[2]);
		worst = fmax(worst, fabs(r - 1.0));
	}
	return worst;
}

static void test_icosphere(void)
{
	bvhlab_gen_params p;
	bvhlab_scene *s;
	bvhlab_error err = { "" };

	bvhlab_gen_params_init(&p);
	for (uint32_t f = 1; f <= 4; f++) {
		p.frequency = f;
		s = generate("icosphere", &p);
		if (!s)
			continue;
		CHECK_INT(s->triangle_count, 20 * f * f);
		CHECK_INT(s->vertex_count, 10 * f * f + 2); /* no duplicated vertices */
		CHECK(indices_valid(s));
		CHECK(closed_manifold(s));
		CHECK(faces_outward(s));
		CHECK(max_radius_error(s) < 1e-6);
		CHECK_INT(s->degenerate_count, 0);
		CHECK(strcmp(s->name, "icosphere") == 0);
		CHECK(s->bounds.hi[1] <= 1.0f && s->bounds.lo[1] >= -1.0f);
		bvhlab_scene_destroy(s);
	}
	p.frequency = 300;
	s = generate("icosphere", &p);
	if (s) {
		CHECK_INT(s->triangle_count, 1800000);
		CHECK_INT(s->vertex_count, 900002);
		CHECK(max_radius_error(s) < 1e-6);
		CHECK_CONTAINS(s->source, "icosphere frequency=300");
		CHECK(indices_valid(s));
		bvhlab_scene_destroy(s);
	}
	p.frequency = 0;
	s = NULL;
	CHECK_INT(bvhlab_scene_generate("icosphere", &p, &s, &err), -EINVAL);
	CHECK_CONTAINS(err.message, "frequency");
	CHECK(s == NULL);
	p.frequency = 100000;
	CHECK_INT(bvhlab_scene_generate("icosphere", &p, &s, &err), -EINVAL);
	CHECK_CONTAINS(err.message, "got 100000");
}

static void test_soup(void)
{
	bvhlab_gen_params p;
	bvhlab_scene *a, *b, *c;
	bvhlab_error err = { "" };

	bvhlab_gen_params_init(&p);
	p.count = 5000;
	p.seed = 42;
	a = generate("soup", &p);
	b = generate("soup", &p);
	p.seed = 43;
	c = generate("soup", &p);
	if (a && b && c) {
		size_t bytes = 9 * sizeof(float) * a->triangle_count;
		CHECK_INT(a->triangle_count, 5000);
		CHECK(memcmp(a->vertices, b->vertices, bytes) == 0);
		CHECK(memcmp(a->vertices, c->vertices, bytes) != 0);
		CHECK(indices_valid(a));
		CHECK(a->bounds.lo[0] > -0.2f && a->bounds.hi[0] < 1.2f);
		CHECK(a->bounds.hi[2] - a->bounds.lo[2] > 0.9f); /* it fills the cube */
		CHECK_CONTAINS(a->source, "seed=42");
		CHECK(strcmp(a->name, "soup") == 0);
	}
	bvhlab_scene_destroy(a);
	bvhlab_scene_destroy(b);
	bvhlab_scene_destroy(c);
	p.count = 0;
	CHECK_INT(bvhlab_scene_generate("soup", &p, &a, &err), -EINVAL);
	CHECK_CONTAINS(err.message, "soup: count");
}

/* Triangles whose box fits inside radius 2 of the origin, and ones over 100 wide. */
static void count_sizes(const bvhlab_scene *s, uint32_t *small, uint32_t *big)
{
	bvhlab_prims prims;
	bvhlab_error err;

	*small = *big = 0;
	if (bvhlab_prims_init(&prims, s, &err) != 0)
		return;
	for (uint32_t i = 0; i < prims.input.prim_count; i++) {
		const bvhlab_aabb *b = &prims.input.prim_bounds[i];
		float extent = fmaxf(b->hi[0] - b->lo[0], b->hi[2] - b->lo[2]);
		bool inside = true;

		for (int k = 0; k < 3; k++)
			inside = inside && b->lo[k] > -2 && b->hi[k] < 2;
		*small += inside;
		*big += extent > 100;
	}
	bvhlab_prims_finish(&prims);
}

static void test_stadium(void)
{
	bvhlab_gen_params p;
	bvhlab_scene *s, *again;
	uint32_t small, big;

	bvhlab_gen_params_init(&p);
	p.count = 20000;
	p.seed = 7;
	s = generate("stadium", &p);
	again = generate("stadium", &p);
	if (!s || !again)
		goto out;
	CHECK(s->triangle_count >= 18000 && s->triangle_count <= 23000);
	CHECK(indices_valid(s));
	CHECK(s->bounds.hi[0] - s->bounds.lo[0] > 900);
	CHECK(s->bounds.hi[2] - s->bounds.lo[2] > 900);
	count_sizes(s, &small, &big);
	CHECK(small >= 18000);         /* the dense object, radius ~1 */
	CHECK(big >= 100 && big <= 2000); /* a few hundred huge triangles */
	CHECK(s->triangle_count - small < 2000);
	CHECK(memcmp(s->vertices, again->vertices, 12 * (size_t)s->vertex_count) == 0);
	CHECK_CONTAINS(s->source, "stadium count=20000 seed=7");
out:
	bvhlab_scene_destroy(s);
	bvhlab_scene_destroy(again);
}

static void test_terrain(void)
{
	bvhlab_gen_params p;
	bvhlab_scene *s, *t;
	bvhlab_error err = { "" };

	bvhlab_gen_params_init(&p);
	CHECK_INT(p.size, 256);
	p.size = 64;
	s = generate("terrain", &p);
	p.seed = 2;
	t = generate("terrain", &p);
	if (s && t) {
		CHECK_INT(s->triangle_count, 2 * 64 * 64);
		CHECK_INT(s->vertex_count, 65 * 65);
		CHECK(indices_valid(s));
		CHECK_INT(s->degenerate_count, 0);
		CHECK(s->bounds.hi[1] - s->bounds.lo[1] > 0.01f); /* not flat */
		CHECK(s->bounds.lo[0] == -0.5f && s->bounds.hi[2] == 0.5f);
		CHECK(memcmp(s->vertices, t->vertices, 12 * (size_t)s->vertex_count) != 0);
	}
	bvhlab_scene_destroy(s);
	bvhlab_scene_destroy(t);
	p.size = 0;
	CHECK_INT(bvhlab_scene_generate("terrain", &p, &s, &err), -EINVAL);
	CHECK_CONTAINS(err.message, "terrain: size");
}

static void test_subdivide(void)
{
	bvhlab_gen_params p;
	bvhlab_scene *s, *soup;
	bvhlab_error err = { "" };
	bvhlab_aabb before;

	bvhlab_gen_params_init(&p);
	p.frequency = 2;
	s = generate("icosphere", &p);
	if (!s)
		return;
	before = s->bounds;
	CHECK_INT(bvhlab_scene_subdivide(s, 0, &err), 0);
	CHECK_INT(s->triangle_count, 80);
	CHECK_INT(bvhlab_scene_subdivide(s, 2, &err), 0);
	CHECK_INT(s->triangle_count, 80 * 16);
	CHECK_INT(s->vertex_count, 10 * 8 * 8 + 2); /* midpoints shared across edges */
	CHECK(closed_manifold(s));
	CHECK(faces_outward(s));
	CHECK(indices_valid(s));
	CHECK(bounds_equal(&before, &s->bounds));
	CHECK_INT(bvhlab_scene_subdivide(s, 16, &err), -EOVERFLOW);
	CHECK_CONTAINS(err.message, "exceeds the limit");
	CHECK_INT(s->triangle_count, 80 * 16); /* untouched */
	bvhlab_scene_destroy(s);

	p.count = 1000;
	soup = generate("soup", &p);
	if (!soup)
		return;
	before = soup->bounds;
	CHECK_INT(bvhlab_scene_subdivide(soup, 1, &err), 0);
	CHECK_INT(soup->triangle_count, 4000);
	CHECK_INT(soup->vertex_count, 6000); /* no shared edges */
	CHECK(bounds_equal(&before, &soup->bounds));
	bvhlab_scene_destroy(soup);
}

/* A hand-made scene: one triangle, one collinear, one with a repeated index. */
static bvhlab_scene *small_scene(void)
{
	static const float v[] = { 0, 0, 0, 2, 0, 0, 0, 4, 1, 1, 0, 0 };
	static const uint32_t idx[] = { 0, 1, 2, 0, 3, 1, 2, 2, 1 };
	bvhlab_scene *s = NULL;

	if (scene_alloc(4, 3, &s, NULL) != 0)
		return NULL;
	memcpy(s->vertices, v, sizeof(v));
	memcpy(s->indices, idx, sizeof(idx));
	bvhlab_scene_update(s);
	return s;
}

static void test_update_and_prims(void)
{
	bvhlab_scene *s = small_scene(), *empty = NULL;
	bvhlab_prims prims;
	bvhlab_error err = { "" };
	const bvhlab_build_input *in = &prims.input;

	if (!s)
		return;
	CHECK_INT(s->degenerate_count, 2);
	CHECK(s->bounds.hi[0] == 2 && s->bounds.hi[1] == 4 && s->bounds.hi[2] == 1);
	CHECK_INT(bvhlab_scene_set_name(s, "tiny"), 0);
	CHECK(strcmp(s->name, "tiny") == 0);
	CHECK_INT(bvhlab_prims_init(&prims, s, &err), 0);
	CHECK_INT(in->struct_size, sizeof(bvhlab_build_input));
	CHECK_INT(in->prim_count, 3);
	CHECK_INT(in->threads, 1);
	CHECK(in->vertices == s->vertices && in->indices == s->indices);
	CHECK_INT(in->vertex_count, 4);
	CHECK(in->prim_bounds[0].hi[1] == 4 && in->prim_bounds[0].lo[2] == 0);
	CHECK(in->prim_bounds[1].hi[0] == 2 && in->prim_bounds[1].hi[1] == 0);
	CHECK(in->centroids[0] == 1 && in->centroids[1] == 2 && in->centroids[2] == 0.5f);
	CHECK(in->centroids[3] == 1 && in->centroids[4] == 0 && in->centroids[5] == 0);
	CHECK(bounds_equal(&in->bounds, &s->bounds));
	CHECK(in->centroid_bounds.lo[1] == 0 && in->centroid_bounds.hi[1] == 2);
	CHECK(in->centroid_bounds.lo[0] == 1 && in->centroid_bounds.hi[0] == 1);
	bvhlab_prims_finish(&prims);
	CHECK(prims.bounds_storage == NULL);
	bvhlab_prims_finish(&prims); /* twice is fine */
	bvhlab_scene_destroy(s);

	CHECK_INT(scene_alloc(0, 0, &empty, NULL), 0);
	if (empty) {
		CHECK_INT(bvhlab_prims_init(&prims, empty, &err), -EINVAL);
		CHECK_CONTAINS(err.message, "no triangles");
	}
	bvhlab_scene_destroy(empty);
	bvhlab_scene_destroy(NULL);
}

static void test_unknown(void)
{
	bvhlab_scene *s = NULL;
	bvhlab_error err = { "" };
	bvhlab_gen_params p;

	CHECK_INT(bvhlab_scene_generate("teapot", NULL, &s, &err), -EINVAL);
	CHECK(s == NULL);
	CHECK_CONTAINS(err.message, "unknown generator 'teapot'");
	CHECK_CONTAINS(err.message, "icosphere, soup, stadium, terrain, needles, room");
	bvhlab_gen_params_init(&p);
	CHECK_INT(p.frequency, 16);
	CHECK_INT(p.count, 10000);
	CHECK_INT(p.seed, 1);
	s = generate("icosphere", NULL); /* NULL: the defaults */
	CHECK(s && s->triangle_count == 20 * 16 * 16);
	bvhlab_scene_destroy(s);
}

int main(void)
{
	test_icosphere();
	test_soup();
	test_stadium();
	test_terrain();
	test_subdivide();
	test_update_and_prims();
	test_unknown();
	return test_finish();
}
