/*
 * The device traversals of a two-level scene (core/trace/trace_cl_two_level.c
 * and .cl) against the CPU's (trace_instances.c) on a small scene: three
 * meshes (a sphere, a triangle soup, a terrain patch), 300 instances
 * scattered turned about y and scaled, and a few placed by matrices that
 * turn about x and z, scale unevenly, mirror and shear. Rays: 1200 from
 * trace_two_level_ray (half aimed at one instance, half at the scene) and
 * 300 aimed away from it (misses).
 * For device_stack, device_stackless and device_wide8, on binary trees and
 * again on 8-wide bottoms under a 4-wide top (the collapse plugin): every
 * ray's instance, primitive, t, u and v bit for bit the CPU stack
 * traversal's (the leaf test and the ray's carrying into an instance are
 * the same operations, rounded the same); the nodes entered per ray and
 * the triangles tested equal to the CPU's own traversal (stack,
 * stackless; wide8 counts its compressed nodes: hits only). Then through
 * trace_measure_two_level, the harness's way: the same hits and the
 * device's name. An any-hit batch is refused, with the reason.
 * Skips (77) when this machine has no OpenCL device.
 */
#include <errno.h>
#include <math.h>
#include <stdlib.h>
#include <string.h>

#include <bvhlab/opencl.h>

#include "harness/harness_two_level.h"
#include "trace/trace_cl.h"
#include "trace/trace_instances.h"
#include "trace/trace_series.h"
#define FIXTURE_SEED 0x4201ULL
#include "../scene_fixture.h"
#include "../testutil.h"
#include "cl_device.h"
#include "../two_level_fixture.h"

#define SCATTERED 300
#define AIMED 1200
#define AWAY 300
#define RAYS (AIMED + AWAY)

static const int device_kinds[] = {BVHLAB_TRAVERSAL_DEVICE_STACK,
                                   BVHLAB_TRAVERSAL_DEVICE_STACKLESS,
                                   BVHLAB_TRAVERSAL_DEVICE_WIDE8};
/* The CPU traversal whose counters each one's must equal (-1: none). */
static const int cpu_twins[] = {BVHLAB_TRAVERSAL_STACK, BVHLAB_TRAVERSAL_STACKLESS, -1};

/* A turn of `deg` degrees about axis a (0 x, 2 z), scaled by sc per
 * column, moved by tr; shear adds x's column into y's row. */
static void matrix(int a, double deg, const double *sc, double shear, const double *tr,
                   double *m)
{
	double rad = deg * 3.14159265358979323846 / 180.0, c = cos(rad), s = sin(rad);
	double r[3][3] = {{0}};
	int u = (a + 1) % 3, v = (a + 2) % 3;
	r[a][a] = 1.0;
	r[u][u] = c, r[u][v] = -s, r[v][u] = s, r[v][v] = c;
	for (int i = 0; i < 3; i++) {
		for (int j = 0; j < 3; j++)
			m[4 * i + j] = r[i][j] * sc[j];
		m[4 * i + 3] = tr[i];
	}
	m[4 * 1 + 0] += shear;
}

static void make_scene(struct scene_instanced *inst)
{
	bvhlab_scene **meshes = calloc(3, sizeof(*meshes));
	bvhlab_error err = {{0}};
	meshes[0] = generate("icosphere", 0, 3, 0);
	meshes[1] = generate("soup", 60, 0, 0);
	meshes[2] = generate("terrain", 0, 0, 6);
	scene_instanced_init(inst, meshes, 3);
	struct scene_scatter sc = {.mesh = 0, .count = SCATTERED / 2, .seed = 3,
	                           .lo = {-40, -2, -40}, .hi = {40, 2, 40}, .scale = {0.5, 2.0},
	                           .random_y = true};
	CHECK_INT(scene_instanced_scatter(inst, &sc, &err), 0);
	sc = (struct scene_scatter){.mesh = 1, .count = SCATTERED / 4, .seed = 4,
	                            .lo = {-40, -2, -40}, .hi = {40, 8, 40}, .scale = {0.01, 0.05},
	                            .random_y = true};
	CHECK_INT(scene_instanced_scatter(inst, &sc, &err), 0);
	sc = (struct scene_scatter){.mesh = 2, .count = SCATTERED / 4, .seed = 6,
	                            .lo = {-40, -4, -40}, .hi = {40, -3, 40}, .scale = {0.02, 0.05},
	                            .random_y = false};
	CHECK_INT(scene_instanced_scatter(inst, &sc, &err), 0);
	static const double placed[][9] = {
		/* axis, degrees, scale x y z, shear, where x z */
		{0, 40, 1, 2.5, 0.7, 0, 3, 5}, {2, 75, -1, 1, 1, 0, -6, 2},
		{0, -120, 0.3, 3, 1.5, 0.4, 10, -8}, {2, 15, 2, 0.5, 2, -0.3, -15, 12}};
	for (size_t i = 0; i < sizeof(placed) / sizeof(placed[0]); i++) {
		double m[12], tr[3] = {placed[i][6], 1, placed[i][7]};
		matrix((int)placed[i][0], placed[i][1], &placed[i][2], placed[i][5], tr, m);
		CHECK_INT(scene_instanced_add(inst, (uint32_t)i % 3, m, &err), 0);
	}
}

static void make_rays(const struct scene_instanced *inst, const bvhlab_tree *top,
                      bvhlab_ray *rays)
{
	bvhlab_aabb b;
	memcpy(b.lo, top->nodes[0].lo, sizeof(b.lo));
	memcpy(b.hi, top->nodes[0].hi, sizeof(b.hi));
	for (uint32_t i = 0; i < AIMED; i++)
		trace_two_level_ray(inst, &b, 21, i, &rays[i]);
	for (uint32_t i = 0; i < AWAY; i++) { /* from outside, pointing further out */
		bvhlab_ray *r = &rays[AIMED + i];
		trace_two_level_ray(inst, &b, 22, i, r);
		for (int k = 0; k < 3; k++)
			r->dir[k] = -r->dir[k];
	}
}

/* One device traversal against the CPU: hits against ref (the stack
 * traversal's), counters against its twin's. */
static void compare(const struct trace_two_level *plain, int d, const bvhlab_ray *rays,
                    const struct trace_inst_hit *ref, const char *what)
{
	struct trace_two_level twin = *plain;
	bvhlab_hit *hits = calloc(RAYS, sizeof(*hits));
	uint32_t *nodes = calloc(RAYS, sizeof(*nodes)), *inst = calloc(RAYS, sizeof(*inst));
	struct trace_cl_tree *t = NULL;
	struct trace_cl_batch *b = NULL;
	bvhlab_trace_stats dev = {0}, cpu = {0};
	bvhlab_error err = {{0}};
	double k, w;
	int r = trace_cl_two_level_create(NULL, device_kinds[d], plain, &t, &err);
	if (r == 0)
		r = trace_cl_batch_create(t, rays, RAYS, false, &b, &err);
	if (r == 0)
		r = trace_cl_pass(b, hits, nodes, &dev, &k, &w, &err);
	if (r == 0)
		r = trace_cl_instances(b, inst, &err);
	if (r < 0)
		fprintf(stderr, "%s, %s: %s\n", what, bvhlab_traversal_name(device_kinds[d]),
		        err.message);
	CHECK_INT(r, 0);
	if (cpu_twins[d] >= 0)
		CHECK_INT(trace_two_level_prepare(&twin, cpu_twins[d]), 0);
	size_t differ = 0, counted = 0, hit = 0;
	for (size_t i = 0; r == 0 && i < RAYS; i++) {
		struct trace_inst_hit h;
		bvhlab_trace_stats st = {0};
		trace_two_level_closest(&twin, &rays[i], &h, &st);
		cpu.tris_tested += st.tris_tested;
		hit += hits[i].prim != BVHLAB_NO_HIT;
		differ += inst[i] != ref[i].instance || memcmp(&hits[i], &ref[i].hit, sizeof(hits[i]));
		counted += cpu_twins[d] >= 0 && nodes[i] != st.nodes_visited;
	}
	if (differ || counted)
		fprintf(stderr, "%s, %s: %zu of %d rays hit otherwise than on the CPU, %zu counted "
		        "other nodes\n", what, bvhlab_traversal_name(device_kinds[d]), differ, RAYS,
		        counted);
	CHECK(differ == 0 && counted == 0 && hit > AIMED / 3 && hit < AIMED);
	CHECK(cpu_twins[d] < 0 || dev.tris_tested == cpu.tris_tested);
	trace_two_level_release(&twin);
	trace_cl_batch_destroy(b);
	trace_cl_tree_destroy(t);
	free(hits);
	free(nodes);
	free(inst);
}

/* Through trace_measure_two_level (the harness's way): the same hits as
 * the CPU stack traversal's there, the device named; any-hit refused. */
static void through_measure(const struct trace_two_level *plain, const bvhlab_ray *rays)
{
	bvhlab_hit *ref = calloc(RAYS, sizeof(*ref)), *got = calloc(RAYS, sizeof(*got));
	bvhlab_trace_options o = {.traversal = BVHLAB_TRAVERSAL_STACK, .threads = 1,
	                          .max_repeats = 1};
	bvhlab_trace_timing tm;
	bvhlab_error err = {{0}};
	char device[128] = "";
	CHECK_INT(trace_measure_two_level(plain, rays, RAYS, &o, ref, &tm, NULL, 0, &err), 0);
	o.traversal = BVHLAB_TRAVERSAL_DEVICE_STACKLESS;
	CHECK_INT(trace_measure_two_level(plain, rays, RAYS, &o, got, &tm, device, sizeof(device),
	                                  &err), 0);
	CHECK(device[0] != '\0' && tm.repeats == 1 && tm.stats.rays == RAYS);
	CHECK(memcmp(ref, got, RAYS * sizeof(*ref)) == 0);
	struct trace_cl_tree *t = NULL;
	struct trace_cl_batch *b = NULL;
	CHECK_INT(trace_cl_two_level_create(NULL, BVHLAB_TRAVERSAL_DEVICE_STACK, plain, &t, &err), 0);
	CHECK_INT(trace_cl_batch_create(t, rays, RAYS, true, &b, &err), -EINVAL);
	CHECK_CONTAINS(err.message, "closest hits only");
	trace_cl_tree_destroy(t);
	free(ref);
	free(got);
}

static void check_all(const struct scene_instanced *inst, const struct two_level_trees *trees,
                      const char *what)
{
	struct trace_two_level plain = {.inst = inst, .top = &trees->top, .bottom = trees->bottom};
	bvhlab_ray *rays = calloc(RAYS, sizeof(*rays));
	struct trace_inst_hit *ref = calloc(RAYS, sizeof(*ref));
	make_rays(inst, &trees->top, rays);
	for (size_t i = 0; i < RAYS; i++)
		trace_two_level_closest(&plain, &rays[i], &ref[i], NULL);
	for (int d = 0; d < 3; d++)
		compare(&plain, d, rays, ref, what);
	through_measure(&plain, rays);
	free(rays);
	free(ref);
}

int main(void)
{
	if (!cl_device_present(NULL, 0))
		return TEST_SKIP;
	struct scene_instanced inst;
	bvhlab_plugin *bottom = NULL, *top = NULL;
	bvhlab_options bo, to;
	bvhlab_error err = {{0}};
	make_scene(&inst);
	if (!plugin_loads("sah_seq", &bottom) || !plugin_loads("lbvh", &top))
		return test_finish();
	CHECK_INT(bvhlab_options_init(&bo, bvhlab_plugin_builder(bottom)), 0);
	CHECK_INT(bvhlab_options_init(&to, bvhlab_plugin_builder(top)), 0);
	struct two_level_job job = {.inst = &inst, .bottom = bottom, .top = top, .bottom_opts = &bo,
	                            .top_opts = &to, .repeat = 1, .threads = 1, .validate_rays = 16};
	double samples[1], cold;
	struct tree_measure whole;
	struct results_two_level lv;
	struct two_level_trees trees;
	CHECK_INT(harness_two_level_series(&job, samples, &cold, &whole, &lv, &trees, &err), TREE_OK);
	CHECK(inst.instance_count == SCATTERED + 4 && trees.top.index_count == inst.instance_count);
	check_all(&inst, &trees, "binary trees");
	if (collapse_levels(&inst, &trees, 8, 4))
		check_all(&inst, &trees, "8-wide bottoms, 4-wide top");
	harness_two_level_finish(&trees);
	bvhlab_options_finish(&bo);
	bvhlab_options_finish(&to);
	bvhlab_plugin_close(bottom);
	bvhlab_plugin_close(top);
	scene_instanced_finish(&inst);
	return test_finish();
}
