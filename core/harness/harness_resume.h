/*
 * `bvhlab run --resume`: taking over an output folder's finished runs, and
 * forgetting those this sweep would not make as they are (harness_resume.c).
 */
#ifndef BVHLAB_CORE_HARNESS_RESUME_H
#define BVHLAB_CORE_HARNESS_RESUME_H

#include <stdbool.h>

#include "config/config.h"
#include "harness/harness_builders.h"
#include "output/results.h"
#include "plan/plan.h"

/* Takes over the finished runs of res's folder (none there: a fresh start,
 * said unless quiet), each one a run of the list, and marks those whose
 * identity changed to be made again, saying how many and why ("3 runs
 * rerun: scene 's' changed") unless quiet; *all_ok whether all of them
 * are ok. 0 or a negative errno with err set (results_resume). */
int harness_resume(struct results *res, const struct run_list *list, bool quiet, bool *all_ok,
                   bvhlab_error *err);

/*
 * Resumed runs that are not what this sweep would make are made again:
 * those whose ray timings are one provisional slice (killed before the
 * scene's rounds), and with retry_failed those that did not end ok. Says how many unless
 * quiet and recomputes *all_ok; each stays in the file until its new record
 * replaces it.
 */
int harness_forget_stale(struct results *res, const struct config *cfg,
                         const struct harness_builder *builders, bool retry_failed, bool quiet,
                         bool *all_ok, bvhlab_error *err);

#endif
