/*
 * A run's strategy over an animated scene's frames (docs/animation.md):
 * per frame, the builder's rebuild or the animation's update and stages,
 * timed; the tree validated (structure every frame, brute-force rays on
 * the first, middle and last); its SAH and primary rays measured; the
 * frame's modelled cost.
 */
#ifndef BVHLAB_CORE_HARNESS_FRAMES_H
#define BVHLAB_CORE_HARNESS_FRAMES_H

#include <stdbool.h>
#include <stdint.h>

#include <bvhlab/bvhlab.h>

#include "config/config.h"
#include "harness/harness_anim.h"
#include "harness/harness_builders.h"
#include "harness/harness_rays.h"
#include "harness/refine_stage.h"
#include "output/results.h"

struct frames_job {
	const struct config *cfg;
	const struct config_builder *cb; /* its "animation", or none: rebuild */
	const struct harness_anim *anim;
	const bvhlab_scene *first;       /* frame 0, the run's scene */
	const bvhlab_plugin *plugin;     /* the builder (a two-level run's top), for rebuilds */
	const bvhlab_options *opts;
	const struct refine_stage *stages; /* the builder's own, after each rebuild */
	uint32_t stage_count;
	uint32_t threads;
	bool spatial_splits;
	double first_ms;                 /* frame 0's build (the series' median) */
};

/* The update plugin and its stages, opened in the run's child. */
struct frames_updater {
	bvhlab_plugin *plugin;
	bvhlab_options opts;
	bvhlab_plugin *stage_plugins[CONFIG_MAX_REFINE];
	bvhlab_options stage_opts[CONFIG_MAX_REFINE];
	uint32_t stage_count;
};

/* job->cb's animation's update plugin and stages into u (zeroed first by
 * the caller); close frees what open got, whether it failed or not. */
int harness_frames_updater_open(const struct frames_job *job, struct frames_updater *u,
                                bvhlab_error *err);
void harness_frames_updater_close(struct frames_updater *u);

/* Frame f is rebuilt: always without "animation", else every K frames. */
bool harness_frames_rebuilds(const struct frames_job *job, uint32_t f);

/* The rebuild (job's plugin and stages) or update (u's) of frame f over
 * `in`, timed together into *ms. 0 or a negative errno (err says why). */
int harness_frames_advance(const struct frames_job *job, const struct frames_updater *u,
                           uint32_t f, const bvhlab_build_input *in, bvhlab_tree *tree,
                           double *ms, bvhlab_error *err);

/* The rays a frame traces: the config's, primary only, in one short
 * stretch (the config's min_ms spread over its rounds, one repeat). */
void harness_frames_ray_settings(const struct config *cfg, struct ray_settings *rs);

/* A frame's ray figures from the timing t of its main traversal (NULL:
 * not traced), and its modelled cost: the update plus rays_per_frame rays
 * at t's speed, unknown (costed false) when rays were asked for and none
 * was traced. */
void harness_frames_cost(const struct config *cfg, const bvhlab_trace_timing *t,
                         struct frame_metrics *fm);

/* Frame f of `frames` has its brute-force rays checked: the first, the
 * middle and the last. */
static inline bool harness_frames_rays_frame(uint32_t frames, uint32_t f)
{
	return f == 0 || f == (frames - 1) / 2 || f == frames - 1;
}

/* Room a run's report needs for the frames of scene a (0 for none). */
static inline size_t harness_frames_size(const struct harness_anim *a)
{
	return a ? a->frames * sizeof(struct frame_metrics) : 0;
}

/*
 * Runs frames 0 .. frames - 1 on `tree` (frame 0's, from the run's build
 * series; updated or rebuilt in place) into out[], *count the frames done.
 * 0 when all were done and valid; 1 when a frame's tree was invalid (err
 * names the frame; the frames before it stay); a negative errno when a
 * frame could not be made, built or updated (err says why).
 */
int harness_frames_run(const struct frames_job *job, bvhlab_tree *tree,
                       struct frame_metrics *out, uint32_t *count, bvhlab_error *err);

/*
 * The frames of a run of builder hb on the animated scene a, after its
 * series on frame 0 (`first`): samples[repeat] the series' times, the
 * frames' records after them (samples + repeat), `tree` the series' tree.
 * Returns as harness_frames_run; 0 at once for a static scene (frames 0).
 */
int harness_frames_after_series(const struct config *cfg, const struct harness_builder *hb,
                                const struct harness_anim *a, const bvhlab_scene *first,
                                uint32_t threads, double *samples, uint32_t repeat,
                                bvhlab_tree *tree, uint32_t *count, bvhlab_error *err);

/*
 * A run's child died (why: how) during frame f, the first of the frames
 * not done: why rewritten to name the frame and what it ran then ("frame
 * 3, updated by 'refit': killed by SIGSEGV ...").
 */
void harness_frames_death(const struct config_builder *cb, uint32_t f, char *why, size_t size);

#endif
