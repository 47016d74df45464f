/*
 * Which thread counts a builder runs at. One without the PARALLEL flag
 * ignores its thread count: timing it at 2 threads would time the same
 * single-threaded build again and show a "speedup" of noise, so it runs
 * once per scene and its other thread counts are said to be not
 * applicable (README, "Experiment configs").
 */
#include <errno.h>
#include <stdio.h>

#include "harness/harness_builders.h"
#include "output/results.h"

static bool serial(const struct harness_builder *hb)
{
	return hb->plugin && !(bvhlab_plugin_builder(hb->plugin)->flags & BVHLAB_BUILDER_PARALLEL);
}

static uint32_t resolved(uint32_t t)
{
	return t ? t : bvhlab_hardware_threads();
}

size_t harness_first_run(const struct harness_builder *hb, const uint32_t *threads, size_t n)
{
	for (size_t t = 0; serial(hb) && t < n; t++)
		if (resolved(threads[t]) == 1)
			return t;
	return 0;
}

bool harness_thread_applies(const struct harness_builder *hb, const uint32_t *threads,
                            size_t n, size_t t, bool by_id)
{
	return by_id || !serial(hb) || t == harness_first_run(hb, threads, n);
}

int harness_note_not_applicable(const struct harness_builder *hb, const uint32_t *threads,
                                size_t n, struct results *res, bool quiet)
{
	static const char reason[] = "not a parallel builder (no PARALLEL flag): one run per "
	                             "scene, at 1 thread";
	uint32_t skipped[CONFIG_MAX_THREADS];
	char list[256] = "";
	size_t k = 0, used = 0, first = harness_first_run(hb, threads, n);
	for (size_t t = 0; serial(hb) && t < n && k < CONFIG_MAX_THREADS; t++) {
		if (t == first)
			continue;
		skipped[k++] = resolved(threads[t]);
		if (used < sizeof(list))
			used += (size_t)snprintf(list + used, sizeof(list) - used, "%s%u",
			                         used ? ", " : "", skipped[k - 1]);
	}
	if (k == 0)
		return 0;
	if (!quiet)
		fprintf(stderr, "bvhlab: builder '%s': %s; thread count%s %s not applicable\n",
		        hb->cb->name, reason, k == 1 ? "" : "s", list);
	return results_set_not_applicable(res, hb->cb->name, skipped, k, reason);
}
