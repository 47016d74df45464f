/*
 * What one run's child sends back (struct series_report: plain bytes in a
 * shared mapping, so what it finished survives its death), and the one
 * place it is read: checked first, since the child ran foreign code.
 */
#ifndef BVHLAB_HARNESS_REPORT_H
#define BVHLAB_HARNESS_REPORT_H

#include <stdbool.h>
#include <stdint.h>

#include <bvhlab/tree.h>

#include "harness/harness_measure.h"
#include "harness/harness_memory.h"
#include "harness/harness_rays.h"
#include "harness/harness_series.h"
#include "output/results.h"

enum series_status { SERIES_OK, SERIES_INVALID, SERIES_FAILED };

/*
 * What one run's build series produces, sent back from its child as plain
 * bytes: the tree stays behind, only its measurements come back.
 */
struct series_report {
	uint32_t status;       /* enum series_status */
	uint32_t sample_count; /* repeat, or 0 when the builds failed */
	double cold_ms;        /* the first build */
	bool validated;
	struct tree_measure tree;
	struct build_memory memory;
	bool has_device;       /* a device builder's run: its device opened */
	struct run_device device;
	struct ray_metrics rays;
	int heat_error, shade_error; /* writing the raw image files: 0 or -errno */
	bool shade_written;
	bool tree_written; /* the tree is in the job's tree_path */
	uint32_t stage_count;
	struct stage_metrics stages[HARNESS_MAX_STAGES];
	uint32_t phase_count;
	bvhlab_phase phases[BVHLAB_MAX_PHASES];
	uint32_t frame_count;  /* frames done, after samples[] (an animated scene) */
	struct results_two_level two_level; /* a two-level builder's run: its levels apart */
	bool in_frames;        /* the frames began: a death after keeps the frames done */
	char error[sizeof(((bvhlab_error *)0)->message)];
	double samples[];      /* [repeat], then struct frame_metrics [frames] */
};

/* Points run's fields into rep (which must outlive run), after checking
 * every count and terminating every string; a malformed report makes the
 * run "crashed". */
void harness_report_to_run(struct series_report *rep, uint32_t repeat, uint32_t frames,
                           struct run_record *run);

#endif /* BVHLAB_HARNESS_REPORT_H */
