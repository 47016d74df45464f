/*
 * The runs of a config with their ids: the order `bvhlab run` takes them,
 * so a plan's ids, `--only` and `--resume` all name the same runs.
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

static void resolve_list(uint32_t *list, size_t n)
{
	for (size_t k = 0; k < n; k++)
		list[k] = list[k] ? list[k] : bvhlab_hardware_threads();
}

int plan_resolve_threads(struct config *cfg, bvhlab_error *err)
{
	int r = plan_check_threads(cfg, err);
	if (r < 0)
		return r;
	resolve_list(cfg->threads, cfg->thread_count);
	for (size_t b = 0; b < cfg->builder_count; b++)
		if (cfg->builders[b].threads)
			resolve_list(cfg->builders[b].threads, cfg->builders[b].thread_count);
	return 0;
}

/* Runs of one scene: every builder's thread counts. */
static size_t runs_per_scene(const struct config *cfg)
{
	size_t total = 0, n;
	for (size_t b = 0; b < cfg->builder_count; b++) {
		plan_builder_threads(cfg, &cfg->builders[b], &n);
		total += n;
	}
	return total;
}

size_t plan_run_count(const struct config *cfg)
{
	return runs_per_scene(cfg) * cfg->scene_count;
}

uint32_t plan_run_id(const struct config *cfg, size_t scene, size_t builder,
                     size_t thread_index)
{
	size_t id = scene * runs_per_scene(cfg), n;
	for (size_t b = 0; b < builder; b++) {
		plan_builder_threads(cfg, &cfg->builders[b], &n);
		id += n;
	}
	return (uint32_t)(id + thread_index);
}

int plan_runs(const struct config *cfg, struct plan_run **runs, size_t *count)
{
	size_t total = plan_run_count(cfg), k = 0;
	*runs = calloc(total ? total : 1, sizeof(**runs));
	*count = 0;
	if (!*runs)
		return -ENOMEM;
	for (size_t s = 0; s < cfg->scene_count; s++) {
		for (size_t b = 0; b < cfg->builder_count; b++) {
			size_t n;
			const uint32_t *threads = plan_builder_threads(cfg, &cfg->builders[b], &n);
			for (size_t t = 0; t < n; t++, k++)
				(*runs)[k] = (struct plan_run){.id = (uint32_t)k, .scene = s, .builder = b,
				                               .threads = threads[t]};
		}
	}
	*count = total;
	return 0;
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
