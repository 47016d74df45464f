/*
 * Single-ray throughput of Embree 3 (rtcIntersect1) beside the core's
 * traverser, on one thread, with the same primary rays, in one process:
 * the yardstick of the per-thread traversal speed (issue 17).
 *
 *   build/bench/embree-rays SCENE [--subdivide K] [--size N] [--min-ms MS]
 *                           [--builder PLUGIN]
 *
 * Embree and the core traversals (stack, stackless, wide) take turns, a round
 * at a time, until --min-ms (default 1000) has passed and at least 5
 * rounds were run. In a round each traces the whole batch PASSES times in
 * a row, timed on both clocks, the thread's CPU time (what the harness
 * reports) and the wall clock; the core's passes go through
 * bvhlab_trace_measure, as the harness's do. A round's figure is the median
 * of its passes, so the first pass, cold after the other tracers ran (and,
 * for the core, after its copy of the tree), is left out as the harness's
 * median leaves it out; the medians over rounds are printed with the ratios.
 * Both clocks' figures come from the same passes: a burst of load from
 * elsewhere stretches the wall clock only.
 * Embree's BVH is its own (rtcCommitScene, default quality, 4- or 8-wide
 * nodes); ours is the plugin's tree in the 32-byte binary layout.
 */
#include <embree3/rtcore.h>
#include <errno.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <time.h>

#include <bvhlab/bvhlab.h>
#include <bvhlab/trace.h>

#include "util/util.h"

#define MAX_SAMPLES 4096
#define MIN_ROUNDS 5
#define PASSES 3
/* The CPU's traversals (the cl_ ones come after them in the enum). */
#define OURS BVHLAB_TRAVERSAL_DEVICE_STACK
#define TRACERS (1 + OURS) /* embree, then ours by enum bvhlab_traversal */

struct args {
	const char *scene, *builder;
	unsigned subdivide;
	uint32_t size;
	double min_ms;
};

static int parse_args(int argc, char **argv, struct args *a)
{
	*a = (struct args){.builder = "sah_seq", .size = 512, .min_ms = 1000};
	for (int i = 1; i < argc; i++) {
		const char *v = i + 1 < argc ? argv[i + 1] : NULL;
		if (strcmp(argv[i], "--subdivide") == 0 && v)
			a->subdivide = (unsigned)atoi(argv[++i]);
		else if (strcmp(argv[i], "--size") == 0 && v)
			a->size = (uint32_t)atoi(argv[++i]);
		else if (strcmp(argv[i], "--min-ms") == 0 && v)
			a->min_ms = atof(argv[++i]);
		else if (strcmp(argv[i], "--builder") == 0 && v)
			a->builder = argv[++i];
		else if (argv[i][0] != '-' && !a->scene)
			a->scene = argv[i];
		else
			return -EINVAL;
	}
	return a->scene && a->size > 0 ? 0 : -EINVAL;
}

static int load(const struct args *a, bvhlab_scene **scene, bvhlab_error *err)
{
	int r = bvhlab_scene_load(a->scene, scene, err);
	if (r == 0 && a->subdivide)
		r = bvhlab_scene_subdivide(*scene, a->subdivide, err);
	return r;
}

static RTCScene embree_scene(RTCDevice dev, const bvhlab_scene *s)
{
	RTCScene sc = rtcNewScene(dev);
	RTCGeometry g = rtcNewGeometry(dev, RTC_GEOMETRY_TYPE_TRIANGLE);
	float *v = rtcSetNewGeometryBuffer(g, RTC_BUFFER_TYPE_VERTEX, 0, RTC_FORMAT_FLOAT3,
	                                   3 * sizeof(float), s->vertex_count);
	unsigned *ix = rtcSetNewGeometryBuffer(g, RTC_BUFFER_TYPE_INDEX, 0, RTC_FORMAT_UINT3,
	                                       3 * sizeof(unsigned), s->triangle_count);
	memcpy(v, s->vertices, 3 * sizeof(float) * s->vertex_count);
	memcpy(ix, s->indices, 3 * sizeof(unsigned) * s->triangle_count);
	rtcCommitGeometry(g);
	rtcAttachGeometry(sc, g);
	rtcReleaseGeometry(g);
	rtcCommitScene(sc);
	return sc;
}

/* One pass of rtcIntersect1 over every ray; returns the hit count. */
static size_t embree_pass(RTCScene sc, const bvhlab_ray *rays, size_t n)
{
	struct RTCIntersectContext ctx;
	size_t hits = 0;
	rtcInitIntersectContext(&ctx);
	for (size_t i = 0; i < n; i++) {
		struct RTCRayHit rh;
		rh.ray.org_x = rays[i].org[0];
		rh.ray.org_y = rays[i].org[1];
		rh.ray.org_z = rays[i].org[2];
		rh.ray.dir_x = rays[i].dir[0];
		rh.ray.dir_y = rays[i].dir[1];
		rh.ray.dir_z = rays[i].dir[2];
		rh.ray.tnear = rays[i].tmin;
		rh.ray.tfar = rays[i].tmax;
		rh.ray.mask = UINT32_MAX;
		rh.ray.flags = 0;
		rh.ray.time = 0;
		rh.hit.geomID = RTC_INVALID_GEOMETRY_ID;
		rtcIntersect1(sc, &ctx, &rh);
		hits += rh.hit.geomID != RTC_INVALID_GEOMETRY_ID;
	}
	return hits;
}

static int cmp_double(const void *a, const void *b)
{
	double x = *(const double *)a, y = *(const double *)b;
	return (x > y) - (x < y);
}

static double median(double *s, size_t n)
{
	qsort(s, n, sizeof(*s), cmp_double);
	return n % 2 ? s[n / 2] : 0.5 * (s[n / 2 - 1] + s[n / 2]);
}

static double cpu_now(void)
{
	struct timespec c;
	clock_gettime(CLOCK_THREAD_CPUTIME_ID, &c);
	return (double)c.tv_sec + 1e-9 * (double)c.tv_nsec;
}

/* What one tracer measured: a median per round, on each clock. */
struct tracer {
	double cpu[MAX_SAMPLES], wall[MAX_SAMPLES];
	double mrays[2]; /* medians over rounds: thread CPU time, wall clock */
	size_t hits;
	double nodes; /* per ray; the core's traversals only */
};

static double rate(size_t n, double seconds)
{
	return (double)n / seconds * 1e-6;
}

/* PASSES passes of rtcIntersect1 in a row. */
static void embree_round(RTCScene sc, const bvhlab_ray *rays, size_t n, struct tracer *t,
                         size_t round)
{
	double cpu[PASSES], wall[PASSES];
	for (int i = 0; i < PASSES; i++) {
		double w0 = util_now(), c0 = cpu_now();
		t->hits = embree_pass(sc, rays, n);
		cpu[i] = rate(n, cpu_now() - c0);
		wall[i] = rate(n, util_now() - w0);
	}
	t->cpu[round] = median(cpu, PASSES);
	t->wall[round] = median(wall, PASSES);
}

/* PASSES passes of the core's traversal k, timed by bvhlab_trace_measure. */
static bool ours_round(const bvhlab_tree *tree, const bvhlab_scene *s, const bvhlab_ray *rays,
                       size_t n, int k, bvhlab_hit *h, struct tracer *t, size_t round)
{
	bvhlab_trace_options o = {.traversal = k, .threads = 1, .min_repeats = PASSES,
	                          .max_repeats = PASSES};
	bvhlab_trace_timing tm;
	if (bvhlab_trace_measure(tree, s, rays, n, &o, h, NULL, &tm) < 0)
		return false;
	t->cpu[round] = tm.mrays_median;
	t->wall[round] = tm.wall_mrays_median;
	t->nodes = (double)tm.stats.nodes_visited / (double)tm.stats.rays;
	t->hits = 0;
	for (size_t i = 0; i < n; i++)
		t->hits += h[i].prim != BVHLAB_NO_HIT;
	return true;
}

/* Rounds of Embree and of every core traversal in turn, so a burst of
 * load from elsewhere on the machine falls on all alike; medians. */
static void time_all(RTCScene sc, const bvhlab_tree *tree, const bvhlab_scene *s,
                     const bvhlab_ray *rays, size_t n, const struct args *a, struct tracer *t)
{
	bvhlab_hit *h = malloc(n * sizeof(*h));
	double start = util_now();
	size_t k = 0;
	while (h && k < MAX_SAMPLES && (k < MIN_ROUNDS || util_now() - start < a->min_ms * 1e-3)) {
		embree_round(sc, rays, n, &t[0], k);
		int j = 0;
		while (j < OURS && ours_round(tree, s, rays, n, j, h, &t[1 + j], k))
			j++;
		if (j < OURS)
			break;
		k++;
	}
	for (int i = 0; i < TRACERS; i++) {
		t[i].mrays[0] = k ? median(t[i].cpu, k) : 0;
		t[i].mrays[1] = k ? median(t[i].wall, k) : 0;
	}
	free(h);
}

static void report(const struct args *a, const bvhlab_scene *s, int clock,
                   const struct tracer *t)
{
	printf("scene %s (%u triangles), %ux%u primary rays, 1 thread, %s\n", s->name,
	       s->triangle_count, a->size, a->size,
	       clock ? "wall clock" : "thread CPU time");
	printf("  embree rtcIntersect1: %.2f Mrays/s (%zu hits)\n", t[0].mrays[clock], t[0].hits);
	for (int k = 1; k < TRACERS; k++)
		printf("  bvhlab %s tree, %s traversal: %.2f Mrays/s (%zu hits, %.2f nodes/ray), "
		       "ratio to embree %.2f\n",
		       a->builder, bvhlab_traversal_name(k - 1), t[k].mrays[clock], t[k].hits,
		       t[k].nodes, t[0].mrays[clock] > 0 ? t[k].mrays[clock] / t[0].mrays[clock] : 0);
}

static int build(const struct args *a, const bvhlab_scene *s, bvhlab_tree *tree,
                 bvhlab_error *err)
{
	bvhlab_plugin *p = NULL;
	bvhlab_options opts = {0};
	bvhlab_prims prims = {0};
	int r = bvhlab_plugin_open(a->builder, &p, err);
	if (r == 0)
		r = bvhlab_options_init(&opts, bvhlab_plugin_builder(p));
	if (r == 0)
		r = bvhlab_prims_init(&prims, s, err);
	if (r == 0)
		r = bvhlab_build(p, &opts, &prims.input, 1, tree, err);
	bvhlab_prims_finish(&prims);
	if (opts.values)
		bvhlab_options_finish(&opts);
	bvhlab_plugin_close(p);
	return r;
}

int main(int argc, char **argv)
{
	struct args a;
	bvhlab_scene *s = NULL;
	bvhlab_tree tree = {0};
	bvhlab_ray *rays = NULL;
	bvhlab_camera cam;
	bvhlab_error err = {{0}};
	if (parse_args(argc, argv, &a) < 0) {
		fprintf(stderr, "usage: embree-rays SCENE [--subdivide K] [--size N] [--min-ms MS] "
		                "[--builder PLUGIN]\n");
		return 2;
	}
	int r = load(&a, &s, &err);
	if (r == 0)
		r = build(&a, s, &tree, &err);
	if (r < 0) {
		fprintf(stderr, "embree-rays: %s\n", err.message);
		return 1;
	}
	bvhlab_camera_frame(&s->bounds, &cam);
	size_t n = (size_t)a.size * a.size;
	static struct tracer t[TRACERS];
	if (bvhlab_rays_primary(&cam, a.size, a.size, &rays) < 0)
		return 1;
	RTCDevice dev = rtcNewDevice("threads=1");
	RTCScene sc = embree_scene(dev, s);
	time_all(sc, &tree, s, rays, n, &a, t);
	for (int clock = 0; clock < 2; clock++)
		report(&a, s, clock, t);
	rtcReleaseScene(sc);
	rtcReleaseDevice(dev);
	free(rays);
	bvhlab_tree_finish(&tree);
	bvhlab_scene_destroy(s);
	return 0;
}
