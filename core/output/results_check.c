/*
 * What --resume accepts from an earlier results.json. Its runs are taken
 * over as they are and the sweep skips every run of its list they cover, so
 * a run that is duplicated, belongs to no run of the list, or has
 * fields of the wrong type or range would be kept forever and shown in
 * every report. Such a file is refused with the run named; the harness
 * has written nothing yet, so the file stays as it was. A run made another
 * way than its run of the list now (its identity changed) is kept until
 * its new record replaces it (results_forget_changed).
 */
#include <errno.h>
#include <math.h>
#include <stdbool.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include <cJSON.h>

#include "output/results.h"
#include "util/util.h"

/* The sweep's runs, each to be claimed by one kept run at most. */
struct claims {
	const struct run_identity *keys;
	size_t count;
	unsigned char *seen; /* [count] */
};

/* The run of the list in the slot of this record, or -1. */
static long find_key(const struct run_identity *keys, size_t count, const cJSON *run)
{
	struct run_identity have;
	run_identity_read(run, &have);
	for (size_t k = 0; k < count; k++)
		if (run_identity_compare(&keys[k], &have, NULL) != RUN_OTHER)
			return (long)k;
	return -1;
}

static const char *string_of(const cJSON *run, const char *key)
{
	const cJSON *v = cJSON_GetObjectItemCaseSensitive(run, key);
	return cJSON_IsString(v) ? v->valuestring : NULL;
}

/* A run of a scene and a builder the sweep has, in a slot it no longer
 * makes: the config's threads changed, the builder's plugin could not be
 * probed then (every thread count) and is serial now, or its "scenes" no
 * longer names the scene. */
static bool slot_gone(const struct run_identity *keys, size_t count, const cJSON *run)
{
	const char *scene = string_of(run, "scene"), *builder = string_of(run, "builder");
	bool scene_known = false, builder_known = false;
	for (size_t k = 0; scene && builder && k < count; k++) {
		scene_known = scene_known || !strcmp(keys[k].scene, scene);
		builder_known = builder_known || !strcmp(keys[k].builder, builder);
	}
	return scene_known && builder_known;
}

static bool is_count(const cJSON *v, double max)
{
	return cJSON_IsNumber(v) && isfinite(v->valuedouble) && v->valuedouble >= 1 &&
	       v->valuedouble <= max && v->valuedouble == floor(v->valuedouble);
}

static bool known_status(const char *s)
{
	static const char *const known[] = {"ok", "invalid", "failed", "crashed", "timeout"};
	for (size_t k = 0; s && k < sizeof(known) / sizeof(known[0]); k++)
		if (strcmp(s, known[k]) == 0)
			return true;
	return false;
}

static bool finite_at(const cJSON *o, const char *key)
{
	const cJSON *v = cJSON_GetObjectItemCaseSensitive(o, key);
	return cJSON_IsNumber(v) && isfinite(v->valuedouble) && v->valuedouble >= 0;
}

/* "build_ms": median, min, max and every sample finite and >= 0. */
static bool timing_ok(const cJSON *t)
{
	const cJSON *samples = cJSON_GetObjectItemCaseSensitive(t, "samples"), *s;
	if (!cJSON_IsObject(t) || !finite_at(t, "median") || !finite_at(t, "min") ||
	    !finite_at(t, "max") || !cJSON_IsArray(samples))
		return false;
	cJSON_ArrayForEach(s, samples)
		if (!cJSON_IsNumber(s) || !isfinite(s->valuedouble) || s->valuedouble < 0)
			return false;
	return true;
}

/* "build_phases": an object of finite times >= 0. */
static bool phases_ok(const cJSON *p)
{
	const cJSON *v;
	if (!cJSON_IsObject(p))
		return false;
	cJSON_ArrayForEach(v, p)
		if (!cJSON_IsNumber(v) || !isfinite(v->valuedouble) || v->valuedouble < 0)
			return false;
	return true;
}

/* The optional members the reports read, each of its type: "" or what is wrong. */
static const char *optional_fields(const cJSON *run)
{
	static const char *const strings[] = {"plugin", "error", "heat_image"};
	static const char *const objects[] = {"options", "tree", "validation", "rays"};
	for (size_t k = 0; k < sizeof(strings) / sizeof(strings[0]); k++) {
		const cJSON *v = cJSON_GetObjectItemCaseSensitive(run, strings[k]);
		if (v && !cJSON_IsString(v))
			return strings[k];
	}
	for (size_t k = 0; k < sizeof(objects) / sizeof(objects[0]); k++) {
		const cJSON *v = cJSON_GetObjectItemCaseSensitive(run, objects[k]);
		if (v && !cJSON_IsObject(v))
			return objects[k];
	}
	const cJSON *t = cJSON_GetObjectItemCaseSensitive(run, "build_ms");
	if (t && !timing_ok(t))
		return "build_ms";
	const cJSON *p = cJSON_GetObjectItemCaseSensitive(run, "build_phases");
	if (p && !phases_ok(p))
		return "build_phases";
	if (cJSON_GetObjectItemCaseSensitive(run, "mtris_per_s") && !finite_at(run, "mtris_per_s"))
		return "mtris_per_s";
	return "";
}

/* NULL when run is acceptable and new; else what is wrong with it. */
static const char *check_run(struct claims *c, const cJSON *run, char *why, size_t size)
{
	const char *scene = string_of(run, "scene"), *builder = string_of(run, "builder");
	const cJSON *t = cJSON_GetObjectItemCaseSensitive(run, "threads");
	if (!cJSON_IsObject(run) || !scene || !builder || !string_of(run, "status"))
		return "lacks a string scene, builder or status";
	if (!is_count(t, CONFIG_MAX_THREADS))
		return "\"threads\" is not a whole number from 1 to the limit of 1024";
	if (!known_status(string_of(run, "status")))
		return "\"status\" is none of ok, invalid, failed, crashed, timeout";
	long k = find_key(c->keys, c->count, run);
	if (k < 0 && !slot_gone(c->keys, c->count, run))
		return "is not a run of this config (scene or builder unknown)";
	const char *field = optional_fields(run);
	if (*field) {
		snprintf(why, size, "\"%s\" has the wrong type or a value out of range", field);
		return why;
	}
	if (k >= 0 && c->seen[k])
		return "repeats an earlier run of the same scene, builder and thread count";
	if (k >= 0)
		c->seen[k] = 1;
	return NULL;
}

int results_check_runs(const cJSON *runs, const struct run_identity *keys, size_t key_count,
                       const char *path, bvhlab_error *err)
{
	struct claims c = {.keys = keys, .count = key_count, .seen = calloc(key_count + 1, 1)};
	char why[128];
	int k = 0, r = 0;
	const cJSON *run;
	if (!cJSON_IsArray(runs)) {
		error_set(err, "cannot resume from %s: no \"runs\" array (not a bvhlab results file?)",
		          path);
		return -EINVAL;
	}
	if (!c.seen) {
		error_set(err, "cannot resume from %s: out of memory", path);
		return -ENOMEM;
	}
	cJSON_ArrayForEach(run, runs) {
		const char *bad = check_run(&c, run, why, sizeof(why));
		if (bad) {
			const char *s = string_of(run, "scene"), *b = string_of(run, "builder");
			error_set(err, "cannot resume from %s: runs[%d] (scene '%s', builder '%s') %s; "
			          "the file is left as it is", path, k, s ? s : "?", b ? b : "?", bad);
			r = -EINVAL;
			break;
		}
		k++;
	}
	free(c.seen);
	return r;
}

size_t results_forget_changed(struct results *res, const struct run_identity *keys,
                              size_t count,
                              void (*changed)(void *ctx, const struct run_identity *key,
                                              const char *what),
                              void *ctx)
{
	size_t n = 0;
	cJSON *run;
	cJSON_ArrayForEach(run, res->runs) {
		struct run_identity have;
		const char *what = NULL;
		long k = results_is_stale(res, run) ? -1 : find_key(keys, count, run);
		if (k < 0)
			continue;
		cJSON *id = cJSON_GetObjectItemCaseSensitive(run, "id");
		if (cJSON_IsNumber(id))
			cJSON_SetNumberValue(id, keys[k].id);
		else
			cJSON_AddNumberToObject(run, "id", keys[k].id);
		run_identity_read(run, &have);
		if (run_identity_compare(&keys[k], &have, &what) != RUN_CHANGED ||
		    !results_mark_stale(res, run))
			continue;
		n++;
		if (changed)
			changed(ctx, &keys[k], what);
	}
	return n;
}

size_t results_drop_gone(struct results *res, const struct run_identity *keys, size_t count)
{
	size_t n = 0;
	cJSON *run = res->runs ? res->runs->child : NULL;
	while (run) {
		cJSON *next = run->next;
		if (find_key(keys, count, run) < 0) {
			cJSON_Delete(cJSON_DetachItemViaPointer(res->runs, run));
			n++;
		}
		run = next;
	}
	return n;
}
