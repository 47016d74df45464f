/*
 * A config scene made real: loaded from its file or generated (a composite:
 * each part loaded, placed and merged), subdivided and named; `bvhlab build`/`render` and the sweep share it.
 * Before a sweep, every file its scenes name is tried (harness_check_scene_files).
 */
#include <errno.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "harness/harness_instances.h"
#include "harness/harness_scene.h"
#include "harness/isolate.h"
#include "plan/plan.h"
#include "scene/scene_check.h"
#include "util/util.h"

/* Prefixes err's message with the part it came from. */
static void part_error(bvhlab_error *err, const char *scene, size_t part)
{
	char msg[sizeof(err->message)];
	if (!err)
		return;
	snprintf(msg, sizeof(msg), "%s", err->message);
	error_set(err, "scene '%s' part %zu: %s", scene, part, msg);
}

/* Loads, places and merges a composite scene's parts. */
static int load_parts(const struct config_scene *cs, bvhlab_scene **out, bvhlab_error *err)
{
	bvhlab_scene **parts = calloc(cs->part_count, sizeof(*parts));
	const char *name = cs->name ? cs->name : "composite";
	int r = parts ? 0 : -ENOMEM;
	for (size_t i = 0; r == 0 && i < cs->part_count; i++) {
		r = harness_load_scene(&cs->parts[i].src, &parts[i], err);
		if (r < 0)
			part_error(err, name, i);
		else
			bvhlab_scene_transform(parts[i], &cs->parts[i].xf);
	}
	if (r == 0)
		r = bvhlab_scene_merge(parts, (uint32_t)cs->part_count, name, out, err);
	for (size_t i = 0; parts && i < cs->part_count; i++)
		bvhlab_scene_destroy(parts[i]);
	free(parts);
	return r;
}

int harness_load_scene(const struct config_scene *cs, bvhlab_scene **out, bvhlab_error *err)
{
	int r = cs->meshes ? harness_load_flattened(cs, out, err)
	        : cs->parts  ? load_parts(cs, out, err)
	        : cs->path ? bvhlab_scene_load(cs->path, out, err)
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

/* What the probe loads: with a memory limit, the scene and its primitives
 * as the sweep will make them (the subdivided arrays are what must fit
 * it); without one, the files alone (parsing them is what can crash or
 * hang; subdividing and the primitives are the host's own arithmetic,
 * which the parent does anyway, and at 68.8M triangles they take
 * minutes). */
struct probe_job {
	const struct config_scene *cs;
	bool whole;
};

/* In the child: the scene as the job says. */
static void probe_work(void *arg, void *report, size_t size)
{
	const struct probe_job *job = arg;
	struct scene_probe *rep = report;
	struct config_scene files = *job->cs;
	bvhlab_scene *scene = NULL;
	bvhlab_prims prims = {0};
	bvhlab_error err = {{0}};
	struct scene_instanced inst = {0};
	(void)size;
	/* A two-level scene's meshes and instances; the parent flattens it,
	 * checked against the memory available, only where a run needs it. */
	files.subdivide = job->whole ? files.subdivide : 0;
	int r = files.meshes ? harness_load_instanced(&files, &inst, &err)
	                     : harness_load_scene(&files, &scene, &err);
	if (r == 0 && scene && job->whole)
		r = bvhlab_prims_init(&prims, scene, &err);
	scene_instanced_finish(&inst);
	rep->ok = r == 0;
	snprintf(rep->error, sizeof(rep->error), "%s", err.message);
}

/* The largest memory limit any builder of the scene runs under; 0 when
 * one has none. */
static uint64_t largest_limit_mb(const struct config *cfg, const struct config_scene *cs)
{
	uint64_t most = 0;
	for (size_t b = 0; b < cfg->builder_count; b++) {
		if (!config_builder_runs_on(&cfg->builders[b], cs))
			continue;
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
	uint64_t mb = largest_limit_mb(cfg, cs);
	struct isolate_limits limits = {.timeout_s = cfg->timeout_s, .memory_bytes = mb << 20};
	struct probe_job job = {.cs = cs, .whole = mb != 0};
	int outcome = isolate_call(probe_work, &job, &rep, sizeof(rep), &limits, why,
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

/* ---- the files, before the sweep --------------------------------------- */

struct file_check {
	const struct config *cfg;
	const struct config_scene *cs;
	size_t bad;
};

/* One file of the scene, tried; a failure printed as a config error, `what`
 * naming the part or frame it is ("" for the scene's own). Counts bad ones
 * and goes on, so that every bad file is named. */
static int check_one(const char *path, const char *what, size_t k, void *ctx)
{
	struct file_check *c = ctx;
	bvhlab_error err = {{0}};
	(void)k;
	if (scene_check_file(path, &err) == 0)
		return 0;
	fprintf(stderr, "bvhlab: %s:%d:%d: scene '%s': %s%s\n", c->cfg->path, c->cs->line,
	        c->cs->column, c->cs->name, what, err.message);
	c->bad++;
	return 0;
}

int harness_check_scene_files(const struct config *cfg, bvhlab_error *err)
{
	struct file_check c = {.cfg = cfg};
	size_t k = 0;
	for (size_t s = 0; s < cfg->scene_count; s++) {
		c.cs = &cfg->scenes[s];
		plan_scene_each_file(c.cs, check_one, &k, &c);
	}
	if (!c.bad)
		return 0;
	error_set(err, "%s: %zu scene file%s cannot be read (above); nothing was run", cfg->path,
	          c.bad, c.bad == 1 ? "" : "s");
	return -EINVAL;
}
