/*
 * Opening the sweep's plugins, behind a forked probe when runs are
 * isolated: README promises that nothing a plugin does outside its run's
 * child ends the sweep, and loading is something it does.
 */
#include <errno.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "harness/harness_builders.h"
#include <cJSON.h>

#include "harness/isolate.h"
#include "output/results.h"
#include "plan/plan.h"
#include "util/util.h"

/* What the probe child sends back. */
struct probe_report {
	uint32_t ok;
	char error[sizeof(((bvhlab_error *)0)->message)];
};

struct isolate_limits harness_run_limits(const struct config *cfg,
                                         const struct config_builder *cb)
{
	uint64_t mb = cb->memory_limit_mb ? cb->memory_limit_mb : cfg->memory_limit_mb;
	return (struct isolate_limits){.timeout_s = cb->timeout_s > 0 ? cb->timeout_s : cfg->timeout_s,
	                               .memory_bytes = mb << 20};
}

/* In the child: dlopen, entry point and descriptor checks; never closed,
 * since the child ends with _exit anyway. */
static void probe_work(void *arg, void *report, size_t size)
{
	const char *name = arg;
	struct probe_report *rep = report;
	bvhlab_plugin *plugin = NULL;
	bvhlab_error err = {{0}};
	(void)size;
	rep->ok = bvhlab_plugin_open(name, &plugin, &err) == 0;
	if (!rep->ok)
		snprintf(rep->error, sizeof(rep->error), "%s", err.message);
}

int harness_probe_plugin(const char *plugin, double timeout_s, const char **status,
                         bvhlab_error *err)
{
	struct probe_report rep = {0};
	char why[sizeof(rep.error)] = "";
	/* The timeout only: the limit is on the builds, and a child's address
	 * space starts at the parent's (its libraries), which can exceed it. */
	struct isolate_limits limits = {.timeout_s = timeout_s};
	int outcome = isolate_call(probe_work, (void *)plugin, &rep, sizeof(rep), &limits, why,
	                           sizeof(why));
	*status = "failed";
	if (outcome == ISOLATE_REPORTED && rep.ok)
		return 0;
	rep.error[sizeof(rep.error) - 1] = '\0';
	if (outcome == ISOLATE_REPORTED) { /* not there, or not a bvhlab plugin */
		error_set(err, "%s", rep.error);
		return -EINVAL;
	}
	*status = outcome == ISOLATE_TIMEOUT ? "timeout" : outcome < 0 ? "failed" : "crashed";
	error_set(err, "plugin %s: %s while loading (library constructor or entry point): %s",
	          plugin, outcome == ISOLATE_TIMEOUT ? "hung" : "died", why);
	return -ECHILD;
}

/* 0 when the builder's plugin and every refine stage's loaded in a child
 * each; else the builder's status and error, naming the stage. One that is
 * not there or not a plugin is a config error; one that died or hung is not
 * (its runs record it). */
static int probe(const struct config *cfg, struct harness_builder *hb)
{
	double timeout_s = harness_run_limits(cfg, hb->cb).timeout_s;
	int r = harness_probe_plugin(hb->cb->plugin, timeout_s, &hb->status, &hb->error);
	for (size_t k = 0; r == 0 && k < hb->cb->refine_count; k++) {
		bvhlab_error err = {{0}};
		r = harness_probe_plugin(hb->cb->refine[k].plugin, timeout_s, &hb->status, &err);
		if (r < 0) {
			hb->stage_failed = true;
			error_set(&hb->error, "refine stage %zu: %s", k + 1, err.message);
		}
	}
	hb->bad_config = r == -EINVAL;
	return r < 0 ? -EINVAL : 0;
}

/* Opens a builder's refinement stages; *ok false (hb->error set) when one
 * cannot be used. -ENOMEM only for options that cannot be set up. */
static int open_stages(const struct config *cfg, struct harness_builder *hb, bool *ok)
{
	*ok = true;
	for (size_t k = 0; *ok && k < hb->cb->refine_count; k++) {
		struct harness_stage *st = &hb->stages[k];
		*ok = bvhlab_plugin_open(hb->cb->refine[k].plugin, &st->plugin, &hb->error) == 0;
		if (*ok && !bvhlab_builder_refine(bvhlab_plugin_builder(st->plugin))) {
			error_set(&hb->error, "refine stage %zu: plugin '%s' has no refinement stage",
			          k + 1, hb->cb->refine[k].plugin);
			*ok = false;
		}
		if (*ok && bvhlab_options_init(&st->opts, bvhlab_plugin_builder(st->plugin)) < 0)
			return -ENOMEM;
		if (*ok)
			*ok = config_apply_refine_options(cfg, hb->cb, k, &st->opts, &hb->error) == 0;
		if (!*ok)
			config_locate_builder_error(cfg, hb->cb, k, &hb->error);
		else
			hb->refine[k] = (struct refine_stage){.plugin = st->plugin, .opts = &st->opts};
	}
	return 0;
}

/* One plugin of the builder's animation, probed (when `probed`) and opened
 * into st with its defaults; *ok false (hb->error naming it) when it is not
 * there or not a plugin. -ENOMEM only for options that cannot be set up. */
static int open_anim_plugin(const struct config *cfg, bool probed, struct harness_builder *hb,
                            const char *plugin, const char *what, struct harness_stage *st,
                            bool *ok)
{
	const char *status;
	bvhlab_error err = {{0}};
	double timeout_s = harness_run_limits(cfg, hb->cb).timeout_s;
	*ok = !probed || harness_probe_plugin(plugin, timeout_s, &status, &err) == 0;
	if (*ok)
		*ok = bvhlab_plugin_open(plugin, &st->plugin, &err) == 0;
	if (!*ok) {
		error_set(&hb->error, "%s: %s", what, err.message);
		return 0;
	}
	return bvhlab_options_init(&st->opts, bvhlab_plugin_builder(st->plugin)) < 0 ? -ENOMEM : 0;
}

/*
 * The builder's "animation" checked as its own stages are, before any run:
 * the update plugin there and with an update function, each stage there,
 * refining, and its options known and valid. Without this each run would
 * fail after frame 0 was built and timed. The runs' children open them
 * again (harness_frames.c); these stay open for the options' hash.
 */
static int open_animation(const struct config *cfg, bool probed, struct harness_builder *hb,
                          bool *ok)
{
	const struct config_animation *a = hb->cb->animation;
	char what[48];
	*ok = true;
	if (!a)
		return 0;
	int r = open_anim_plugin(cfg, probed, hb, a->update, "animation update", &hb->update, ok);
	if (r == 0 && *ok && !bvhlab_builder_update(bvhlab_plugin_builder(hb->update.plugin))) {
		error_set(&hb->error, "animation update: plugin '%s' has no update function (ABI "
		          "1.4)", a->update);
		*ok = false;
	}
	if (r == 0 && *ok && bvhlab_options_check(&hb->update.opts, &hb->error) < 0) {
		error_prefix(&hb->error, "animation update");
		*ok = false;
	}
	for (size_t k = 0; r == 0 && *ok && k < a->refine_count; k++) {
		struct harness_stage *st = &hb->anim_stages[k];
		snprintf(what, sizeof(what), "animation refine stage %zu", k + 1);
		r = open_anim_plugin(cfg, probed, hb, a->refine[k].plugin, what, st, ok);
		if (r == 0 && *ok && !bvhlab_builder_refine(bvhlab_plugin_builder(st->plugin))) {
			error_set(&hb->error, "%s: plugin '%s' has no refinement stage", what,
			          a->refine[k].plugin);
			*ok = false;
		}
		if (r == 0 && *ok)
			*ok = config_apply_anim_refine_options(cfg, hb->cb, k, &st->opts, &hb->error) == 0;
	}
	if (r == 0 && !*ok)
		config_locate_builder_error(cfg, hb->cb, SIZE_MAX, &hb->error);
	return r;
}

/* A two-level builder's top plugin: there, and able to build over boxes
 * (BVHLAB_BUILDER_BOXES), refused by name before the sweep otherwise. */
static int open_top(const struct config *cfg, bool probed, struct harness_builder *hb,
                    bool *ok)
{
	*ok = true;
	if (!hb->cb->top)
		return 0;
	int r = open_anim_plugin(cfg, probed, hb, hb->cb->top, "top", &hb->top, ok);
	if (r == 0 && *ok && !bvhlab_builder_takes_boxes(bvhlab_plugin_builder(hb->top.plugin))) {
		error_set(&hb->error, "top: plugin '%s' cannot build over boxes (no "
		          "BVHLAB_BUILDER_BOXES flag; `bvhlab list` marks those that can)",
		          hb->cb->top);
		*ok = false;
	}
	if (r == 0 && *ok) { /* "top_options" checked as "options" are, against the top's */
		struct config_builder as_top = *hb->cb;
		as_top.options = hb->cb->top_options;
		as_top.pick_count = 0;
		*ok = config_apply_options(cfg, &as_top, &hb->top.opts, &hb->error) == 0;
	}
	if (r == 0 && !*ok)
		config_locate_builder_error(cfg, hb->cb, SIZE_MAX, &hb->error);
	return r;
}

/*
 * The hash of what a builder's runs are made with beyond its name: its
 * plugin and resolved options, each stage's plugin and options. Part of a
 * run's identity: --resume runs again what was made with other options,
 * and merge refuses parts that disagree.
 */
static int hash_options(struct harness_builder *hb)
{
	struct strbuf sb = {0};
	for (size_t k = 0; k <= hb->cb->refine_count; k++) {
		const bvhlab_options *opts = k ? &hb->stages[k - 1].opts : &hb->opts;
		const char *plugin = k ? hb->cb->refine[k - 1].plugin : hb->cb->plugin;
		cJSON *o = results_options_json(opts);
		char *text = o ? cJSON_PrintUnformatted(o) : NULL;
		cJSON_Delete(o);
		if (text)
			sb_printf(&sb, "%s%s %s", k ? " | " : "", plugin, text);
		free(text);
		if (!text)
			return free(sb_take(&sb)), -ENOMEM;
	}
	char *all = sb_take(&sb);
	if (!all)
		return -ENOMEM;
	plan_hash_text(all, hb->options_hash);
	free(all);
	return 0;
}

/* {"plugin": descriptor name, "options": {...}} of an opened plugin. */
static cJSON *plugin_json(const bvhlab_plugin *plugin, const bvhlab_options *opts)
{
	cJSON *o = cJSON_CreateObject();
	cJSON_AddStringToObject(o, "plugin", bvhlab_plugin_builder(plugin)->name);
	cJSON_AddItemToObject(o, "options", results_options_json(opts));
	return o;
}

static cJSON *stages_json(const struct harness_stage *stages, size_t count)
{
	cJSON *a = cJSON_CreateArray();
	for (size_t k = 0; a && k < count; k++)
		cJSON_AddItemToArray(a, plugin_json(stages[k].plugin, &stages[k].opts));
	return a;
}

/*
 * The builder as its runs are made, for their identity (plan_identity.c)
 * and their record's "config": plugins by their descriptors' names (a
 * plan's absolute path is the same plugin), options resolved (defaults
 * filled in, a grid's value picked), refine stages and the animation.
 */
static int builder_identity(struct harness_builder *hb)
{
	const struct config_animation *a = hb->cb->animation;
	cJSON *o = plugin_json(hb->plugin, &hb->opts);
	cJSON_AddItemToObject(o, "refine", stages_json(hb->stages, hb->cb->refine_count));
	if (a) {
		cJSON *anim = plugin_json(hb->update.plugin, &hb->update.opts);
		cJSON_AddNumberToObject(anim, "rebuild_every", a->rebuild_every);
		cJSON_AddItemToObject(anim, "refine", stages_json(hb->anim_stages, a->refine_count));
		cJSON_AddItemToObject(o, "animation", anim);
	}
	if (hb->top.plugin)
		cJSON_AddItemToObject(o, "top", plugin_json(hb->top.plugin, &hb->top.opts));
	char *text = o ? cJSON_PrintUnformatted(o) : NULL;
	if (!text)
		return cJSON_Delete(o), -ENOMEM;
	plan_hash_text(text, hb->builder_hash);
	free(text);
	hb->identity = o;
	return 0;
}

/* 0, -EINVAL with hb's error set, or -ENOMEM. */
static int open_one(const struct config *cfg, bool probed, struct harness_builder *hb)
{
	hb->status = "failed";
	int r = probed ? probe(cfg, hb) : 0;
	if (r == 0 && bvhlab_plugin_open(hb->cb->plugin, &hb->plugin, &hb->error) < 0)
		r = -EINVAL, hb->bad_config = true;
	if (r < 0) {
		config_locate_builder_error(cfg, hb->cb, SIZE_MAX, &hb->error);
		return r;
	}
	if (bvhlab_options_init(&hb->opts, bvhlab_plugin_builder(hb->plugin)) < 0)
		return -ENOMEM;
	hb->opts_ok = config_apply_options(cfg, hb->cb, &hb->opts, &hb->error) == 0;
	if (hb->opts_ok && open_stages(cfg, hb, &hb->opts_ok) < 0)
		return -ENOMEM;
	if (hb->opts_ok && open_animation(cfg, probed, hb, &hb->opts_ok) < 0)
		return -ENOMEM;
	if (hb->opts_ok && open_top(cfg, probed, hb, &hb->opts_ok) < 0)
		return -ENOMEM;
	if (hb->opts_ok && (hash_options(hb) < 0 || builder_identity(hb) < 0))
		return -ENOMEM;
	hb->bad_config = !hb->opts_ok;
	return hb->opts_ok ? 0 : -EINVAL;
}

/* FILE:LINE:COLUMN: of a message, or its whole length when it has none. */
static size_t position_length(const char *message)
{
	const char *p = message;
	for (int colons = 0; *p && colons < 3; p++)
		colons += *p == ':';
	return (size_t)(p - message);
}

/* True when an earlier builder's message came from the same place: the
 * builders of one grid share their plugin and most options. */
static bool said_before(const struct harness_builder *builders, size_t b)
{
	const char *m = builders[b].error.message;
	size_t n = position_length(m);
	for (size_t k = 0; k < b; k++)
		if ((builders[k].bad_config || builders[k].skipped) &&
		    strncmp(builders[k].error.message, m, n) == 0 &&
		    position_length(builders[k].error.message) == n)
			return true;
	return false;
}

int harness_open_builders(const struct config *cfg, bool probed,
                          struct harness_builder **out, size_t *bad_configs)
{
	*bad_configs = 0;
	struct harness_builder *builders = calloc(cfg->builder_count ? cfg->builder_count : 1,
	                                          sizeof(*builders));
	*out = builders;
	if (!builders)
		return -ENOMEM;
	for (size_t b = 0; b < cfg->builder_count; b++) {
		struct harness_builder *hb = &builders[b];
		hb->cb = &cfg->builders[b];
		int r = open_one(cfg, probed, hb);
		if (r == -ENOMEM)
			return r;
		hb->skipped = r < 0 && !hb->plugin && !hb->stage_failed && hb->cb->optional;
		hb->bad_config = hb->bad_config && !hb->skipped;
		*bad_configs += hb->bad_config;
		if (r == 0 || said_before(builders, b))
			continue;
		if (hb->skipped)
			fprintf(stderr, "bvhlab: optional builder skipped: %s\n", hb->error.message);
		else
			fprintf(stderr, "bvhlab: %s\n", hb->error.message);
	}
	return 0;
}

static void close_stage(struct harness_stage *st)
{
	if (st->opts.values)
		bvhlab_options_finish(&st->opts);
	bvhlab_plugin_close(st->plugin);
}

void harness_close_builders(const struct config *cfg, struct harness_builder *builders)
{
	for (size_t b = 0; builders && b < cfg->builder_count; b++) {
		if (builders[b].opts.values)
			bvhlab_options_finish(&builders[b].opts);
		bvhlab_plugin_close(builders[b].plugin);
		for (size_t k = 0; k < HARNESS_MAX_STAGES; k++) {
			close_stage(&builders[b].stages[k]);
			close_stage(&builders[b].anim_stages[k]);
		}
		close_stage(&builders[b].update);
		close_stage(&builders[b].top);
		cJSON_Delete(builders[b].identity);
	}
	free(builders);
}

int harness_open_sweep_builders(const struct config *cfg, struct harness_builder **out,
                                bvhlab_error *err)
{
	size_t bad = 0;
	int r = harness_open_builders(cfg, cfg->isolate, out, &bad);
	if (r < 0)
		error_set(err, "out of memory opening plugins");
	else if (bad)
		r = -EINVAL, error_set(err, "%s: %zu builder%s cannot run as configured (above); "
		                       "nothing was run", cfg->path, bad, bad == 1 ? "" : "s");
	return r;
}
