/*
 * A run's identity, the one key results, --resume, ray and image updates,
 * plan.json and merge find a run by (results.h, struct run_identity):
 * written into a record by run_identity_add, read back by
 * run_identity_read and compared by run_identity_compare, so no file
 * compares scene, builder and thread count its own way.
 */
#include <stdio.h>
#include <string.h>

#include <cJSON.h>

#include "output/results.h"

static const char *string_at(const cJSON *o, const char *key)
{
	const cJSON *v = cJSON_GetObjectItemCaseSensitive(o, key);
	return cJSON_IsString(v) ? v->valuestring : NULL;
}

/* A whole count from 0 to CONFIG_MAX_THREADS, or `none`. */
static uint32_t count_at(const cJSON *o, const char *key, uint32_t none)
{
	const cJSON *v = cJSON_GetObjectItemCaseSensitive(o, key);
	if (!cJSON_IsNumber(v) || v->valuedouble < 0 || v->valuedouble > CONFIG_MAX_THREADS ||
	    v->valuedouble != (double)(uint32_t)v->valuedouble)
		return none;
	return (uint32_t)v->valuedouble;
}

static cJSON *fragment(const struct run_identity *key)
{
	cJSON *c = cJSON_CreateObject();
	const cJSON *parts[] = {key->scene_config, key->builder_config, key->measure_config};
	static const char *const names[] = {"scene", "builder", "measure"};
	for (size_t k = 0; c && k < 3; k++)
		if (parts[k])
			cJSON_AddItemToObject(c, names[k], cJSON_Duplicate(parts[k], 1));
	return c;
}

int run_identity_add(cJSON *o, const struct run_identity *key)
{
	if (key->threads_configured != RUN_THREADS_UNKNOWN &&
	    !cJSON_AddNumberToObject(o, "threads_configured", key->threads_configured))
		return -1;
	if (!key->hash)
		return 0;
	cJSON *id = cJSON_AddObjectToObject(o, "identity");
	if (!id || !cJSON_AddStringToObject(id, "hash", key->hash) ||
	    !cJSON_AddStringToObject(id, "scene", key->scene_hash) ||
	    !cJSON_AddStringToObject(id, "builder", key->builder_hash) ||
	    !cJSON_AddStringToObject(id, "measure", key->measure_hash))
		return -1;
	cJSON *c = key->scene_config || key->builder_config || key->measure_config ? fragment(key)
	                                                                           : NULL;
	if (c)
		cJSON_AddItemToObject(o, "config", c);
	return 0;
}

void run_identity_read(const cJSON *run, struct run_identity *out)
{
	const cJSON *id = cJSON_GetObjectItemCaseSensitive(run, "identity");
	const cJSON *n = cJSON_GetObjectItemCaseSensitive(run, "id");
	*out = (struct run_identity){
		.id = cJSON_IsNumber(n) && n->valuedouble >= 0 ? (uint32_t)n->valuedouble : 0,
		.scene = string_at(run, "scene"), .builder = string_at(run, "builder"),
		.threads = count_at(run, "threads", 0),
		.threads_configured = count_at(run, "threads_configured", RUN_THREADS_UNKNOWN),
		.options_hash = string_at(run, "options_hash"), .hash = string_at(id, "hash"),
		.scene_hash = string_at(id, "scene"), .builder_hash = string_at(id, "builder"),
		.measure_hash = string_at(id, "measure")};
}

static bool same(const char *a, const char *b)
{
	return a && b && strcmp(a, b) == 0;
}

/* One run of a config: its scene and builder, and its thread count, the
 * resolved one where both sides know it (a plan knows only the configured). */
static bool same_slot(const struct run_identity *a, const struct run_identity *b)
{
	if (!same(a->scene, b->scene) || !same(a->builder, b->builder))
		return false;
	if (a->threads && b->threads)
		return a->threads == b->threads;
	return a->threads_configured != RUN_THREADS_UNKNOWN &&
	       a->threads_configured == b->threads_configured;
}

enum run_match run_identity_compare(const struct run_identity *want,
                                    const struct run_identity *have, const char **changed)
{
	const char *what = NULL;
	if (!same_slot(want, have))
		return RUN_OTHER;
	if (!want->hash || same(want->hash, have->hash))
		return RUN_SAME;
	if (!have->hash)
		what = "record";
	else if (!same(want->scene_hash, have->scene_hash))
		what = "scene";
	else if (!same(want->builder_hash, have->builder_hash))
		what = "builder";
	else
		what = "measure";
	if (changed)
		*changed = what;
	return RUN_CHANGED;
}
