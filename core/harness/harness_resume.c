/*
 * Resuming a sweep: the runs kept are those this sweep would make the same
 * way, judged by a run's identity (scene, builder, resolved threads and the
 * hash of its options) and by whether its figures are final.
 */
#include <errno.h>
#include <stdio.h>
#include <stdlib.h>

#include "harness/harness_resume.h"
#include "util/util.h"

int harness_resume(struct results *res, const struct run_list *list, bool quiet, bool *all_ok,
                   bvhlab_error *err)
{
	const struct config *cfg = list->cfg;
	size_t kept = 0, not_ok = 0;
	struct run_identity *keys = calloc(list->count + 1, sizeof(*keys));
	if (!keys)
		return error_set(err, "out of memory"), -ENOMEM;
	for (size_t k = 0; k < list->count; k++)
		keys[k] = list->runs[k].key;
	int r = results_resume(res, keys, list->count, &kept, &not_ok, err);
	free(keys);
	if (r == -ENOENT) {
		if (!quiet)
			fprintf(stderr, "bvhlab: nothing to resume in %s/; starting afresh\n",
			        cfg->output);
		return 0;
	}
	if (r < 0)
		return r;
	*all_ok = not_ok == 0;
	if (!quiet)
		fprintf(stderr, "bvhlab: resuming %s/: %zu finished run%s kept\n", cfg->output, kept,
		        kept == 1 ? "" : "s");
	return 0;
}

static const char *plural(size_t n)
{
	return n == 1 ? "" : "s";
}

int harness_forget_stale(struct results *res, const struct config *cfg,
                         const struct harness_builder *builders, bool retry_failed, bool quiet,
                         bool *all_ok, bvhlab_error *err)
{
	size_t changed = 0, failed = 0, provisional = results_forget_provisional(res);
	for (size_t b = 0; b < cfg->builder_count; b++) {
		const struct harness_builder *hb = &builders[b];
		if (hb->opts_ok)
			changed += results_forget_runs(res, hb->cb->name, hb->options_hash, false);
		if (retry_failed)
			failed += results_forget_runs(res, hb->cb->name, NULL, true);
	}
	if (!quiet && provisional)
		fprintf(stderr, "bvhlab: %zu resumed run%s with provisional ray timings (killed "
		        "before their rounds) will run again\n", provisional, plural(provisional));
	if (!quiet && changed)
		fprintf(stderr, "bvhlab: %zu resumed run%s made with other options will run again\n",
		        changed, plural(changed));
	if (!quiet && failed)
		fprintf(stderr, "bvhlab: --retry-failed: %zu run%s that did not end ok will run "
		        "again\n", failed, plural(failed));
	(void)err; /* the file changes as each is made again, not before */
	*all_ok = results_all_ok(res);
	return 0;
}
