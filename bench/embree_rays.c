/*
 * Single-ray throughput of Embree 3 (rtcIntersect1) beside the core's
 * traverser, on one thread, with the same primary rays, in one process:
 * the yardstick of the per-thread traversal speed (issue 17).
 *
 *   build/bench/embree-rays SCENE [--subdivide K] [--size N] [--min-ms MS]
 *                           [--builder PLUGIN] [--traversal stack|stackless]
 *
 * The two trace the whole batch in turn, pass after pass, until --min-ms
 * (default 1000) has passed and at least 5 times each; the medians are
 * printed with the ratio, once timed by the thread's CPU time (what the
 * harness reports) and once by the wall clock.
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
#include <bvhlab/rays.h>
#include <bvhlab/traversal.h>

#include "util/util.h"

#define MAX_SAMPLES 4096
#define MIN_REPEATS 5

struct args {
	const char *scene, *builder;
	unsigned subdivide;
	uint32_t size;
	double min_ms;
	int traversal;
};

static int parse_args(int argc, char **argv, struct args *a)
{
	*a = (struct args){.builder = "sah_seq", .size = 512, .min_ms = 1000,
	                   .traversal = BVHLAB_TRAVERSAL_STACK};
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
		else if (strcmp(argv[i], "--traversal") == 0 && v)
			a->traversal = strcmp(argv[++i], "stackless") == 0 ? BVHLAB_TRAVERSAL_STACKLESS
			                                                    : BVHLAB_TRAVERSAL_STACK;
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

/* Passes of both tracers, alternating, so a burst of load from elsewhere
 * on the machine falls on both alike; medians of each. */
static void time_both(bool wall_clock, RTCScene sc, const bvhlab_tree *tree, const bvhlab_scene *s,
                      const bvhlab_ray *rays, size_t n, const struct args *a, double mrays[2],
                      size_t hits[2], double *nodes)
{
	static double se[MAX_SAMPLES], so[MAX_SAMPLES];
	bvhlab_trace_options o = {.traversal = a->traversal, .threads = 1, .max_repeats = 1};
	bvhlab_hit *h = malloc(n * sizeof(*h));
	double total = 0, start = util_now();
	size_t k = 0;
	while (h && k < MAX_SAMPLES && (k < MIN_REPEATS || total < a->min_ms * 1e-3)) {
		bvhlab_trace_timing t;
		struct timespec c0, c1;
		double t0 = util_now();
		clock_gettime(CLOCK_THREAD_CPUTIME_ID, &c0);
		hits[0] = embree_pass(sc, rays, n);
		clock_gettime(CLOCK_THREAD_CPUTIME_ID, &c1);
		double cpu = (double)(c1.tv_sec - c0.tv_sec) + 1e-9 * (double)(c1.tv_nsec - c0.tv_nsec);
		se[k] = (double)n / (wall_clock ? util_now() - t0 : cpu) * 1e-6;
		if (bvhlab_trace_measure(tree, s, rays, n, &o, h, NULL, &t) < 0)
			break;
		so[k++] = wall_clock ? t.wall_mrays_median : t.mrays_median;
		total = util_now() - start;
		*nodes = (double)t.stats.nodes_visited / (double)t.stats.rays;
	}
	hits[1] = 0;
	for (size_t i = 0; h && i < n; i++)
		hits[1] += h[i].prim != BVHLAB_NO_HIT;
	mrays[0] = k ? median(se, k) : 0;
	mrays[1] = k ? median(so, k) : 0;
	free(h);
}

static void report(const struct args *a, const bvhlab_scene *s, bool wall_clock,
                   const double mrays[2], const size_t hits[2], double nodes)
{
	printf("scene %s (%u triangles), %ux%u primary rays, 1 thread, %s\n", s->name,
	       s->triangle_count, a->size, a->size,
	       wall_clock ? "wall clock" : "thread CPU time");
	printf("  embree rtcIntersect1: %.2f Mrays/s (%zu hits)\n", mrays[0], hits[0]);
	printf("  bvhlab %s tree, %s traversal: %.2f Mrays/s (%zu hits, %.2f nodes/ray)\n",
	       a->builder, bvhlab_traversal_name(a->traversal), mrays[1], hits[1], nodes);
	printf("  ratio bvhlab/embree: %.2f\n", mrays[0] > 0 ? mrays[1] / mrays[0] : 0);
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
		                "[--builder PLUGIN] [--traversal stack|stackless]\n");
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
	size_t n = (size_t)a.size * a.size, hits[2] = {0, 0};
	double nodes = 0, mrays[2];
	if (bvhlab_rays_primary(&cam, a.size, a.size, &rays) < 0)
		return 1;
	RTCDevice dev = rtcNewDevice("threads=1");
	RTCScene sc = embree_scene(dev, s);
	for (int clock = 0; clock < 2; clock++) {
		time_both(clock == 1, sc, &tree, s, rays, n, &a, mrays, hits, &nodes);
		report(&a, s, clock == 1, mrays, hits, nodes);
	}
	rtcReleaseScene(sc);
	rtcReleaseDevice(dev);
	free(rays);
	bvhlab_tree_finish(&tree);
	bvhlab_scene_destroy(s);
	return 0;
}
