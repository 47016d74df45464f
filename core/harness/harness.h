/*
 * The experiment harness (harness.c): every run of a config's run list
 * (plan/plan.h), timed, validated and measured, with results written as
 * runs finish.
 */
#ifndef BVHLAB_CORE_HARNESS_H
#define BVHLAB_CORE_HARNESS_H

#include <stdbool.h>
#include <stddef.h>

#include <bvhlab/bvhlab.h>

#include "config/config.h"

struct plan_file;

/* What went wrong in a sweep, for its last line. */
struct harness_tally {
	size_t not_ok;   /* runs of this process that did not end ok */
	size_t untraced; /* ok runs without ray figures (their "rays": "error" says why) */
	size_t unsaved;  /* runs that finished but could not be written */
	size_t images_lost; /* images asked for that could not be written (named above) */
};

struct harness_options {
	bool quiet;  /* no progress lines on stderr */
	bool resume; /* keep the finished runs of the output's results.json, skip them */
	bool force;  /* without resume: move an earlier results.json aside, not refuse */
	bool retry_failed; /* with resume: runs kept that did not end ok run again */
	const char *only;      /* run just these ids ("3,7,10-12" of the run list); NULL: all */
	const struct plan_file *plan; /* run from a plan: its run list must be this
	                               * machine's, its hash is recorded so merge can
	                               * match parts */
	struct harness_tally *tally; /* filled when not NULL */
};

/*
 * Runs the config's run list (the runs opts->only names, or all); each
 * run's builds in a child process unless the config says "isolate": false.
 * Returns 0 when every run (kept ones included) is ok and valid, 1 when
 * some run is not (all are still recorded), or a negative errno when
 * nothing could be recorded (a builder, thread list, --only id or plan
 * that does not fit; output folder not writable, results.json to resume
 * unreadable) with err set.
 */
int harness_run(const struct config *cfg, const struct harness_options *opts,
                bvhlab_error *err);

#endif
