/*
 * Single-ray throughput of Embree 3 (rtcIntersect1) beside the core's
 * traversals (stack, stackless, wide, wide4, wide8), one thread, the same
 * primary and diffuse rays, in one process: the yardstick of the
 * per-thread traversal speed (issues 17 and 41).
 *
 *   build/bench/embree-rays SCENE [--subdivide K] [--size N] [--min-ms MS]
 *                           [--builder PLUGIN] [--refine PLUGIN[:KEY=VALUE,...]] [--count]
 *
 * e.g. `--builder sah_tasks --refine collapse:width=8` times wide8 on the
 * collapsed 8-wide tree. Embree's BVH is its own (rtcCommitScene, default
 * quality, 4- or 8-wide nodes as the CPU suits); ours is the plugin's tree
 * (and stage's). Rounds and clocks: rays_bench.c.
 */
#include <embree3/rtcore.h>
#include <stdio.h>
#include <string.h>

#include "rays_bench.h"

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
static size_t embree_pass(void *peer, const bvhlab_ray *rays, size_t n)
{
	RTCScene sc = peer;
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

int main(int argc, char **argv)
{
	struct rb_args a;
	struct rb_setup s;
	bvhlab_error err = {{0}};
	if (rb_parse(argc, argv, "embree-rays", &a) < 0)
		return 2;
	if (rb_setup_init(&a, &s, &err) < 0) {
		fprintf(stderr, "embree-rays: %s\n", err.message);
		rb_setup_finish(&s);
		return 1;
	}
	RTCDevice dev = rtcNewDevice("threads=1");
	RTCScene sc = embree_scene(dev, s.scene);
	rb_run(&a, &s, "embree rtcIntersect1", embree_pass, sc);
	rtcReleaseScene(sc);
	rtcReleaseDevice(dev);
	rb_setup_finish(&s);
	return 0;
}
