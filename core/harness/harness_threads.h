/*
 * Which thread counts a sweep's builders run at (harness_threads.c): what
 * the run list needs of an opened builder, and the counts it leaves out.
 */
#ifndef BVHLAB_CORE_HARNESS_THREADS_H
#define BVHLAB_CORE_HARNESS_THREADS_H

#include <stdbool.h>

#include "harness/harness_builders.h"
#include "output/results.h"
#include "plan/plan.h"

/* The run list's view of an opened builder: serial when its plugin loaded
 * without the PARALLEL flag (one whose plugin did not load keeps all its
 * runs, to record them), and its options' hash. */
struct plan_builder harness_plan_builder(const struct harness_builder *hb);

/* Says which thread counts of the list's serial builders are not
 * applicable, on stderr (unless quiet) and in results.json's
 * "not_applicable". 0, or -ENOMEM with err set. */
int harness_note_not_applicable(const struct run_list *list, struct results *res, bool quiet,
                                bvhlab_error *err);

#endif
