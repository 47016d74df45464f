/* Rays and images of a run (harness_rays.c): primary and diffuse rays traced
 * through a tree with every traversal the config asks for. */
#ifndef BVHLAB_CORE_HARNESS_RAYS_H
#define BVHLAB_CORE_HARNESS_RAYS_H

#include <stdint.h>

#include <bvhlab/bvhlab.h>
#include <bvhlab/trace.h>

#include "config/config.h"
#include "output/results.h"

/* Each tile keeps its best of at least this many passes (see
 * bvhlab_trace_timing): enough chances to run undisturbed. */
#define HARNESS_MIN_REPEATS 10
/* Diffuse and AO rays: the same for every builder of a scene. */
#define HARNESS_DIFFUSE_SEED 0xd1ff05eULL
#define HARNESS_AO_SEED 0xa0a0a0ULL

/* What rays a run is measured with: the config's "rays". */
struct ray_settings {
	uint32_t width, height; /* primary rays: one per pixel */
	uint32_t diffuse;       /* bounces per primary hit */
	unsigned kinds;         /* bit (1 << enum ray_kind) per kind measured */
	bool has_light;         /* light given; else bvhlab_light_frame per scene */
	float light[3];         /* the shadow rays' point light */
	float ao_length;        /* the AO rays' length, a fraction of the scene's diagonal */
	uint32_t threads;       /* tracing threads; 0: all hardware threads */
	double min_ms;          /* each batch is repeated for at least this long */
	uint32_t min_repeats;   /* ... and at least this many passes */
	uint32_t rounds;        /* slices min_ms is spread over (harness_rounds.c) */
	unsigned traversals;    /* bit (1 << enum bvhlab_traversal) for each one measured */
	int main;               /* the traversal whose hits feed images and diffuse rays */
	const char *device;     /* the cl_ traversals' OpenCL device spec (NULL: auto) */
};

/* The config's settings (cfg NULL: one quick stack pass, all threads). */
void harness_ray_settings(const struct config *cfg, struct ray_settings *rs);

/* The config's camera, or the automatic framing of the scene. */
void harness_camera(const struct config *cfg, const bvhlab_scene *scene, bvhlab_camera *cam);
/* The same for the scene named `name` whose bounds are `bounds`. */
void harness_camera_of(const struct config *cfg, const char *name, const bvhlab_aabb *bounds,
                       bvhlab_camera *cam);

/*
 * The rays of a secondary kind (diffuse, shadow, ao) from the primary
 * rays' hits, as rs asks for them: the same for every tree of a scene
 * given the same hits. *rays malloc'd (NULL when *count is 0); no rays
 * when rs does not measure the kind. 0 or -ENOMEM.
 */
int harness_secondary_rays(int kind, const bvhlab_scene *scene, const struct ray_settings *rs,
                           const bvhlab_ray *primary, const bvhlab_hit *hits, size_t n,
                           bvhlab_ray **rays, size_t *count);

/*
 * Primary rays (width x height) and, from their hits, the secondary kinds
 * of rs (`diffuse` bounces per hit, shadow and AO rays),
 * each batch timed (bvhlab_trace_measure) with every traversal of rs.
 * nodes ([width * height], may be NULL) gets nodes visited per pixel,
 * shade ([3 * width * height], may be NULL) the shaded render, both from
 * the main traversal. 0 or a negative errno, with m->error saying why (it
 * also names a traversal other than the main one that could not run: that
 * one is left out of m and the others are measured).
 */
int harness_trace_rays(const bvhlab_tree *tree, const bvhlab_scene *scene,
                       const bvhlab_camera *cam, const struct ray_settings *rs,
                       struct ray_metrics *m, uint32_t *nodes, uint8_t *shade);

/*
 * A two-level scene's primary rays (width x height from cam) timed with
 * each traversal of rs at both levels (trace_measure_two_level), into
 * m->primary; another traversal's hits are compared with the main one's
 * into m->disagreements, one that cannot run (a device traversal with no
 * device) is left out with its reason in m->error. No secondary kinds
 * (they need the flattened scene's normals).
 * 0 or a negative errno (the main traversal failing).
 */
struct trace_two_level;
int harness_trace_rays_two_level(const struct trace_two_level *tl, const bvhlab_camera *cam,
                                 const struct ray_settings *rs, struct ray_metrics *m);

/* Why no ray was traced (r a negative errno) into buf; out of memory with
 * the limit it ran under (memory_limit bytes, 0 none; only when isolated,
 * where the limit applies), as a build's failure says. */
void harness_rays_error(int r, uint64_t memory_limit, bool isolated, char *buf, size_t size);

#endif
