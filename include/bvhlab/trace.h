/*
 * bvhlab — tracing rays through a tree, and the rays a tree is measured
 * with: the watertight triangle test, closest-hit and any-hit traversal
 * (single ray, stack-based, near child first), brute force for checking,
 * primary rays from a pinhole camera, diffuse secondary rays from their
 * hits, and a multithreaded batch traversal that counts what each ray
 * cost; beside the stack traversal a stackless one (parent links) and a
 * wide one for batches (the tree collapsed into 4-child nodes), and a
 * timed batch that repeats until enough time has passed, so a throughput
 * figure is over many passes rather than one short interval. Every
 * builder's tree is measured by this code, with the same rays.
 *
 * Every traversal returns the same closest hit for any ray on a valid tree:
 * the closest (t, prim) pair, ties in t broken by the smaller primitive id
 * (as bvhlab_trace_closest and bvhlab_trace_brute do), whatever order the
 * nodes are visited in.
 */
#ifndef BVHLAB_TRACE_H
#define BVHLAB_TRACE_H

#include <stdbool.h>
#include <stddef.h>
#include <stdint.h>

#include "scene.h"
#include "tree.h"
#include "types.h"

BVHLAB_BEGIN_DECLS

/* Counters a traversal adds to (may be NULL). */
typedef struct bvhlab_trace_stats {
	uint64_t rays;
	uint64_t nodes_visited;
	uint64_t tris_tested;
} bvhlab_trace_stats;

/*
 * Watertight ray/triangle test (Woop, Benthin, Wald 2013), two-sided. Uses
 * the caller's hit->t as the upper bound (initialise it to ray->tmax) and
 * reports hits with tmin < t < hit->t; u and v weight vertices 1 and 2.
 */
bool bvhlab_intersect_triangle(const bvhlab_ray *ray, const bvhlab_scene *scene,
                               uint32_t prim, bvhlab_hit *hit);

/* Closest hit through the tree (stack-based, near child first). Initialises
 * *hit (t = tmax, prim = BVHLAB_NO_HIT); nodes_visited counts nodes entered. */
void bvhlab_trace_closest(const bvhlab_tree *tree, const bvhlab_scene *scene,
                          const bvhlab_ray *ray, bvhlab_hit *hit, bvhlab_trace_stats *stats);

/*
 * Any hit (occlusion): true when some triangle is hit with tmin < t < tmax.
 * Stops at the first hit found, which fills *hit but need not be the
 * closest; *hit is initialised like bvhlab_trace_closest's. Same counters.
 */
bool bvhlab_trace_any(const bvhlab_tree *tree, const bvhlab_scene *scene,
                      const bvhlab_ray *ray, bvhlab_hit *hit, bvhlab_trace_stats *stats);

/* Closest hit by testing every triangle; initialises *hit like the above. */
void bvhlab_trace_brute(const bvhlab_scene *scene, const bvhlab_ray *ray, bvhlab_hit *hit);

/* ---- rays ------------------------------------------------------------- */

/* A pinhole camera; fov is the vertical field of view in degrees. */
typedef struct bvhlab_camera {
	float position[3];
	float target[3];
	float up[3];
	float fov_deg;
} bvhlab_camera;

/*
 * Frames a box: looks at its centre from the direction (1, 0.6, 1.4)
 * (normalised), far enough that the bounding sphere fits a 45 degree fov;
 * up is +y. An empty box gives a camera at (0, 0, 1) looking at the origin.
 */
void bvhlab_camera_frame(const bvhlab_aabb *bounds, bvhlab_camera *camera);

/*
 * One primary ray per pixel, row-major from the top-left pixel, through the
 * pixel centres; tmin 0, tmax +inf. *rays is malloc'd ([width * height]).
 * 0, -EINVAL for a degenerate camera (position = target, up parallel to the
 * view direction) or zero size, -ENOMEM.
 */
int bvhlab_rays_primary(const bvhlab_camera *camera, uint32_t width, uint32_t height,
                        bvhlab_ray **rays);

/*
 * Diffuse secondary rays: for every hit (prim != BVHLAB_NO_HIT) of the
 * primary rays, `per_hit` rays from the hit point, cosine-weighted over the
 * hemisphere around the triangle's geometric normal turned to face the
 * incoming ray. The origin is offset along that normal (relative to the
 * scene's size) so a ray does not hit its own triangle again. The same
 * seed gives the same rays. *rays is malloc'd, *count rays (may be 0, then
 * *rays is NULL). 0 or -ENOMEM.
 */
int bvhlab_rays_diffuse(const bvhlab_scene *scene, const bvhlab_ray *primary,
                        const bvhlab_hit *hits, size_t count, uint32_t per_hit, uint64_t seed,
                        bvhlab_ray **rays, size_t *ray_count);

/*
 * Shadow rays: for every hit of the primary rays, one ray from the hit
 * point (offset as bvhlab_rays_diffuse's) toward the point `light`, tmax
 * its distance to the light: an any-hit ray that hits something is in
 * shadow. *rays is malloc'd, *count rays (may be 0, then *rays is NULL).
 * 0 or -ENOMEM.
 */
int bvhlab_rays_shadow(const bvhlab_scene *scene, const bvhlab_ray *primary,
                       const bvhlab_hit *hits, size_t count, const float light[3],
                       bvhlab_ray **rays, size_t *ray_count);

/*
 * Ambient-occlusion rays: for every hit of the primary rays, one
 * cosine-weighted ray as bvhlab_rays_diffuse's, of length `length` times
 * the scene's bounding-box diagonal (tmax): short any-hit rays that mostly
 * stay near the surface. The same seed gives the same rays. 0 or -ENOMEM.
 */
int bvhlab_rays_ao(const bvhlab_scene *scene, const bvhlab_ray *primary,
                   const bvhlab_hit *hits, size_t count, float length, uint64_t seed,
                   bvhlab_ray **rays, size_t *ray_count);

/* The default point light of a scene's box: above it by its diagonal,
 * off to the side of the default camera (an empty box: around the origin). */
void bvhlab_light_frame(const bvhlab_aabb *bounds, float light[3]);

/* The geometric normal of a triangle (unit length; 0 for a degenerate one). */
void bvhlab_triangle_normal(const bvhlab_scene *scene, uint32_t prim, float normal[3]);

/*
 * Traces `count` rays with `threads` threads (0: bvhlab_hardware_threads()),
 * closest hit or any hit, in tiles of rays taken from a shared counter.
 * hits (may be NULL) gets each ray's hit; nodes (may be NULL) each ray's
 * count of nodes visited; stats (may be NULL) is added the sums of every
 * thread. *seconds (may be NULL) gets the wall time of the traversal.
 * The calling thread traces too, so a thread that cannot be started only
 * slows the batch down. 0, or -ENOMEM (then nothing was traced).
 */
int bvhlab_trace_batch(const bvhlab_tree *tree, const bvhlab_scene *scene,
                       const bvhlab_ray *rays, size_t count, bool any_hit, uint32_t threads,
                       bvhlab_hit *hits, uint32_t *nodes, bvhlab_trace_stats *stats,
                       double *seconds);

/* Which traversal a batch uses. */
enum bvhlab_traversal {
	BVHLAB_TRAVERSAL_STACK = 0,     /* bvhlab_trace_closest: near child first, stack of far ones */
	BVHLAB_TRAVERSAL_STACKLESS = 1, /* bvhlab_trace_stackless: parent links, no stack */
	BVHLAB_TRAVERSAL_WIDE = 2,      /* the tree collapsed into 4-child nodes, four box
	                                 * tests at once, nearest child first (batches only) */
	BVHLAB_TRAVERSAL_DEVICE_STACK = 3, /* the stack traversal as a kernel on a device
	                                    * (batches only; needs a device backend built:
	                                    * OpenCL) */
	BVHLAB_TRAVERSAL_DEVICE_STACKLESS = 4, /* the stackless one likewise */
	BVHLAB_TRAVERSAL_WIDE4 = 5,     /* a tree of width 3 or 4 as built, 4 lanes per node
	                                 * (a binary or wider tree: wide's collapse) */
	BVHLAB_TRAVERSAL_WIDE8 = 6,     /* a tree of width 5 to 8 as built, 8 lanes per node
	                                 * with AVX-512VL, AVX2 or portable code chosen at run
	                                 * time (width 3 or 4: wide4's; binary: wide's) */
	BVHLAB_TRAVERSAL_DEVICE_WIDE8 = 7, /* the tree as compressed 8-wide nodes (Ylitie et al.
	                                    * 2017: 80 bytes, quantised child boxes, children
	                                    * by octant) traced on a device (batches only;
	                                    * OpenCL); narrower trees collapsed to 8 first */
	BVHLAB_TRAVERSAL_COUNT = 8      /* how many there are */
};

/* The names before the device traversals said what they are, not which
 * API (deprecated; the values are the same). */
#define BVHLAB_TRAVERSAL_CL_STACK BVHLAB_TRAVERSAL_DEVICE_STACK
#define BVHLAB_TRAVERSAL_CL_STACKLESS BVHLAB_TRAVERSAL_DEVICE_STACKLESS

/* "stack" / "stackless" / "wide" / "device_stack" / "device_stackless" / "wide4" / "wide8" /
 * "device_wide8" (the keys of results.json's rays); NULL for another value. */
const char *bvhlab_traversal_name(int traversal);

/*
 * The parent of every node of a tree, for the stackless traversal:
 * (*parents)[root] = UINT32_MAX. *parents is malloc'd ([node_count]).
 * 0, -EINVAL for a tree whose child links leave the node array or give a
 * node two parents (validate first), -ENOMEM.
 */
int bvhlab_tree_parents(const bvhlab_tree *tree, uint32_t **parents);

/*
 * Closest hit (any_hit false) or any hit without a stack (Hapala et al.,
 * "Efficient Stack-less BVH Traversal for Ray Tracing", SCCG 2011): the
 * walk goes down into the near child, and back up through the parent
 * links; which child is near is decided per ray from the children's box
 * centres, so it is the same on the way down and on the way up. Memory per
 * ray is constant. Initialises *hit like bvhlab_trace_closest; stats (may
 * be NULL) counts nodes entered (a node entered again on the way up is not
 * counted again) and triangle tests. parents from bvhlab_tree_parents.
 * Returns whether something was hit.
 */
bool bvhlab_trace_stackless(const bvhlab_tree *tree, const uint32_t *parents,
                            const bvhlab_scene *scene, const bvhlab_ray *ray, bool any_hit,
                            bvhlab_hit *hit, bvhlab_trace_stats *stats);

/* How bvhlab_trace_measure traces a batch. */
typedef struct bvhlab_trace_options {
	int traversal;        /* enum bvhlab_traversal */
	bool any_hit;         /* occlusion rays: the first hit ends a ray */
	uint32_t threads;     /* tracing threads; 0: bvhlab_hardware_threads() */
	double min_ms;        /* repeat the batch until the tracing threads have run this
	                       * long (CPU time per thread: a busy machine stretches a
	                       * measurement instead of cutting its passes short) */
	uint64_t min_rays;    /* ... and at least this many rays were traced (0: no minimum) */
	uint32_t min_repeats; /* ... and at least this many passes (0 counts as 1), unless
	                       * the passes so far took 10 x min_ms */
	uint32_t max_repeats; /* at most this many passes (0: 10000) */
	const char *device;   /* the device traversals' device: "auto" (NULL), "gpu",
	                       * "cpu" or "P:D" (platform and device indices) */
} bvhlab_trace_options;

/*
 * What bvhlab_trace_measure measured. Two clocks per pass: the wall clock,
 * and the CPU time of the tracing threads (CLOCK_THREAD_CPUTIME_ID), which
 * leaves out the time they waited for a core while other processes ran.
 * cpu figures are rays per CPU second times the thread count: the
 * throughput the threads would give with a core each to themselves; wall
 * figures are what the batch really took.
 *
 * mrays_best goes one step further for a shared machine, where even CPU
 * time swings with what else runs (caches refilled after each switch to
 * another process): every tile of rays is timed on its own in every pass,
 * each tile keeps its least CPU time over the passes, and the batch's time
 * is the sum of those. A tile lasts tens of microseconds, so most passes
 * leave each tile undisturbed at least once: the figure is the traversal's
 * own speed, and it repeats between runs where the medians do not.
 */
/*
 * The device traversals (device_stack, device_stackless) have no tiles or
 * thread CPU time: their mrays_best is from the least kernel time over the
 * passes (the device's profiling events), median, min and max are over the
 * passes' kernel times, and the wall figures time each launch to its
 * completion (the tree and rays are uploaded once, before the passes).
 */
typedef struct bvhlab_trace_timing {
	bvhlab_trace_stats stats; /* counters of ONE pass: exact per-ray averages */
	uint32_t threads;         /* threads that traced */
	uint32_t repeats;         /* passes timed */
	double seconds_total;     /* wall time of all passes */
	double mrays_best;        /* million rays per CPU second x threads, from the
	                           * least time of every tile over the passes */
	double mrays_median;      /* million rays per CPU second x threads: median over passes */
	double mrays_min, mrays_max;
	double wall_mrays_median; /* million rays per wall-clock second: median over passes */
	double wall_mrays_min, wall_mrays_max;
} bvhlab_trace_timing;

/*
 * Traces the batch of `count` rays once, then again until the minimums of
 * *opts are met; every pass is timed on its
 * own, on both clocks, and the figures are over passes. Threads take tiles of rays
 * from a shared counter; per ray nothing is allocated or locked. hits and
 * nodes (may be NULL) get each ray's hit and count of nodes entered, from
 * the first pass. For BVHLAB_TRAVERSAL_WIDE the counters and nodes still
 * count the tree's own nodes, from an extra untimed pass of the stack
 * traversal, so they mean the same whatever traversal is timed; hits come
 * from the first wide pass. 0, -EINVAL (bad traversal, tree links for
 * stackless or wide), -ENOMEM, -ENOTSUP (a device traversal in a build
 * without a device backend), -ENODEV (no such device), -EIO; then nothing was
 * measured.
 */
int bvhlab_trace_measure(const bvhlab_tree *tree, const bvhlab_scene *scene,
                         const bvhlab_ray *rays, size_t count, const bvhlab_trace_options *opts,
                         bvhlab_hit *hits, uint32_t *nodes, bvhlab_trace_timing *timing);

BVHLAB_END_DECLS

#endif /* BVHLAB_TRACE_H */
