/*
 * The experiment harness. Scenes are the outer loop so only one scene is in
 * memory at a time; plugins are opened once. Whatever fails (a scene, a
 * plugin, a build, a tree) is recorded as a run with its status and message,
 * and the sweep goes on.
 */
#include <errno.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "harness.h"
#include "results.h"
#include "util.h"

#define RAY_SEED 0x5eedULL

/* A builder of the config, opened once for the whole sweep. */
struct harness_builder {
	const struct config_builder *cb;
	bvhlab_plugin *plugin; /* NULL when it could not be loaded */
	bvhlab_options opts;
	bool opts_ok;
	bvhlab_error error;
};

struct harness {
	const struct config *cfg;
	struct results res;
	struct harness_builder *builders;
	bool quiet;
	bool all_ok;
	uint32_t run_index, run_total;
	double start;
};

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

static uint32_t resolve_threads(uint32_t t)
{
	return t ? t : bvhlab_hardware_threads();
}

static void progress(struct harness *h, const struct run_record *run)
{
	h->run_index++;
	if (h->quiet)
		return;
	double elapsed = util_now() - h->start;
	fprintf(stderr, "[%u/%u %.1fs] %s / %s / %u thread%s: %s", h->run_index, h->run_total,
	        elapsed, run->scene, run->builder, run->threads, run->threads == 1 ? "" : "s",
	        run->status);
	if (run->sample_count && run->stats) {
		double med, mn, mx;
		harness_summarise(run->samples_ms, run->sample_count, &med, &mn, &mx);
		fprintf(stderr, ", %.2f ms median, SAH %.3f", med, run->stats->sah_cost);
	}
	if (run->error)
		fprintf(stderr, " (%s)", run->error);
	fputc('\n', stderr);
}

/* Records a run and rewrites the files, so nothing finished is ever lost. */
static void record(struct harness *h, struct run_record *run)
{
	bvhlab_error err = {{0}};
	if (strcmp(run->status, "ok") != 0)
		h->all_ok = false;
	progress(h, run);
	if (results_add_run(&h->res, run) < 0 || results_write(&h->res, &err) < 0) {
		fprintf(stderr, "bvhlab: cannot write results: %s\n",
		        err.message[0] ? err.message : "out of memory");
		h->all_ok = false;
	}
}

static const uint32_t *builder_threads(const struct harness *h, const struct config_builder *b,
                                       size_t *count)
{
	*count = b->threads ? b->thread_count : h->cfg->thread_count;
	return b->threads ? b->threads : h->cfg->threads;
}

/* Every run of a builder fails the same way (plugin or scene unusable). */
static void record_all_failed(struct harness *h, const char *scene, struct harness_builder *hb,
                              const char *error)
{
	size_t n;
	const uint32_t *threads = builder_threads(h, hb->cb, &n);
	for (size_t k = 0; k < n; k++) {
		struct run_record run = {.scene = scene, .builder = hb->cb->name,
		                         .plugin = hb->cb->plugin, .threads = resolve_threads(threads[k]),
		                         .opts = hb->opts_ok ? &hb->opts : NULL,
		                         .status = "failed", .error = error};
		record(h, &run);
	}
}

/*
 * Structure is always checked: the metrics are meaningless (and a cyclic tree
 * unsafe to walk) otherwise. The brute-force ray check is what "validate"
 * switches, since it is the expensive part.
 */
static void validate(struct harness *h, const bvhlab_scene *scene, const bvhlab_prims *prims,
                     const bvhlab_builder *desc, const bvhlab_tree *tree, struct run_record *run,
                     bvhlab_error *err)
{
	bool dup = desc->flags & BVHLAB_BUILDER_SPATIAL_SPLITS;
	run->validated = true;
	run->valid = bvhlab_validate_tree(tree, &prims->input, dup, err) == 0;
	if (!run->valid) {
		run->status = "invalid";
		run->error = err->message;
		return;
	}
	if (!h->cfg->validate)
		return;
	run->rays_checked = h->cfg->validate_rays;
	if (bvhlab_validate_rays(tree, scene, h->cfg->validate_rays, RAY_SEED, &run->mismatches,
	                         err) < 0) {
		run->status = "failed";
		run->error = err->message;
	} else if (run->mismatches) {
		run->valid = false;
		run->status = "invalid";
		snprintf(err->message, sizeof(err->message),
		         "%llu of %llu sampled rays disagree with brute force",
		         (unsigned long long)run->mismatches, (unsigned long long)run->rays_checked);
		run->error = err->message;
	}
}

static void run_one(struct harness *h, const bvhlab_scene *scene, const bvhlab_prims *prims,
                    struct harness_builder *hb, uint32_t threads)
{
	const bvhlab_builder *desc = bvhlab_plugin_builder(hb->plugin);
	double samples[h->cfg->repeat];
	struct build_series s = {.warmup = h->cfg->warmup, .repeat = h->cfg->repeat,
	                         .threads = threads, .samples_ms = samples};
	bvhlab_error err = {{0}};
	bvhlab_tree_stats stats;
	struct run_record run = {.scene = scene->name, .builder = hb->cb->name,
	                         .plugin = desc->name, .threads = resolve_threads(threads),
	                         .opts = &hb->opts, .status = "ok",
	                         .triangles = scene->triangle_count};
	if (harness_time_builds(hb->plugin, &hb->opts, &prims->input, &s, &err) < 0) {
		run.status = "failed";
		run.error = err.message;
	} else {
		run.samples_ms = samples;
		run.sample_count = s.repeat;
		validate(h, scene, prims, desc, &s.tree, &run, &err);
		if (run.valid || (run.mismatches && run.rays_checked)) {
			bvhlab_tree_stats_compute(&s.tree, &stats);
			run.stats = &stats;
		}
	}
	record(h, &run);
	bvhlab_tree_finish(&s.tree);
}

static void run_scene(struct harness *h, const struct config_scene *cs)
{
	bvhlab_scene *scene = NULL;
	bvhlab_prims prims = {0};
	bvhlab_error err = {{0}};
	int r = harness_load_scene(cs, &scene, &err);
	if (r == 0)
		r = bvhlab_prims_init(&prims, scene, &err);
	if (r < 0) {
		results_add_scene(&h->res, cs->name, cs->path ? cs->path : cs->generator, 0,
		                  err.message);
		for (size_t b = 0; b < h->cfg->builder_count; b++)
			record_all_failed(h, cs->name, &h->builders[b], err.message);
		goto out;
	}
	results_add_scene(&h->res, scene->name, scene->source, scene->triangle_count, NULL);
	for (size_t b = 0; b < h->cfg->builder_count; b++) {
		struct harness_builder *hb = &h->builders[b];
		if (!hb->plugin || !hb->opts_ok) {
			record_all_failed(h, scene->name, hb, hb->error.message);
			continue;
		}
		size_t n;
		const uint32_t *threads = builder_threads(h, hb->cb, &n);
		for (size_t t = 0; t < n; t++)
			run_one(h, scene, &prims, hb, threads[t]);
	}
out:
	bvhlab_prims_finish(&prims);
	bvhlab_scene_destroy(scene);
}

/* Opens every plugin and checks its options; a failure is kept, not fatal. */
static int open_builders(struct harness *h)
{
	h->builders = calloc(h->cfg->builder_count, sizeof(*h->builders));
	if (!h->builders)
		return -ENOMEM;
	for (size_t b = 0; b < h->cfg->builder_count; b++) {
		struct harness_builder *hb = &h->builders[b];
		hb->cb = &h->cfg->builders[b];
		if (bvhlab_plugin_open(hb->cb->plugin, &hb->plugin, &hb->error) < 0)
			goto report;
		if (bvhlab_options_init(&hb->opts, bvhlab_plugin_builder(hb->plugin)) < 0)
			return -ENOMEM;
		hb->opts_ok = config_apply_options(h->cfg, hb->cb, &hb->opts, &hb->error) == 0;
		if (hb->opts_ok)
			continue;
	report:
		fprintf(stderr, "bvhlab: builder '%s': %s\n", hb->cb->name, hb->error.message);
	}
	return 0;
}

static void close_builders(struct harness *h)
{
	for (size_t b = 0; h->builders && b < h->cfg->builder_count; b++) {
		if (h->builders[b].opts.values)
			bvhlab_options_finish(&h->builders[b].opts);
		bvhlab_plugin_close(h->builders[b].plugin);
	}
	free(h->builders);
}

static uint32_t count_runs(const struct harness *h)
{
	uint32_t total = 0;
	for (size_t b = 0; b < h->cfg->builder_count; b++) {
		size_t n;
		builder_threads(h, &h->cfg->builders[b], &n);
		total += (uint32_t)n;
	}
	return total * (uint32_t)h->cfg->scene_count;
}

int harness_run(const struct config *cfg, bool quiet, bvhlab_error *err)
{
	struct harness h = {.cfg = cfg, .quiet = quiet, .all_ok = true, .start = util_now()};
	int r = results_init(&h.res, cfg, cfg->output, err);
	if (r < 0)
		return r;
	r = results_write(&h.res, err);
	if (r == 0 && (r = open_builders(&h)) < 0)
		error_set(err, "out of memory opening plugins");
	h.run_total = count_runs(&h);
	for (size_t s = 0; r == 0 && s < cfg->scene_count; s++)
		run_scene(&h, &cfg->scenes[s]);
	close_builders(&h);
	results_finish(&h.res);
	return r < 0 ? r : h.all_ok ? 0 : 1;
}
