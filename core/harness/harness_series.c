/*
 * The harness's building blocks that the command's other subcommands
 * (build, render) share: loading a config scene and timing a build series.
 */
#include <errno.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "harness/harness.h"
#include "harness/isolate.h"
#include "util/util.h"

int harness_load_scene(const struct config_scene *cs, bvhlab_scene **out, bvhlab_error *err)
{
	int r = cs->path ? bvhlab_scene_load(cs->path, out, err)
	                 : bvhlab_scene_generate(cs->generator, &cs->gen, out, err);
	if (r < 0)
		return r;
	if (cs->subdivide > 0)
		r = bvhlab_scene_subdivide(*out, cs->subdivide, err);
	if (r == 0 && cs->name)
		r = bvhlab_scene_set_name(*out, cs->name);
	if (r < 0) {
		if (r == -ENOMEM && err && !err->message[0])
			error_set(err, "scene '%s': out of memory", cs->name);
		bvhlab_scene_destroy(*out);
		*out = NULL;
	}
	return r;
}

/* What the scene probe sends back. */
struct scene_probe {
	uint32_t ok;
	char error[sizeof(((bvhlab_error *)0)->message)];
};

/* In the child: the scene and its primitives, as the sweep will make them. */
static void probe_work(void *arg, void *report, size_t size)
{
	struct scene_probe *rep = report;
	bvhlab_scene *scene = NULL;
	bvhlab_prims prims = {0};
	bvhlab_error err = {{0}};
	(void)size;
	int r = harness_load_scene(arg, &scene, &err);
	if (r == 0)
		r = bvhlab_prims_init(&prims, scene, &err);
	rep->ok = r == 0;
	snprintf(rep->error, sizeof(rep->error), "%s", err.message);
}

/* The largest memory limit any builder runs under; 0 when one has none. */
static uint64_t largest_limit_mb(const struct config *cfg)
{
	uint64_t most = 0;
	for (size_t b = 0; b < cfg->builder_count; b++) {
		uint64_t mb = cfg->builders[b].memory_limit_mb ? cfg->builders[b].memory_limit_mb
		                                                : cfg->memory_limit_mb;
		if (mb == 0)
			return 0;
		most = mb > most ? mb : most;
	}
	return most;
}

int harness_probe_scene(const struct config *cfg, const struct config_scene *cs,
                        bvhlab_error *err)
{
	struct scene_probe rep = {0};
	char why[sizeof(rep.error)] = "", limit[64] = "";
	uint64_t mb = largest_limit_mb(cfg);
	struct isolate_limits limits = {.timeout_s = cfg->timeout_s, .memory_bytes = mb << 20};
	int outcome = isolate_call(probe_work, (void *)cs, &rep, sizeof(rep), &limits, why,
	                           sizeof(why));
	if (outcome == ISOLATE_REPORTED && rep.ok)
		return 0;
	rep.error[sizeof(rep.error) - 1] = '\0';
	if (mb)
		snprintf(limit, sizeof(limit), " (under memory_limit_mb = %llu)",
		         (unsigned long long)mb);
	if (outcome == ISOLATE_TIMEOUT)
		error_set(err, "scene '%s': loading took longer than timeout_s (%g s); killed",
		          cs->name, cfg->timeout_s);
	else if (outcome == ISOLATE_REPORTED)
		error_set(err, "%s%s", rep.error, strstr(rep.error, "memory") ? limit : "");
	else
		error_set(err, "scene '%s': loading %s%s", cs->name, why, limit);
	return outcome == ISOLATE_TIMEOUT ? -ETIMEDOUT : -EINVAL;
}

static int cmp_double(const void *a, const void *b)
{
	double x = *(const double *)a, y = *(const double *)b;
	return (x > y) - (x < y);
}

void harness_summarise(const double *samples, uint32_t n, double *median, double *min,
                       double *max)
{
	double sorted[n ? n : 1];
	memcpy(sorted, samples, n * sizeof(double));
	qsort(sorted, n, sizeof(double), cmp_double);
	*min = n ? sorted[0] : 0;
	*max = n ? sorted[n - 1] : 0;
	*median = n == 0 ? 0 : n % 2 ? sorted[n / 2] : 0.5 * (sorted[n / 2 - 1] + sorted[n / 2]);
}

int harness_time_builds(const bvhlab_plugin *plugin, const bvhlab_options *opts,
                        const bvhlab_build_input *input, struct build_series *s,
                        bvhlab_error *err)
{
	for (uint32_t k = 0; k < s->warmup + s->repeat; k++) {
		double t0 = util_now();
		int r = bvhlab_build(plugin, opts, input, s->threads, &s->tree, err);
		double t1 = util_now();
		if (r < 0)
			return r;
		if (k >= s->warmup)
			s->samples_ms[k - s->warmup] = (t1 - t0) * 1e3;
	}
	return 0;
}

