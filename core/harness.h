/*
 * The experiment harness: every scene x builder x thread count of a config,
 * timed, validated and measured, with results written as runs finish.
 */
#ifndef BVHLAB_CORE_HARNESS_H
#define BVHLAB_CORE_HARNESS_H

#include <stdbool.h>
#include <stdint.h>

#include <bvhlab/bvhlab.h>

#include "config.h"

/* Loads or generates one config scene, subdivides it and names it. */
int harness_load_scene(const struct config_scene *cs, bvhlab_scene **out, bvhlab_error *err);

/*
 * Runs the whole config. Progress lines go to stderr unless quiet.
 * Returns 0 when every run is ok and valid, 1 when some run is not (all are
 * still recorded), or a negative errno when nothing could be recorded
 * (output folder not writable) with err set.
 */
int harness_run(const struct config *cfg, bool quiet, bvhlab_error *err);

/* One timed build series of a plugin on prepared primitives. */
struct build_series {
	uint32_t warmup, repeat;
	uint32_t threads;      /* 0: all hardware threads */
	double *samples_ms;    /* [repeat], filled */
	bvhlab_tree tree;      /* the last build's tree */
};

/* Runs warmup + repeat builds; stops at the first failure (err set). */
int harness_time_builds(const bvhlab_plugin *plugin, const bvhlab_options *opts,
                        const bvhlab_build_input *input, struct build_series *s,
                        bvhlab_error *err);

/* Median, min and max of n samples (sorts a copy). */
void harness_summarise(const double *samples, uint32_t n, double *median, double *min,
                       double *max);

#endif
