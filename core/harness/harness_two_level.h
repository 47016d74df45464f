/*
 * A two-level run's builds (harness_two_level.c; docs/instances.md): the
 * bottom plugin once per mesh, the top plugin over the instances' world
 * boxes, each level timed, validated and measured apart.
 */
#ifndef BVHLAB_CORE_HARNESS_TWO_LEVEL_H
#define BVHLAB_CORE_HARNESS_TWO_LEVEL_H

#include <bvhlab/bvhlab.h>

#include "config/config.h"
#include "harness/harness_builders.h"
#include "harness/harness_instances.h"
#include "harness/harness_measure.h"
#include "output/results.h"
#include "scene/instances.h"
#include "trace/trace_instances.h"

struct two_level_job {
	const struct scene_instanced *inst;
	const bvhlab_plugin *bottom, *top;
	const bvhlab_options *bottom_opts, *top_opts;
	uint32_t warmup, repeat, threads;
	uint32_t validate_rays; /* sampled rays per bottom tree against brute force; 0: none */
};

/* The trees a two-level series leaves: one per mesh, and the top over
 * boxes (its input kept: primitive i is instance i). */
struct two_level_trees {
	bvhlab_tree *bottom; /* [mesh_count] */
	uint32_t mesh_count;
	bvhlab_tree top;
	bvhlab_prims top_prims;
	/* The plugins' phases (a peer's input and convert): per name, the sum
	 * over the builds (each mesh's bottom, the top) of each one's median,
	 * as the bottom's build_ms sums the meshes' medians. */
	bvhlab_phase phases[BVHLAB_MAX_PHASES];
	uint32_t phase_count;
};

/*
 * warmup + repeat builds of each level; samples_ms[k] ([repeat]) the k-th
 * timed bottom builds of every mesh plus the k-th top build, *cold_ms the
 * same of the first builds. Every bottom tree is validated (structure and
 * validate_rays sampled rays against brute force over its mesh), the top
 * over the boxes, and validate_rays rays through both levels against brute
 * force over every instanced triangle; *whole gets the two-level tree's statistics (every
 * tree's nodes once, the two-level SAH), *levels the levels apart.
 * Returns TREE_OK, TREE_INVALID (err naming the level and mesh) or
 * TREE_FAILED (err saying why); trees are filled in every case and freed
 * by harness_two_level_finish.
 */
enum tree_verdict harness_two_level_series(const struct two_level_job *job,
                                           double *samples_ms, double *cold_ms,
                                           struct tree_measure *whole,
                                           struct results_two_level *levels,
                                           struct two_level_trees *trees, bvhlab_error *err);
void harness_two_level_finish(struct two_level_trees *trees);

/* The two-level SAH (docs/instances.md) of top (over inst's world boxes,
 * its own SAH top_sah), mesh m's bottom tree's SAH mesh_sah[m]. */
double harness_two_level_sah(const struct scene_instanced *inst, const bvhlab_tree *top,
                             const bvhlab_aabb *boxes, double top_sah, const double *mesh_sah);

struct series_report; /* harness_report.h */
struct harness_anim;  /* harness_anim.h */

/*
 * A sweep's two-level run, in its child: builder hb's bottom plugin and
 * options and its top's over inst, with the config's warmup, repeat and
 * validation, at `threads`. Fills rep's samples, cold_ms, tree (the
 * two-level tree's statistics) and two_level (the levels apart) as
 * harness_two_level_series gives them, sample_count (the repeats timed) and
 * validated (whether the trees were judged: TREE_OK or TREE_INVALID), and on
 * valid trees rays (the primary rays of the config's camera for scene
 * `scene`, or of one framing `flat`, the flattened scene's bounds, or when
 * NULL the top tree's root box; each traversal, CPU or device, at both
 * levels, harness_trace_rays_two_level); on an animated scene (anim's
 * frames; NULL or 0: none) then the frames, the top rebuilt or updated on
 * each (harness_anim_top.c). Returns the verdict
 * (TREE_OK, _INVALID, _FAILED: the run's status, in the same order).
 */
enum tree_verdict harness_two_level_run(const struct config *cfg,
                                        const struct harness_builder *hb,
                                        const struct scene_instanced *inst,
                                        const struct harness_anim *anim, const char *scene,
                                        const bvhlab_aabb *flat, uint32_t threads,
                                        struct series_report *rep, bvhlab_error *err);

/*
 * A frame's primary rays (cam's, frame 0's camera; NULL or no rays
 * configured: none) through tl's posed instances and trees, with the run's
 * main traversal, and the frame's cost from them (harness_frames_cost, as
 * a one-level frame's). Untraced when tracing fails.
 */
void harness_two_level_frame_rays(const struct config *cfg, const struct trace_two_level *tl,
                                  const bvhlab_camera *cam, struct frame_metrics *fm);

/* levels as a run's child sent them, its strings ended, for the record;
 * NULL when it holds no levels (a one-level run's zeroed report). */
const struct results_two_level *harness_two_level_checked(struct results_two_level *levels);

#endif
