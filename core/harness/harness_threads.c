/*
 * Which thread counts a builder runs at. One without the PARALLEL flag
 * ignores its thread count: timing it at 2 threads would time the same
 * single-threaded build again and show a "speedup" of noise, so the run
 * list has it once per scene and its other thread counts are said to be
 * not applicable (README, "Experiment configs").
 */
#include <errno.h>
#include <stdio.h>

#include "harness/harness_threads.h"
#include "util/util.h"

struct plan_builder harness_plan_builder(const struct harness_builder *hb)
{
	bool serial = hb->plugin &&
	              !(bvhlab_plugin_builder(hb->plugin)->flags & BVHLAB_BUILDER_PARALLEL);
	return (struct plan_builder){.serial = serial,
	                             .options_hash = hb->opts_ok ? hb->options_hash : NULL,
	                             .builder_hash = hb->opts_ok ? hb->builder_hash : NULL,
	                             .builder_config = hb->opts_ok ? hb->identity : NULL};
}

/* One serial builder's counts left out of the list, said and recorded. */
static int note(const char *name, const struct plan_threads *t, struct results *res,
                bool quiet)
{
	static const char reason[] = "not a parallel builder (no PARALLEL flag): one run per "
	                             "scene, at 1 thread";
	uint32_t skipped[CONFIG_MAX_THREADS];
	char list[256] = "";
	size_t k = 0, used = 0;
	for (size_t i = 0; t->serial && i < t->count && k < CONFIG_MAX_THREADS; i++) {
		if (i == t->first)
			continue;
		skipped[k++] = t->resolved[i];
		if (used < sizeof(list))
			used += (size_t)snprintf(list + used, sizeof(list) - used, "%s%u",
			                         used ? ", " : "", skipped[k - 1]);
	}
	if (k == 0)
		return 0;
	if (!quiet)
		fprintf(stderr, "bvhlab: builder '%s': %s; thread count%s %s not applicable\n", name,
		        reason, k == 1 ? "" : "s", list);
	return results_set_not_applicable(res, name, skipped, k, reason);
}

int harness_note_not_applicable(const struct run_list *list, struct results *res, bool quiet,
                                bvhlab_error *err)
{
	int r = 0;
	for (size_t b = 0; r == 0 && b < list->cfg->builder_count; b++)
		r = note(list->cfg->builders[b].name, &list->threads[b], res, quiet);
	if (r < 0)
		error_set(err, "out of memory");
	return r;
}
