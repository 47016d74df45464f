/*
 * Resuming a sweep: the runs kept are those this sweep would make the same
 * way, judged by a run's identity (its slot, scene x builder x resolved
 * threads, and the hash of everything that shapes its figures,
 * run_identity.c) and by whether its figures are final.
 */
#include <errno.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "harness/harness_resume.h"
#include "util/util.h"

static const char *plural(size_t n)
{
	return n == 1 ? "" : "s";
}

/* Why kept runs are made again: each distinct reason with its count. */
struct reasons {
	struct reason {
		const char *what, *name; /* "scene" and its name, ... */
		size_t count;
	} list[16];
	size_t count, others;
};

static void note_change(void *ctx, const struct run_identity *key, const char *what)
{
	struct reasons *r = ctx;
	const char *name = !strcmp(what, "scene") ? key->scene : !strcmp(what, "builder")
	                   ? key->builder : "";
	for (size_t k = 0; k < r->count; k++)
		if (!strcmp(r->list[k].what, what) && !strcmp(r->list[k].name, name)) {
			r->list[k].count++;
			return;
		}
	if (r->count == sizeof(r->list) / sizeof(r->list[0])) {
		r->others++;
		return;
	}
	r->list[r->count++] = (struct reason){.what = what, .name = name, .count = 1};
}

/* "3 runs rerun: scene 's' changed (2), builder 'B' changed (1)". */
static void say_changes(const struct reasons *r, size_t total)
{
	fprintf(stderr, "bvhlab: %zu run%s rerun:", total, plural(total));
	for (size_t k = 0; k < r->count; k++) {
		const struct reason *c = &r->list[k];
		const char *sep = k ? "," : "";
		if (!strcmp(c->what, "measure"))
			fprintf(stderr, "%s measurement settings changed", sep);
		else if (!strcmp(c->what, "record"))
			fprintf(stderr, "%s recorded without an identity (an older bvhlab)", sep);
		else
			fprintf(stderr, "%s %s '%s' changed", sep, c->what, c->name);
		if (r->count > 1 || r->others)
			fprintf(stderr, " (%zu)", c->count);
	}
	if (r->others)
		fprintf(stderr, ", other changes (%zu)", r->others);
	fputc('\n', stderr);
}

int harness_resume(struct results *res, const struct run_list *list, bool quiet, bool *all_ok,
                   bvhlab_error *err)
{
	const struct config *cfg = list->cfg;
	size_t kept = 0, not_ok = 0, changed = 0, gone = 0;
	struct reasons why = {0};
	struct run_identity *keys = calloc(list->count + 1, sizeof(*keys));
	if (!keys)
		return error_set(err, "out of memory"), -ENOMEM;
	for (size_t k = 0; k < list->count; k++)
		keys[k] = list->runs[k].key;
	int r = results_resume(res, keys, list->count, &kept, &not_ok, err);
	if (r == 0)
		gone = results_drop_gone(res, keys, list->count);
	if (r == 0)
		changed = results_forget_changed(res, keys, list->count, note_change, &why);
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
		fprintf(stderr, "bvhlab: resuming %s/: %zu finished run%s kept\n", cfg->output,
		        kept - gone - changed, plural(kept - gone - changed));
	if (!quiet && gone)
		fprintf(stderr, "bvhlab: %zu run%s dropped: made at a thread count its builder no "
		        "longer runs at, or on a scene it no longer runs on (its threads or "
		        "\"scenes\" changed, or its plugin was not known then)\n", gone, plural(gone));
	if (!quiet && changed)
		say_changes(&why, changed);
	return 0;
}

int harness_forget_stale(struct results *res, const struct config *cfg,
                         const struct harness_builder *builders, bool retry_failed, bool quiet,
                         bool *all_ok, bvhlab_error *err)
{
	size_t failed = 0, provisional = results_forget_provisional(res);
	for (size_t b = 0; retry_failed && b < cfg->builder_count; b++)
		failed += results_forget_runs(res, builders[b].cb->name, NULL, true);
	if (!quiet && provisional)
		fprintf(stderr, "bvhlab: %zu resumed run%s with provisional ray timings (killed "
		        "before their rounds) will run again\n", provisional, plural(provisional));
	if (!quiet && failed)
		fprintf(stderr, "bvhlab: --retry-failed: %zu run%s that did not end ok will run "
		        "again\n", failed, plural(failed));
	(void)err; /* the file changes as each is made again, not before */
	*all_ok = results_all_ok(res);
	return 0;
}
