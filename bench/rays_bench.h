/*
 * What the single-ray benches share (rays_bench.c): a scene, a bvhlab tree
 * (a builder, then optionally a refinement stage such as collapse), its
 * primary rays and one diffuse bounce per primary hit, and rounds in
 * which a peer's tracer and the core's traversals take turns on the same
 * rays, one thread, so load from elsewhere falls on all alike. Used by
 * embree_rays.c and tinybvh_rays.cpp.
 *
 *   BENCH SCENE [--subdivide K] [--size N] [--min-ms MS] [--builder PLUGIN]
 *               [--refine PLUGIN[:KEY=VALUE,...]] [--count]
 *
 * --count replaces the timed rounds by one untimed pass of each tracer
 * over each kind of rays, printing each core traversal's own counters
 * (wide nodes and triangle lanes of the wide ones): the run to give
 * `valgrind --tool=callgrind`, whose instructions per ray (a tracer's
 * inclusive cost over its calls) do not depend on the machine's load.
 */
#ifndef BVHLAB_BENCH_RAYS_BENCH_H
#define BVHLAB_BENCH_RAYS_BENCH_H

#include <stdbool.h>
#include <stddef.h>
#include <stdint.h>

#include <bvhlab/bvhlab.h>
#include <bvhlab/trace.h>

#ifdef __cplusplus
extern "C" {
#endif

#define RB_KINDS 2 /* primary, diffuse */

struct rb_args {
	const char *scene, *builder, *refine;
	unsigned subdivide;
	uint32_t size;
	double min_ms;
	bool count; /* --count: one untimed pass each, own counters */
};

struct rb_setup {
	bvhlab_scene *scene;
	bvhlab_tree tree;
	bvhlab_ray *rays[RB_KINDS];
	size_t count[RB_KINDS];
};

/* A peer's pass over n rays (one thread): the rays that hit something. */
typedef size_t rb_pass_fn(void *peer, const bvhlab_ray *rays, size_t n);

/* 0, or -EINVAL with the usage printed (program name `prog`). */
int rb_parse(int argc, char **argv, const char *prog, struct rb_args *a);

/* Scene, tree and rays; 0 or a negative errno with err saying why. */
int rb_setup_init(const struct rb_args *a, struct rb_setup *s, bvhlab_error *err);
void rb_setup_finish(struct rb_setup *s);

/*
 * Rounds of the peer (named `peer_name`) and the core's CPU traversals,
 * primary then diffuse rays, until a->min_ms has passed and at least 5
 * rounds ran; prints per kind and clock the medians over rounds, each
 * traversal's ratio to the peer and its hit count beside the peer's.
 * With a->count, one untimed pass each instead (rays_bench.h's top).
 */
void rb_run(const struct rb_args *a, const struct rb_setup *s, const char *peer_name,
            rb_pass_fn *pass, void *peer);

#ifdef __cplusplus
}
#endif

#endif
