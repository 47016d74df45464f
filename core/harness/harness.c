/*
 * The experiment harness: it walks the run list (plan/plan.h), whose
 * scenes are the outer loop so only one scene is in memory at a time;
 * plugins are opened once. Whatever fails (a scene, a
 * plugin, a build, a tree) is recorded as a run with its status and message,
 * and the sweep goes on.
 */
#include <errno.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/mman.h>
#include <unistd.h>

#include "harness/harness.h"
#include "harness/harness_builders.h"
#include "harness/harness_estimate.h"
#include "harness/harness_frames.h"
#include "harness/harness_images.h"
#include "harness/harness_measure.h"
#include "harness/harness_memory.h"
#include "harness/harness_rays.h"
#include "harness/harness_report.h"
#include "harness/harness_resume.h"
#include "harness/harness_rounds.h"
#include "harness/harness_scene.h"
#include "harness/harness_series.h"
#include "harness/harness_threads.h"
#include "harness/harness_two_level.h"
#include "harness/isolate.h"
#include "harness/progress.h"
#include "machine/machine.h"
#include "output/results.h"
#include "output/images.h"
#include "output/safe_file.h"
#include "plan/plan.h"
#include "tree/tree_spare.h"
#include "util/util.h"

struct harness {
	const struct config *cfg;
	struct run_list list; /* every run of the sweep, made once */
	bool *only; /* [run id]: the runs to do; NULL: all */
	struct results res;
	struct harness_builder *builders;
	struct progress progress;
	bool all_ok;
	struct harness_tally tally;
	bool images;     /* images asked for, and the images module is there */
	bool shade_done; /* this scene's shaded render is on its way */
	int shade_error; /* the last failure to leave it (-errno), said if no run does */
	bool rounds_on;  /* this scene's rays are timed in interleaved rounds */
	struct harness_rounds rounds; /* this scene's trees waiting for them */
	struct harness_anim anim; /* this scene's animation, frames 0 if none (harness_anim.c) */
	struct scene_instanced inst; /* this scene's two-level form, if it has "instances" */
};

/* One run's build series, as handed to the child. */
struct series_job {
	const struct harness *h;
	const bvhlab_scene *scene;
	const bvhlab_prims *prims;
	const struct harness_builder *hb;
	const struct plan_run *run;
	const char *heat_path;  /* where the child leaves nodes per pixel, or NULL */
	const char *shade_path; /* where it leaves the shaded render, or NULL */
	const char *tree_path;  /* where it leaves its tree for the rounds, or NULL */
};

/* Records a run and rewrites the files, so nothing finished is ever lost. */
static void record(struct harness *h, struct run_record *run)
{
	bvhlab_error err = {{0}};
	h->tally.not_ok += strcmp(run->status, "ok") != 0;
	/* A valid tree whose rays could not be traced stays ok ("rays": "error"
	 * says why), but the last line counts it. */
	h->tally.untraced += !strcmp(run->status, "ok") && run->rays && !run->rays->measured;
	if (strcmp(run->status, "ok") != 0)
		h->all_ok = false;
	progress_done(&h->progress, run);
	if (results_add_run(&h->res, run) < 0 || results_write(&h->res, &err) < 0) {
		fprintf(stderr, "bvhlab: cannot write results: %s\n",
		        err.message[0] ? err.message : "out of memory");
		h->tally.unsaved++;
		h->all_ok = false;
	}
}

/* A run of the list this sweep makes: named by --only (or all of them), of
 * a builder that is not skipped (optional, its plugin missing). */
static bool wanted(const struct harness *h, const struct plan_run *run)
{
	return (!h->only || h->only[run->key.id]) && !h->builders[run->builder].skipped;
}

/* A run not wanted, or kept from the results resumed (counted as done). */
static bool skip_run(struct harness *h, const struct plan_run *run)
{
	if (!wanted(h, run))
		return true;
	if (!results_has_run(&h->res, &run->key))
		return false;
	h->progress.index++;
	return true;
}

/* A run's record as far as its identity and builder tell. */
static struct run_record run_record_of(const struct plan_run *run,
                                       const struct harness_builder *hb)
{
	return (struct run_record){.id = run->key.id, .scene = run->key.scene,
	                           .builder = run->key.builder, .plugin = hb->cb->plugin,
	                           .threads = run->key.threads,
	                           .opts = hb->opts_ok ? &hb->opts : NULL,
	                           .options_hash = hb->opts_ok ? hb->options_hash : NULL,
	                           .key = &run->key};
}

/* A run that fails before it starts (its plugin or scene unusable). */
static void record_failed(struct harness *h, const struct plan_run *run, const char *status,
                          const char *error)
{
	struct run_record rec = run_record_of(run, &h->builders[run->builder]);
	rec.status = status;
	rec.error = error;
	if (!skip_run(h, run))
		record(h, &rec);
}

/* Resumed runs already hold every run of the scene: no need to load it. */
static bool scene_done(struct harness *h, size_t s)
{
	uint32_t done = 0, total = 0;
	for (size_t k = h->list.scene_first[s]; k < h->list.scene_first[s + 1]; k++) {
		const struct plan_run *run = &h->list.runs[k];
		if (!wanted(h, run))
			continue;
		total++;
		done += results_has_run(&h->res, &run->key);
	}
	if (done < total)
		return false;
	h->progress.index += total;
	return true;
}

/* Whether the job's builder may duplicate references (spatial splits):
 * its trees are validated, here and in the rounds, as such. */
static bool spatial_splits(const struct series_job *job)
{
	return bvhlab_plugin_builder(job->hb->plugin)->flags & BVHLAB_BUILDER_SPATIAL_SPLITS;
}

/* Validation, statistics and EPO (harness_measure.c), into the report. */
static void measure(const struct series_job *job, const bvhlab_tree *tree,
                    struct series_report *rep, bvhlab_error *err)
{
	const struct config *cfg = job->h->cfg;
	static const uint32_t status[] = {SERIES_OK, SERIES_INVALID, SERIES_FAILED};
	rep->validated = true;
	rep->status = status[harness_measure_tree(tree, job->scene, &job->prims->input,
	                                          spatial_splits(job),
	                                          cfg->validate ? cfg->validate_rays : 0,
	                                          &rep->tree, err)];
}

/* Per-pixel buffers of the images this run draws; NULL when it draws none. */
static int image_buffers(const struct series_job *job, size_t n, uint32_t **nodes,
                         uint8_t **shade)
{
	*nodes = job->heat_path ? malloc(n * sizeof(**nodes)) : NULL;
	*shade = job->shade_path ? malloc(3 * n) : NULL;
	return (job->heat_path && !*nodes) || (job->shade_path && !*shade) ? -ENOMEM : 0;
}

/* Traversal statistics on the valid tree, and the raw image data. A
 * failure here costs the numbers, not the run: the tree itself is fine. */
static void trace_rays(const struct series_job *job, const bvhlab_tree *tree,
                       struct series_report *rep)
{
	const struct config *cfg = job->h->cfg;
	size_t n = (size_t)cfg->ray_width * cfg->ray_height;
	uint32_t *nodes;
	uint8_t *shade;
	bvhlab_camera cam;
	struct ray_settings rs;
	if (n == 0)
		return;
	harness_camera(cfg, job->scene, &cam);
	harness_ray_settings(cfg, &rs);
	/* With its tree kept for the rounds, which measure again, the run times
	 * one provisional slice; without (a full disk), all of min_ms here. */
	if (job->tree_path)
		rep->tree_written = harness_rounds_write_tree(job->tree_path, tree) == 0;
	if (rep->tree_written) {
		rs.min_ms /= rs.rounds;
		rs.min_repeats = 1;
	}
	int r = image_buffers(job, n, &nodes, &shade);
	if (r == 0)
		r = harness_trace_rays(tree, job->scene, &cam, &rs, &rep->rays, nodes, shade);
	/* One slice, until the scene's rounds replace it. */
	rep->rays.provisional = r == 0 && rep->tree_written;
	if (r == 0 && nodes)
		rep->heat_error = images_write_raw(job->heat_path, nodes, n * sizeof(*nodes));
	if (r == 0 && shade)
		rep->shade_error = images_write_raw(job->shade_path, shade, 3 * n);
	rep->shade_written = r == 0 && shade && rep->shade_error == 0;
	/* The run stays ok (its tree is); its "rays" says why there are no figures. */
	if (r < 0 && !rep->rays.error[0])
		harness_rays_error(r, harness_run_limits(job->h->cfg, job->hb->cb).memory_bytes,
		                   job->h->cfg->isolate, rep->rays.error, sizeof(rep->rays.error));
	free(nodes);
	free(shade);
}

/* Warm-up, timed builds, validation and metrics: what runs in the child. */
static void series_work(void *arg, void *report, size_t size)
{
	const struct series_job *job = arg;
	struct series_report *rep = report;
	const struct config *cfg = job->h->cfg;
	struct build_series s = {.warmup = cfg->warmup, .repeat = cfg->repeat,
	                         .threads = job->run->key.threads, .samples_ms = rep->samples,
	                         .stages = job->hb->refine,
	                         .stage_count = (uint32_t)job->hb->cb->refine_count,
	                         .stage_out = rep->stages};
	bvhlab_error err = {{0}};
	(void)size;
	rep->status = SERIES_OK;
	if (job->hb->top.plugin) { /* two-level (harness_two_level.c): status in the same order */
		rep->status = harness_two_level_run(cfg, job->hb, &job->h->inst, &job->h->anim,
		                                    cfg->scenes[job->run->scene].name,
		                                    job->scene ? &job->scene->bounds : NULL,
		                                    job->run->key.threads, rep, &err);
		goto out;
	}
	rep->has_device = harness_memory_device(job->hb->plugin, &job->hb->opts, &rep->device);
	harness_memory_begin(&rep->memory, &job->prims->input);
	int r = harness_time_builds(job->hb->plugin, &job->hb->opts, &job->prims->input, &s, &err);
	harness_memory_end(&rep->memory, &s.tree);
	if (r < 0) {
		rep->status = SERIES_FAILED;
	} else {
		rep->sample_count = s.repeat;
		rep->cold_ms = s.cold_ms;
		rep->stage_count = s.stage_count;
		rep->phase_count = s.phase_count;
		memcpy(rep->phases, s.phases, sizeof(rep->phases));
		/* The builders' scratch, kept for builds no longer coming, makes
		 * room for validation and tracing (harness_estimate.c counts on
		 * it); an animation's frames build again and keep it. */
		if (!job->h->anim.frames)
			tree_release_spare(&s.tree);
		measure(job, &s.tree, rep, &err);
		if (rep->status == SERIES_OK)
			trace_rays(job, &s.tree, rep);
		rep->in_frames = rep->status == SERIES_OK;
		int f = rep->status != SERIES_OK ? 0 : harness_frames_after_series(cfg, job->hb,
			&job->h->anim, job->scene, job->run->key.threads, rep->samples, s.repeat, &s.tree,
			&rep->frame_count, &err); /* an animated scene's frames: harness_frames.c */
		rep->status = f > 0 ? SERIES_INVALID : f < 0 ? SERIES_FAILED : rep->status;
		harness_memory_run_end(&rep->memory);
	}
out:
	if (rep->status != SERIES_OK)
		snprintf(rep->error, sizeof(rep->error), "%s", err.message);
	bvhlab_tree_finish(&s.tree);
}

/* Runs the series in a child (or here, with "isolate": false) and records it. */
static void run_series(struct harness *h, struct series_job *job, struct run_record *run,
                       struct series_report *rep, size_t size)
{
	static const char *const outcomes[] = {"ok", "crashed", "timeout"};
	char why[sizeof(rep->error)] = "", limited[sizeof(rep->error) + 64];
	int outcome = ISOLATE_REPORTED;
	struct isolate_limits limits = harness_run_limits(h->cfg, job->hb->cb);
	struct machine_cpu_mark m0, m1;
	run->load_before = machine_load_average();
	machine_cpu_mark(&m0);
	if (h->cfg->isolate)
		outcome = isolate_call(series_work, job, rep, size, &limits, why, sizeof(why));
	else
		series_work(job, rep, size);
	machine_cpu_mark(&m1);
	run->load_after = machine_load_average();
	run->load_other = machine_other_load(&m0, &m1);
	run->load_read = true;
	if (outcome == ISOLATE_REPORTED) {
		harness_report_to_run(rep, h->cfg->repeat, h->anim.frames, run);
	} else {
		/* Dead among the frames: those done stay, the one that killed it is named. */
		if (outcome > 0 && rep->in_frames) {
			harness_report_to_run(rep, h->cfg->repeat, h->anim.frames, run);
			harness_frames_death(job->hb->cb, rep->frame_count, why, sizeof(why));
		}
		run->status = outcome < 0 ? "failed" : outcomes[outcome];
		run->error = why;
	}
	/* A run that failed or died under a memory limit most likely hit it: say so. */
	if (h->cfg->isolate && limits.memory_bytes && run->error &&
	    (!strcmp(run->status, "failed") || !strcmp(run->status, "crashed"))) {
		snprintf(limited, sizeof(limited), "%s (under memory_limit_mb = %llu)", run->error,
		         (unsigned long long)(limits.memory_bytes >> 20));
		run->error = limited;
	}
	record(h, run);
}

/* An image asked for and not written counts as a run not saved would:
 * named above, in the last line and the exit status. */
static void images_lost(struct harness *h, size_t lost)
{
	h->tally.images_lost += lost;
	h->all_ok = h->all_ok && lost == 0;
}

/* Images are drawn in the children: the heat map by each builder's first
 * thread count, the shaded render by the first run to get that far. */
static void image_paths(struct harness *h, struct series_job *job, size_t scene_index,
                        size_t builder_index, bool first, char (*paths)[4096])
{
	if (!h->images)
		return;
	/* Unlinked first: a run that dies or times out leaves no data, and no
	 * older run's is drawn in its place. */
	if (first && images_temp_path(paths[0], sizeof(paths[0]), h->cfg->output, "heat",
	                               scene_index, builder_index) == 0 &&
	    (unlink(paths[0]) == 0 || errno == ENOENT))
		job->heat_path = paths[0];
	if (!h->shade_done && images_temp_path(paths[1], sizeof(paths[1]), h->cfg->output,
	                                        "shade", scene_index, 0) == 0 &&
	    (unlink(paths[1]) == 0 || errno == ENOENT))
		job->shade_path = paths[1];
}

/* A tree the child left for the rounds joins them if its run is ok. */
static void queue_tree(struct harness *h, const struct series_job *job,
                       const struct run_record *run, const struct series_report *rep)
{
	if (!job->tree_path)
		return;
	if (!rep->tree_written || strcmp(run->status, "ok") != 0 || !run->rays ||
	    harness_rounds_add(&h->rounds, job->tree_path, &job->run->key, spatial_splits(job),
	                       &rep->rays) < 0)
		unlink(job->tree_path);
}

/* The scene's triangles: the flattened scene's, or a two-level one's
 * instanced triangles (past 2^32 - 1, its "instances" entry has them). */
static uint32_t scene_triangles(const struct harness *h, const bvhlab_scene *scene)
{
	uint64_t t = scene ? scene->triangle_count : scene_instanced_triangles(&h->inst);
	return t > UINT32_MAX ? UINT32_MAX : (uint32_t)t;
}

static void run_one(struct harness *h, struct series_job *job)
{
	const struct plan_run *pr = job->run;
	bool first = pr == plan_list_first(&h->list, pr->scene, pr->builder);
	struct run_record run = run_record_of(pr, job->hb);
	char paths[2][4096], tree_path[4096];
	run.plugin = bvhlab_plugin_builder(job->hb->plugin)->name;
	const char *scene = h->cfg->scenes[pr->scene].name;
	run.status = "failed";
	run.triangles = scene_triangles(h, job->scene);
	if (skip_run(h, pr))
		return;
	struct memory_estimate est;
	char refused[640];
	run.estimate = &est;
	if ((job->hb->top.plugin
	     ? harness_estimate_two_level(h->cfg, job->hb, scene, &h->inst, &est, refused,
	                                  sizeof(refused))
	     : harness_estimate_run(h->cfg, job->hb, scene, &job->prims->input,
	                            h->anim.frames != 0, &est, refused, sizeof(refused))) < 0) {
		run.error = refused; /* nothing built: the sweep goes on */
		record(h, &run);
		return;
	}
	size_t size = sizeof(struct series_report) + h->cfg->repeat * sizeof(double) +
	              harness_frames_size(&h->anim);
	/* Shared with the run's child: what it finished survives its death. */
	struct series_report *rep = mmap(NULL, size, PROT_READ | PROT_WRITE,
	                                 MAP_SHARED | MAP_ANONYMOUS, -1, 0);
	if (rep == MAP_FAILED) {
		run.error = "out of memory for the run's samples";
		record(h, &run);
		return;
	}
	image_paths(h, job, pr->scene, pr->builder, first, paths);
	if (h->rounds_on && harness_rounds_path(tree_path, sizeof(tree_path), h->cfg->output,
	                                        pr->scene, run.id) == 0)
		job->tree_path = tree_path;
	progress_start(&h->progress, &run);
	run_series(h, job, &run, rep, size);
	images_lost(h, harness_image_lost(scene, job->hb->cb->name, job->heat_path,
	                                  rep->heat_error, h->progress.tty));
	if (job->shade_path && rep->shade_error < 0)
		h->shade_error = rep->shade_error; /* a later run may still leave it */
	queue_tree(h, job, &run, rep);
	h->shade_done = h->shade_done || (job->shade_path && rep->shade_written);
	munmap(rep, size);
}

/* The scene's runs of the list, on the loaded scene (NULL: a two-level
 * scene not flattened, its one-level runs failed with no_flat). */
static void run_list_scene(struct harness *h, const bvhlab_scene *scene,
                           const bvhlab_prims *prims, size_t s, const char *no_flat)
{
	for (size_t k = h->list.scene_first[s]; k < h->list.scene_first[s + 1]; k++) {
		const struct plan_run *run = &h->list.runs[k];
		struct harness_builder *hb = &h->builders[run->builder];
		struct series_job job = {.h = h, .scene = scene, .prims = prims, .hb = hb,
		                         .run = run};
		if (!hb->plugin || !hb->opts_ok)
			record_failed(h, run, hb->status, hb->error.message);
		else if (!scene && !hb->top.plugin)
			record_failed(h, run, "failed", no_flat);
		else
			run_one(h, &job);
	}
}

/* The scene's PNGs; a shaded render no run could leave is said once. */
static void scene_images(struct harness *h, const bvhlab_scene *scene, size_t s)
{
	char shade[4096];
	if (!h->shade_done &&
	    images_temp_path(shade, sizeof(shade), h->cfg->output, "shade", s, 0) == 0)
		images_lost(h, harness_image_lost(scene->name, NULL, shade, h->shade_error,
		                                  h->progress.tty));
	images_lost(h, harness_scene_images(&h->res, h->cfg, &h->list, scene, s, h->progress.tty));
}

/* Whether scene s has a run of a one-level builder: a two-level scene is
 * flattened for those alone. */
static bool wants_flat(const struct harness *h, size_t s)
{
	for (size_t k = h->list.scene_first[s]; k < h->list.scene_first[s + 1]; k++)
		if (!h->builders[h->list.runs[k].builder].top.plugin)
			return true;
	return false;
}

/* A two-level scene's meshes and instances, and its flattened form when a
 * one-level builder needs it; one that cannot be made fails those runs
 * alone (flat_err says why), the two-level ones run without it. */
static int load_instanced(struct harness *h, const struct config_scene *cs, size_t s,
                          bvhlab_scene **scene, bvhlab_error *flat_err, bvhlab_error *err)
{
	int r = harness_load_instanced(cs, &h->inst, err);
	if (r == 0 && wants_flat(h, s) && harness_flatten(cs, &h->inst, scene, flat_err) < 0)
		fprintf(stderr, "%s%s\n", h->progress.tty ? "\n" : "", flat_err->message);
	return r;
}

static void run_scene(struct harness *h, const struct config_scene *cs, size_t s)
{
	bvhlab_scene *scene = NULL;
	bvhlab_prims prims = {0};
	bvhlab_error err = {{0}}, flat_err = {{0}};
	if (scene_done(h, s))
		return;
	int r = h->cfg->isolate ? harness_probe_scene(h->cfg, cs, &err) : 0;
	if (r == 0) /* two-level: meshes once, flattened if need be; animated: frame 0 */
		r = cs->meshes ? load_instanced(h, cs, s, &scene, &flat_err, &err)
		               : harness_anim_load(cs, &h->anim, &scene, &err);
	if (r == 0 && cs->meshes) /* its instances move (harness_anim_inst.c) */
		harness_anim_instanced(cs, &h->inst, &h->anim);
	if (r == 0 && scene)
		r = bvhlab_prims_init(&prims, scene, &err);
	if (r < 0) {
		results_add_scene(&h->res, cs->name, cs->path ? cs->path : cs->generator, 0,
		                  err.message);
		for (size_t k = h->list.scene_first[s]; k < h->list.scene_first[s + 1]; k++)
			record_failed(h, &h->list.runs[k], "failed", err.message);
		goto out;
	}
	char *shown = cs->path ? util_path_shown(h->cfg->dir, cs->path) : NULL;
	const char *source = shown ? shown : scene ? scene->source : "two-level scene";
	results_add_scene(&h->res, cs->name, source, scene_triangles(h, scene), NULL);
	free(shown);
	harness_record_instances(&h->res, cs->name, &h->inst);
	h->shade_done = false;
	h->shade_error = 0;
	h->rounds_on = scene && harness_rounds_start(h->cfg, scene, h->progress.tty);
	run_list_scene(h, scene, &prims, s, flat_err.message);
	if (scene)
		harness_rounds_end(&h->rounds, &h->res, h->cfg, scene, &prims, h->progress.tty);
	h->rounds_on = false;
	if (h->images && scene)
		scene_images(h, scene, s);
out:
	harness_anim_close(&h->anim);
	scene_instanced_finish(&h->inst);
	bvhlab_prims_finish(&prims);
	bvhlab_scene_destroy(scene);
}

static uint32_t count_runs(const struct harness *h)
{
	uint32_t chosen = 0;
	for (size_t k = 0; k < h->list.count; k++)
		chosen += wanted(h, &h->list.runs[k]);
	return chosen;
}

/* The run list of the opened builders (a plan's must be the same), and
 * the runs --only names in it. */
static int make_list(struct harness *h, const struct harness_options *opts, bvhlab_error *err)
{
	const struct config *cfg = h->cfg;
	struct plan_builder *pb = calloc(cfg->builder_count + 1, sizeof(*pb));
	if (!pb)
		return error_set(err, "out of memory"), -ENOMEM;
	for (size_t b = 0; b < cfg->builder_count; b++)
		pb[b] = harness_plan_builder(&h->builders[b]);
	int r = plan_list_make(&h->list, cfg, pb, err);
	free(pb);
	if (r == 0 && opts->plan)
		r = plan_check_list(opts->plan, &h->list, err);
	if (r == 0 && opts->only)
		r = plan_parse_only(opts->only, h->list.count, &h->only, err);
	return r;
}

/* The folder locked and claimed, the document started (resumed). */
static int start(struct harness *h, const struct harness_options *opts, bvhlab_error *err)
{
	const struct config *cfg = h->cfg;
	int r = results_init(&h->res, cfg, cfg->output, err);
	if (r < 0)
		return r;
	/* One writer per folder, from before anything in it is read or moved. */
	r = results_lock(&h->res, err);
	if (r == 0 && !opts->resume)
		r = safe_claim_output(h->res.dir, opts->force, err);
	if (r == 0 && opts->plan)
		r = results_set_plan(&h->res, opts->plan->hash, h->list.count, err);
	if (r == 0 && opts->resume)
		r = harness_resume(&h->res, &h->list, h->progress.quiet, &h->all_ok, err);
	if (r == 0 && opts->resume)
		r = harness_forget_stale(&h->res, cfg, h->builders, opts->retry_failed,
		                         h->progress.quiet, &h->all_ok, err);
	if (r == 0)
		r = harness_note_not_applicable(&h->list, &h->res, opts->quiet, err);
	if (r == 0)
		r = results_write(&h->res, err);
	if (r == 0)
		harness_rounds_sweep(cfg->output);
	return r;
}

int harness_run(const struct config *cfg, const struct harness_options *opts,
                bvhlab_error *err)
{
	struct harness h = {.cfg = cfg, .all_ok = true};
	progress_init(&h.progress, opts->quiet);
	bvhlab_set_pinning(cfg->pin);
	h.images = harness_want_images(cfg);
	/* Every builder's plugin and options and every scene file first, before
	 * the folder is touched; the files' errors printed even after the
	 * builders' (err keeps the first). */
	int r = harness_open_sweep_builders(cfg, &h.builders, err);
	bvhlab_error files_err = {{0}};
	int f = r == -ENOMEM ? 0 : harness_check_scene_files(cfg, &files_err);
	if (r == 0 && f < 0)
		r = f, *err = files_err;
	if (r == 0)
		r = make_list(&h, opts, err);
	if (r == 0)
		r = start(&h, opts, err);
	h.progress.total = r == 0 ? count_runs(&h) : 0;
	for (size_t s = 0; r == 0 && s < cfg->scene_count; s++)
		run_scene(&h, &cfg->scenes[s], s);
	progress_finish(&h.progress);
	if (opts->tally)
		*opts->tally = h.tally;
	harness_rounds_finish(&h.rounds);
	results_finish(&h.res);
	plan_list_finish(&h.list);
	free(h.only);
	harness_close_builders(cfg, h.builders);
	return r < 0 ? r : h.all_ok ? 0 : 1;
}
