/*
 * Tracing two-level scenes (trace_instances.c; docs/instances.md): each
 * CPU traversal of the top tree descends into an instance's bottom tree
 * with the ray carried into the instance's space by its inverse matrix.
 * An affine map keeps the ray parameter, so t is comparable across
 * instances. Ties in t go to the smaller (instance, primitive), the order
 * the flattened scene's primitive ids have.
 */
#ifndef BVHLAB_CORE_TRACE_INSTANCES_H
#define BVHLAB_CORE_TRACE_INSTANCES_H

#include <bvhlab/trace.h>

#include "scene/instances.h"

struct trace_view; /* trace_kernel.h */

struct trace_two_level {
	const struct scene_instanced *inst;
	const bvhlab_tree *top;    /* primitive i: instance i's world box */
	const bvhlab_tree *bottom; /* [inst->mesh_count] */
	/* What trace_two_level_prepare adds; zeroed, the stack traversal
	 * walks the trees themselves. */
	int traversal;              /* enum bvhlab_traversal, a CPU one */
	struct trace_view *views;   /* [mesh_count] each bottom tree's tracing copies */
	uint32_t **parents;         /* [mesh_count] stackless: each bottom tree's parent links */
	uint32_t *top_parents;      /* stackless: the top tree's */
};

/*
 * Makes tl traced with `traversal` at both levels: stack and stackless walk
 * the top tree and each bottom tree alike; wide, wide4 and wide8 walk each
 * bottom tree through its wide nodes (trace_view_wide) and the top tree
 * with the stack traversal (its leaves hold instances, which no wide node
 * layout holds). 0, -EINVAL (a device or unknown traversal, or links that
 * do not make a tree), -ENOMEM; on failure tl is as trace_two_level_release
 * leaves it.
 */
int trace_two_level_prepare(struct trace_two_level *tl, int traversal);
/* Frees what trace_two_level_prepare added (zeroed tl fields are fine). */
void trace_two_level_release(struct trace_two_level *tl);

/* A hit of a two-level scene: the instance, and hit.prim in its mesh. */
struct trace_inst_hit {
	bvhlab_hit hit;     /* prim BVHLAB_NO_HIT: a miss */
	uint32_t instance;
};

/* Closest hit: the top tree, then the bottom trees of the instances whose
 * boxes the ray enters. stats (may be NULL) counts nodes of both levels. */
void trace_two_level_closest(const struct trace_two_level *tl, const bvhlab_ray *ray,
                             struct trace_inst_hit *out, bvhlab_trace_stats *stats);

/* The closest hit as the batch tracer records it (trace_batch.c): the
 * primitive in its instance's mesh, t, u and v (the instance is not kept:
 * two traversals' hits agree when those four are bit-identical); stats
 * (may be NULL) counts one ray and the nodes and triangles of both levels. */
void trace_two_level_hit(const struct trace_two_level *tl, const bvhlab_ray *ray,
                         bvhlab_hit *hit, bvhlab_trace_stats *stats);

/* The same by brute force: every instance whose world box the ray enters
 * (the box holds all its triangles), every triangle of its mesh. */
void trace_two_level_brute(const struct scene_instanced *inst, const bvhlab_ray *ray,
                           struct trace_inst_hit *out);

/* Ray i of the sampled check (origins on a sphere around `bounds`, aimed
 * at random points of them or of a random instance's box); depends only
 * on (seed, i). */
void trace_two_level_ray(const struct scene_instanced *inst, const bvhlab_aabb *bounds,
                         uint64_t seed, uint32_t i, bvhlab_ray *ray);

/*
 * `count` sampled rays through the two-level trees against brute force:
 * *mismatches counts rays whose (instance, primitive, t) differ. With
 * `flat` (the flattened scene, or NULL) *flat_mismatches counts rays whose
 * hit differs from brute force over it, as bvhlab_validate_rays judges:
 * hit or miss, and t within a relative 1e-4 (the flattened vertices are
 * rounded to floats in world space, the instanced ones are not).
 */
void trace_two_level_check(const struct trace_two_level *tl, const bvhlab_scene *flat,
                           uint32_t count, uint64_t seed, uint64_t *mismatches,
                           uint64_t *flat_mismatches);

#endif
