/*
 * The run list: the runs of a config with their ids and identities, made
 * once, in the order `bvhlab run` takes them, so a plan's ids, `--only`,
 * `--resume` and merge all name the same runs.
 */
#include <errno.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include <bvhlab/machine.h>

#include "plan/plan.h"
#include "util/util.h"

const uint32_t *plan_builder_threads(const struct config *cfg, const struct config_builder *b,
                                     size_t *count)
{
	*count = b->threads ? b->thread_count : cfg->thread_count;
	return b->threads ? b->threads : cfg->threads;
}

/* A list whose 0 (all cores) resolves to a count it already has: the two
 * would be one run twice. 0 when it is fine; else err names the list. */
static int check_list(const uint32_t *list, size_t n, const char *where, bvhlab_error *err)
{
	uint32_t all = bvhlab_hardware_threads();
	for (size_t i = 0; i < n; i++)
		for (size_t j = 0; j < i; j++) {
			uint32_t a = list[i] ? list[i] : all, b = list[j] ? list[j] : all;
			if (a != b)
				continue;
			error_set(err, "%s: duplicate thread count %u (0 means all %u hardware threads "
			          "of this machine): drop one of them", where, a, all);
			return -EINVAL;
		}
	return 0;
}

int plan_check_threads(const struct config *cfg, bvhlab_error *err)
{
	char where[320];
	int r = check_list(cfg->threads, cfg->thread_count, "'threads'", err);
	for (size_t b = 0; r == 0 && b < cfg->builder_count; b++) {
		const struct config_builder *cb = &cfg->builders[b];
		snprintf(where, sizeof(where), "builder '%s': 'threads'", cb->name);
		if (cb->threads)
			r = check_list(cb->threads, cb->thread_count, where, err);
	}
	return r;
}

/* The one place a thread count of 0 becomes this machine's. A serial
 * builder ignores its count, so it runs once: at 1 thread when it can. */
static int resolve(struct plan_threads *t, const struct config *cfg,
                   const struct config_builder *cb, bool serial)
{
	t->configured = plan_builder_threads(cfg, cb, &t->count);
	t->resolved = calloc(t->count ? t->count : 1, sizeof(*t->resolved));
	if (!t->resolved)
		return -ENOMEM;
	t->serial = serial;
	t->first = 0;
	for (size_t k = 0; k < t->count; k++)
		t->resolved[k] = t->configured[k] ? t->configured[k] : bvhlab_hardware_threads();
	for (size_t k = t->count; serial && k-- > 0;)
		t->first = t->resolved[k] == 1 ? k : t->first;
	return 0;
}

static bool listed(const struct plan_threads *t, size_t k)
{
	return !t->serial || k == t->first;
}

/* The runs of scene s of every builder that runs on it ("scenes"),
 * appended to the list. */
static void add_scene(struct run_list *list, size_t s, const struct plan_builder *builders)
{
	const struct config *cfg = list->cfg;
	list->scene_first[s] = list->count;
	for (size_t b = 0; b < cfg->builder_count; b++) {
		const struct plan_threads *t = &list->threads[b];
		for (size_t k = 0; k < t->count; k++) {
			if (!listed(t, k) || !config_builder_runs_on(&cfg->builders[b], &cfg->scenes[s]))
				continue;
			struct plan_run *run = &list->runs[list->count];
			*run = (struct plan_run){.scene = s, .builder = b, .threads = t->configured[k]};
			run->key = (struct run_identity){
				.id = (uint32_t)list->count, .scene = cfg->scenes[s].name,
				.builder = cfg->builders[b].name, .threads = t->resolved[k],
				.threads_configured = t->configured[k],
				.options_hash = builders ? builders[b].options_hash : NULL};
			plan_identity_key(list, run);
			list->count++;
		}
	}
	list->scene_first[s + 1] = list->count;
}

int plan_list_make(struct run_list *list, const struct config *cfg,
                   const struct plan_builder *builders, bvhlab_error *err)
{
	size_t per_scene = 0;
	memset(list, 0, sizeof(*list));
	list->cfg = cfg;
	int r = plan_check_threads(cfg, err);
	if (r < 0)
		return r;
	list->threads = calloc(cfg->builder_count + 1, sizeof(*list->threads));
	list->scene_first = calloc(cfg->scene_count + 1, sizeof(*list->scene_first));
	r = list->threads && list->scene_first ? 0 : -ENOMEM;
	for (size_t b = 0; r == 0 && b < cfg->builder_count; b++) {
		r = resolve(&list->threads[b], cfg, &cfg->builders[b], builders && builders[b].serial);
		per_scene += list->threads[b].serial ? 1 : list->threads[b].count;
	}
	if (r == 0 && !(list->runs = calloc(per_scene * cfg->scene_count + 1, sizeof(*list->runs))))
		r = -ENOMEM;
	if (r == 0)
		r = plan_identity_make(list, builders);
	for (size_t s = 0; r == 0 && s < cfg->scene_count; s++)
		add_scene(list, s, builders);
	if (r < 0) {
		plan_list_finish(list);
		error_set(err, "out of memory");
	}
	return r;
}

void plan_list_finish(struct run_list *list)
{
	for (size_t b = 0; list->threads && b < list->cfg->builder_count; b++)
		free(list->threads[b].resolved);
	plan_identity_finish(list);
	free(list->threads);
	free(list->scene_first);
	free(list->runs);
	memset(list, 0, sizeof(*list));
}

const struct plan_run *plan_list_find(const struct run_list *list, size_t scene,
                                      size_t builder, size_t thread_index)
{
	for (size_t k = list->scene_first[scene]; k < list->scene_first[scene + 1]; k++) {
		const struct plan_run *run = &list->runs[k];
		if (run->builder == builder &&
		    run->key.threads == list->threads[builder].resolved[thread_index])
			return run;
	}
	return NULL;
}

const struct plan_run *plan_list_first(const struct run_list *list, size_t scene,
                                       size_t builder)
{
	for (size_t k = list->scene_first[scene]; k < list->scene_first[scene + 1]; k++)
		if (list->runs[k].builder == builder)
			return &list->runs[k];
	return NULL;
}

/* One "N" or "N-M" of an --only list; *end past it. */
static int parse_range(const char *p, const char **end, unsigned long *lo, unsigned long *hi)
{
	char *e = NULL;
	errno = 0;
	*lo = *hi = strtoul(p, &e, 10);
	if (e == p || errno || *p == '-' || *p == '+')
		return -EINVAL;
	if (*e == '-') {
		const char *q = e + 1;
		*hi = strtoul(q, &e, 10);
		if (e == q || errno || *q == '-' || *q == '+' || *hi < *lo)
			return -EINVAL;
	}
	*end = e;
	return *e == ',' || *e == '\0' ? 0 : -EINVAL;
}

int plan_parse_only(const char *text, size_t run_count, bool **only, bvhlab_error *err)
{
	*only = calloc(run_count ? run_count : 1, sizeof(**only));
	if (!*only) {
		error_set(err, "out of memory");
		return -ENOMEM;
	}
	const char *p = text;
	do {
		unsigned long lo, hi;
		const char *end = p;
		if (parse_range(p, &end, &lo, &hi) < 0) {
			error_set(err, "--only needs run ids like 3,7,10-12, not '%s'", text);
			goto fail;
		}
		if (hi >= run_count) {
			error_set(err, "--only: there is no run %lu; this config has %zu runs (ids 0 to "
			          "%zu, see `bvhlab plan`)", hi, run_count, run_count ? run_count - 1 : 0);
			goto fail;
		}
		for (unsigned long id = lo; id <= hi; id++)
			(*only)[id] = true;
		p = *end ? end + 1 : end;
	} while (*p);
	return 0;
fail:
	free(*only);
	*only = NULL;
	return -EINVAL;
}

void plan_hash_text(const char *text, char out[17])
{
	uint64_t h = 0xcbf29ce484222325ULL;
	for (const unsigned char *p = (const unsigned char *)text; *p; p++) {
		h ^= *p;
		h *= 0x100000001b3ULL;
	}
	snprintf(out, 17, "%016llx", (unsigned long long)h);
}
