/*
 * A timed build series (harness_series.c): warm-up and timed builds of one
 * plugin, each followed by its refinement stages; `bvhlab build` and the
 * sweep share it.
 */
#ifndef BVHLAB_CORE_HARNESS_SERIES_H
#define BVHLAB_CORE_HARNESS_SERIES_H

#include <stdint.h>

#include <bvhlab/bvhlab.h>

#include "harness/refine_stage.h"
#include "output/results.h"

/* One timed build series of a plugin on prepared primitives. */
struct build_series {
	uint32_t warmup, repeat;
	uint32_t threads;      /* 0: all hardware threads */
	double *samples_ms;    /* [repeat], filled: the build and every stage */
	double cold_ms;        /* the first build (warm-up or not) with its refine stages: fresh output
	                        * and builder scratch, page faults included */
	const struct refine_stage *stages; /* [stage_count], applied in order */
	uint32_t stage_count;  /* at most HARNESS_MAX_STAGES */
	struct stage_metrics *stage_out; /* [stage_count], filled */
	/* The builder's own phases (ABI 1.3 host->phase): each one's median
	 * over the timed repeats (0 in a repeat that did not report it), in
	 * the order first reported; filled. */
	bvhlab_phase phases[BVHLAB_MAX_PHASES];
	uint32_t phase_count;
	bvhlab_tree tree;      /* the last build's tree, refined */
};

/* Runs warmup + repeat builds, each followed by the stages; stops at the
 * first failure (err set). */
int harness_time_builds(const bvhlab_plugin *plugin, const bvhlab_options *opts,
                        const bvhlab_build_input *input, struct build_series *s,
                        bvhlab_error *err);

#endif
