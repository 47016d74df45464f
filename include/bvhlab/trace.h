/*
 * bvhlab — tracing rays through a tree, and the rays a tree is measured
 * with: the watertight triangle test, closest-hit and any-hit traversal
 * (single ray, stack-based, near child first), brute force for checking,
 * primary rays from a pinhole camera, diffuse secondary rays from their
 * hits, and a multithreaded batch traversal that counts what each ray
 * cost. Every builder's tree is measured by this code, with the same rays.
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

BVHLAB_END_DECLS

#endif /* BVHLAB_TRACE_H */
