/*
 * The watertight triangle test and the traversal: basic hits and misses,
 * no ray slipping through shared edges and vertices of closed meshes and
 * fans, closest hit through a tree equal to brute force on random scenes,
 * axis-parallel rays (zero direction components) and a tree far deeper
 * than the traversal's fixed stack.
 */
#include <math.h>

#include <bvhlab/trace.h>

#include "testutil.h"
#include "tree_fixture.h"

static bvhlab_ray make_ray(float ox, float oy, float oz, float dx, float dy, float dz)
{
	return (bvhlab_ray){ { ox, oy, oz }, 0.0f, { dx, dy, dz }, INFINITY };
}

static int reported;

/*
 * Traces through the tree and by brute force; returns whether both agree
 * exactly and *hit is the tree's answer. Both run the same triangle test,
 * so t must be bit-identical; the primitive may differ only in a tie (a ray
 * through a shared edge or vertex meets several triangles at the same t).
 */
static bool trace_both(const fixture *f, const bvhlab_ray *ray, bvhlab_hit *hit,
                       bvhlab_trace_stats *stats)
{
	bvhlab_hit brute;

	bvhlab_trace_closest(&f->tree, &f->scene, ray, hit, stats);
	bvhlab_trace_brute(&f->scene, ray, &brute);
	if ((hit->prim == BVHLAB_NO_HIT) != (brute.prim == BVHLAB_NO_HIT) ||
	    (hit->prim != BVHLAB_NO_HIT && hit->t != brute.t)) {
		if (reported++ < 10)
			fprintf(stderr, "tree: prim %u t %.9g, brute: prim %u t %.9g\n", hit->prim,
			        (double)hit->t, brute.prim, (double)brute.t);
		return false;
	}
	return true;
}

static void test_single_triangle(void)
{
	fixture f;
	bvhlab_ray ray = make_ray(0.25f, 0.5f, 1.0f, 0.0f, 0.0f, -1.0f);
	bvhlab_hit hit = { INFINITY, 0, 0, BVHLAB_NO_HIT };

	fixture_alloc(&f, 3, 1);
	memcpy(f.scene.vertices, (float[]){ 0, 0, 0, 1, 0, 0, 0, 1, 0 }, 9 * sizeof(float));
	memcpy(f.scene.indices, (uint32_t[]){ 0, 1, 2 }, 3 * sizeof(uint32_t));
	fixture_prepare(&f);
	CHECK(bvhlab_intersect_triangle(&ray, &f.scene, 0, &hit));
	CHECK(hit.t == 1.0f && hit.prim == 0);
	CHECK(fabsf(hit.u - 0.25f) < 1e-6f && fabsf(hit.v - 0.5f) < 1e-6f); /* weights of v1, v2 */
	CHECK(!bvhlab_intersect_triangle(&ray, &f.scene, 0, &hit)); /* t must beat hit->t */
	hit.t = INFINITY;
	ray = make_ray(0.25f, 0.5f, -2.0f, 0.0f, 0.0f, 1.0f); /* from behind: two-sided */
	CHECK(bvhlab_intersect_triangle(&ray, &f.scene, 0, &hit) && hit.t == 2.0f);
	hit.t = INFINITY;
	ray.tmin = 2.0f; /* the interval is open at tmin */
	CHECK(!bvhlab_intersect_triangle(&ray, &f.scene, 0, &hit));
	ray.tmin = 1.5f;
	CHECK(bvhlab_intersect_triangle(&ray, &f.scene, 0, &hit));
	hit.t = INFINITY;
	ray = make_ray(0.75f, 0.75f, 1.0f, 0.0f, 0.0f, -1.0f); /* outside the hypotenuse */
	CHECK(!bvhlab_intersect_triangle(&ray, &f.scene, 0, &hit));
	ray = make_ray(0.25f, 0.25f, 1.0f, 0.0f, 0.0f, 0.0f); /* no direction */
	CHECK(!bvhlab_intersect_triangle(&ray, &f.scene, 0, &hit));
	ray = make_ray(0.25f, 0.25f, 1.0f, NAN, 0.0f, -1.0f);
	CHECK(!bvhlab_intersect_triangle(&ray, &f.scene, 0, &hit));
	ray = make_ray(0.25f, 0.25f, 0.0f, 1.0f, 0.0f, 0.0f); /* in the plane: edge-on */
	CHECK(!bvhlab_intersect_triangle(&ray, &f.scene, 0, &hit));
	fixture_free(&f);
}

/*
 * Edge functions that round to exactly 0 in float but not in exact
 * arithmetic: products near 2^25 where floats are 4 apart. The ray (down
 * the z axis through the origin) lies inside T1 = (A, B, C) and outside
 * T2 = (D, C, B), each edge function being exactly +-1; in float T2's edge
 * functions come out (0, 4, 0), which without the double fallback would
 * count as a hit on T2's edge.
 */
static void test_double_fallback(void)
{
	static const float v[4][3] = {
		{ -8193, -8195, 0 }, /* A */
		{ 4097, 4098, 0 },   /* B */
		{ 4096, 4097, 0 },   /* C */
		{ 8193, 8195, 0 },   /* D */
	};
	static const uint32_t tris[6] = { 0, 1, 2, 3, 2, 1 };
	bvhlab_ray ray = make_ray(0.0f, 0.0f, 10.0f, 0.0f, 0.0f, -1.0f);
	bvhlab_hit hit = { INFINITY, 0, 0, BVHLAB_NO_HIT };
	fixture f;

	fixture_alloc(&f, 4, 2);
	memcpy(f.scene.vertices, v, sizeof(v));
	memcpy(f.scene.indices, tris, sizeof(tris));
	fixture_prepare(&f);
	CHECK(!bvhlab_intersect_triangle(&ray, &f.scene, 1, &hit));
	CHECK(bvhlab_intersect_triangle(&ray, &f.scene, 0, &hit));
	CHECK(hit.t == 10.0f);
	fixture_build(&f, 1);
	CHECK(trace_both(&f, &ray, &hit, NULL));
	CHECK_INT(hit.prim, 0);
	fixture_free(&f);
}

/*
 * A closed bipyramid: a ring of n vertices at irregular radii, far from the
 * origin so coordinates round, and an apex above and below. Two fans of n
 * triangles share each apex. Any ray from inside must hit, including rays
 * aimed exactly at vertices and at points along every edge.
 */
static void bipyramid(fixture *f, uint32_t n, const float c[3], uint64_t seed)
{
	uint32_t i;

	fixture_alloc(f, n + 2, 2 * n);
	for (i = 0; i < n; i++) {
		float a = 6.2831853f * ((float)i + 0.3f * fx_unit(&seed)) / (float)n;
		float r = 1.0f + 0.5f * fx_unit(&seed);

		f->scene.vertices[3 * i] = c[0] + r * cosf(a);
		f->scene.vertices[3 * i + 1] = c[1] + r * sinf(a);
		f->scene.vertices[3 * i + 2] = c[2] + 0.2f * (fx_unit(&seed) - 0.5f);
	}
	memcpy(f->scene.vertices + 3 * n, (float[]){ c[0], c[1], c[2] + 1.3f, c[0] + 0.1f,
	       c[1] - 0.2f, c[2] - 1.7f }, 6 * sizeof(float));
	for (i = 0; i < n; i++) {
		uint32_t *t = f->scene.indices + 6 * i;

		t[0] = n, t[1] = i, t[2] = (i + 1) % n;
		t[3] = n + 1, t[4] = (i + 1) % n, t[5] = i;
	}
	fixture_prepare(f);
	fixture_build(f, 2);
}

static uint32_t shoot_from_inside(const fixture *f, const float c[3], const float *target,
                                  uint64_t *seed)
{
	uint32_t misses = 0, k;
	int j;

	for (k = 0; k < 8; k++) {
		bvhlab_ray ray;
		bvhlab_hit hit;

		for (j = 0; j < 3; j++) {
			ray.org[j] = c[j] + 0.1f * (fx_unit(seed) - 0.5f);
			ray.dir[j] = target[j] - ray.org[j];
		}
		ray.tmin = 0.0f;
		ray.tmax = INFINITY;
		if (!trace_both(f, &ray, &hit, NULL) || hit.prim == BVHLAB_NO_HIT)
			misses++;
	}
	return misses;
}

static void test_closed_mesh(void)
{
	static const float centers[3][3] = { { 0, 0, 0 }, { 1000.3f, -7.1f, 3.3f },
	                                     { -0.001f, 12345.6f, -98.7f } };
	uint64_t seed = 11;
	uint32_t misses = 0, rays = 0, m, i, s;
	fixture f;

	for (m = 0; m < 3; m++) {
		const float *c = centers[m];

		bipyramid(&f, 97, c, 100 + m);
		for (i = 0; i < f.scene.vertex_count; i++, rays += 8)
			misses += shoot_from_inside(&f, c, f.scene.vertices + 3 * i, &seed);
		for (i = 0; i < f.scene.triangle_count; i++) { /* points along every edge */
			const uint32_t *t = f.scene.indices + 3 * i;

			for (s = 1; s < 8; s++, rays += 8) {
				const float *p = f.scene.vertices + 3 * t[0], *q = f.scene.vertices + 3 * t[1];
				float target[3];
				int j;

				for (j = 0; j < 3; j++)
					target[j] = p[j] + (q[j] - p[j]) * ((float)s / 8.0f);
				misses += shoot_from_inside(&f, c, target, &seed);
			}
		}
		fixture_free(&f);
	}
	CHECK(rays > 10000);
	CHECK_INT(misses, 0);
}

/*
 * A flat fan of 9 triangles around the origin. Rays from above and below
 * aimed at the shared centre vertex (direction = -origin, so the ray passes
 * exactly through it) and at points on the shared interior edges must hit.
 */
static void test_fan(void)
{
	const uint32_t n = 9;
	uint64_t seed = 5;
	uint32_t misses = 0, i, k;
	fixture f;

	fixture_alloc(&f, n + 1, n);
	for (i = 0; i < n; i++) {
		float a = 6.2831853f * ((float)i + 0.4f * fx_unit(&seed)) / (float)n;

		f.scene.vertices[3 * i] = (1.0f + fx_unit(&seed)) * cosf(a);
		f.scene.vertices[3 * i + 1] = (1.0f + fx_unit(&seed)) * sinf(a);
		f.scene.indices[3 * i] = n; /* the centre, stored as vertex n: (0, 0, 0) */
		f.scene.indices[3 * i + 1] = i;
		f.scene.indices[3 * i + 2] = (i + 1) % n;
	}
	fixture_prepare(&f);
	fixture_build(&f, 1);
	for (k = 0; k < 4000; k++) {
		const float *edge = f.scene.vertices + 3 * (k % n);
		float s = (k & 1) ? 0.95f * fx_unit(&seed) : 0.0f, side = (k & 2) ? 1.0f : -1.0f;
		bvhlab_ray ray = make_ray(4.0f * (fx_unit(&seed) - 0.5f), 4.0f * (fx_unit(&seed) - 0.5f),
		                          side * (0.1f + fx_unit(&seed)), 0, 0, 0);
		bvhlab_hit hit;
		int j;

		for (j = 0; j < 3; j++)
			ray.dir[j] = s * edge[j] - ray.org[j];
		if (!trace_both(&f, &ray, &hit, NULL) || hit.prim == BVHLAB_NO_HIT)
			misses++;
	}
	CHECK_INT(misses, 0);
	fixture_free(&f);
}

static void random_ray(uint64_t *seed, float extent, bvhlab_ray *ray)
{
	int j;

	for (j = 0; j < 3; j++) {
		ray->org[j] = (1.6f * fx_unit(seed) - 0.3f) * extent;
		ray->dir[j] = fx_unit(seed) - 0.5f;
	}
	ray->tmin = (fx_rand(seed) & 1) ? 0.0f : 0.5f * extent * fx_unit(seed);
	ray->tmax = (fx_rand(seed) & 3) ? INFINITY : extent * fx_unit(seed);
}

static void test_random_scenes(void)
{
	static const uint32_t leaf[3] = { 1, 4, 16 };
	uint32_t s, k, bad = 0, hits = 0;
	uint64_t seed = 77;

	for (s = 0; s < 3; s++) {
		bvhlab_trace_stats stats = { 0 };
		fixture f;

		fixture_soup(&f, 3000 + 500 * s, 1000 + s, 50.0f, 6.0f);
		fixture_build(&f, leaf[s]);
		for (k = 0; k < 3000; k++) {
			bvhlab_ray ray;
			bvhlab_hit hit;

			random_ray(&seed, 50.0f, &ray);
			bad += !trace_both(&f, &ray, &hit, &stats);
			hits += hit.prim != BVHLAB_NO_HIT;
		}
		CHECK_INT(stats.rays, 3000);
		CHECK(stats.nodes_visited > 0);
		CHECK(stats.tris_tested > 0);
		CHECK(stats.tris_tested < (uint64_t)3000 * f.scene.triangle_count / 10);
		fixture_free(&f);
	}
	CHECK_INT(bad, 0);
	CHECK(hits > 2000);
}

/* A z = 0 grid and a wall x = 5 of edge-sharing triangles; rays along the
 * axes through lattice points: exactly on shared edges, vertices and the
 * faces of every node's box. */
static void test_axis_parallel(void)
{
	uint32_t misses = 0, wrong_t = 0, bad = 0, x, y, i;
	fixture f;

	fixture_grid(&f, 8, 8, 0.0f);
	fixture_build(&f, 2);
	for (x = 0; x <= 32; x++) {
		for (y = 0; y <= 32; y++) {
			float px = (float)x / 4.0f, py = (float)y / 4.0f;
			bvhlab_ray down = make_ray(px, py, 1.0f, 0.0f, 0.0f, -1.0f);
			bvhlab_ray up = make_ray(px, py, -3.0f, -0.0f, -0.0f, 2.0f);
			bvhlab_hit hit;

			bad += !trace_both(&f, &down, &hit, NULL);
			misses += hit.prim == BVHLAB_NO_HIT;
			wrong_t += hit.prim != BVHLAB_NO_HIT && hit.t != 1.0f;
			bad += !trace_both(&f, &up, &hit, NULL);
			misses += hit.prim == BVHLAB_NO_HIT;
			wrong_t += hit.prim != BVHLAB_NO_HIT && hit.t != 1.5f;
		}
	}
	/* In the plane of the grid every triangle is edge-on: no hit, either way. */
	for (y = 0; y <= 32; y++) {
		bvhlab_ray along = make_ray(-1.0f, (float)y / 4.0f, 0.0f, 1.0f, 0.0f, 0.0f);
		bvhlab_hit hit;

		bad += !trace_both(&f, &along, &hit, NULL);
	}
	for (i = 0; i < f.scene.vertex_count; i++) { /* (x, y, 0) -> (5, x, y) */
		float *v = f.scene.vertices + 3 * i;
		float vx = v[0], vy = v[1];

		v[0] = 5.0f, v[1] = vx, v[2] = vy;
	}
	fixture_prepare(&f);
	fixture_build(&f, 3);
	for (x = 0; x <= 32; x++) {
		for (y = 0; y <= 32; y++) {
			bvhlab_ray ray = make_ray((x + y) & 1 ? 0.0f : 10.0f, (float)x / 4.0f,
			                          (float)y / 4.0f, (x + y) & 1 ? 1.0f : -1.0f, 0.0f, 0.0f);
			bvhlab_hit hit;

			bad += !trace_both(&f, &ray, &hit, NULL);
			misses += hit.prim == BVHLAB_NO_HIT;
			wrong_t += hit.prim != BVHLAB_NO_HIT && hit.t != 5.0f;
		}
	}
	CHECK_INT(bad, 0);
	CHECK_INT(misses, 0);
	CHECK_INT(wrong_t, 0);
	fixture_free(&f);
}

/* Depth 1999: the traversal stack must outgrow its fixed 64 entries. */
static void test_deep_tree(void)
{
	fixture f;
	bvhlab_ray down = make_ray(0.5f, 0.5f, 3000.0f, 0.0f, 0.0f, -1.0f);
	bvhlab_ray up = make_ray(0.5f, 0.5f, -100.0f, 0.0f, 0.0f, 1.0f);
	bvhlab_trace_stats stats = { 0 };
	bvhlab_hit hit;

	fixture_chain(&f, 2000);
	CHECK(trace_both(&f, &down, &hit, &stats));
	CHECK_INT(hit.prim, 1999);
	CHECK(hit.t == 1001.0f);
	CHECK(trace_both(&f, &up, &hit, NULL));
	CHECK_INT(hit.prim, 0);
	CHECK(hit.t == 100.0f);
	down.tmax = 1000.0f; /* stops short of every triangle */
	CHECK(trace_both(&f, &down, &hit, NULL));
	CHECK_INT(hit.prim, BVHLAB_NO_HIT);
	CHECK(stats.nodes_visited >= 2000);
	fixture_free(&f);
}

/* A zero-area triangle is never hit, and does not disturb its neighbours. */
static void test_degenerate(void)
{
	fixture f;
	bvhlab_ray ray = make_ray(0.5f, 0.0f, 1.0f, 0.0f, 0.0f, -1.0f);
	bvhlab_hit hit;

	fixture_alloc(&f, 3, 1);
	memcpy(f.scene.vertices, (float[]){ 0, 0, 0, 1, 0, 0, 2, 0, 0 }, 9 * sizeof(float));
	memcpy(f.scene.indices, (uint32_t[]){ 0, 1, 2 }, 3 * sizeof(uint32_t));
	fixture_prepare(&f);
	fixture_build(&f, 1);
	CHECK(trace_both(&f, &ray, &hit, NULL));
	CHECK_INT(hit.prim, BVHLAB_NO_HIT);
	fixture_free(&f);
}

int main(void)
{
	test_single_triangle();
	test_double_fallback();
	test_closed_mesh();
	test_fan();
	test_random_scenes();
	test_axis_parallel();
	test_deep_tree();
	test_degenerate();
	return test_finish();
}
