/*
 * What shapes a run's figures, hashed once per scene, builder and
 * measurement (docs/design.md, "Run identity"): the run list gives every
 * run these hashes and the config fragments they come from, so --resume
 * makes again a run whose scene, builder or measurement changed, and a
 * plan's parts are checked against the plan's.
 */
#include <errno.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include <cJSON.h>

#include "plan/plan.h"
#include "util/util.h"

/* "path" and "pattern" name where a file is, not what it holds (the
 * fingerprints do): a plan's absolute paths are the same scene. */
static void strip_paths(cJSON *scene)
{
	cJSON *part;
	cJSON_DeleteItemFromObjectCaseSensitive(scene, "path");
	cJSON_ArrayForEach(part, cJSON_GetObjectItemCaseSensitive(scene, "parts"))
		cJSON_DeleteItemFromObjectCaseSensitive(part, "path");
	cJSON_ArrayForEach(part, cJSON_GetObjectItemCaseSensitive(scene, "meshes"))
		cJSON_DeleteItemFromObjectCaseSensitive(part, "path");
	cJSON_DeleteItemFromObjectCaseSensitive(cJSON_GetObjectItemCaseSensitive(scene, "frames"),
	                                        "pattern");
}

static int add_fingerprint(const char *path, const char *what, size_t k, void *ctx)
{
	struct plan_fingerprint fp;
	(void)what;
	(void)k;
	if (plan_fingerprint(path, &fp) == 0)
		sb_printf(ctx, " %.0f:%s", fp.size, fp.hash);
	else /* not readable here: which one it was is all that is known */
		sb_printf(ctx, " missing:%s", path);
	return 0;
}

/* The scene's description without paths, and every file's size and hash. */
static int scene_hash(const struct config *cfg, size_t s, char out[17])
{
	struct strbuf sb = {0};
	size_t k = 0;
	cJSON *copy = cJSON_Duplicate(cJSON_GetArrayItem(cJSON_GetObjectItemCaseSensitive(
	                                                   cfg->root, "scenes"), (int)s), 1);
	if (copy)
		strip_paths(copy);
	char *text = copy ? cJSON_PrintUnformatted(copy) : NULL;
	cJSON_Delete(copy);
	if (!text)
		return -ENOMEM;
	sb_printf(&sb, "%s", text);
	free(text);
	plan_scene_each_file(&cfg->scenes[s], add_fingerprint, &k, &sb);
	char *all = sb_take(&sb);
	if (!all)
		return -ENOMEM;
	plan_hash_text(all, out);
	free(all);
	return 0;
}

/* The kinds, light and AO length only when not the default, so configs
 * from before rays.kinds keep their identity. */
static void add_kinds(cJSON *r, const struct config *cfg)
{
	if (cfg->ray_kinds == RAY_KINDS_DEFAULT)
		return;
	cJSON *kinds = cJSON_AddArrayToObject(r, "kinds");
	for (int k = 0; k < RAY_KINDS; k++)
		if (cfg->ray_kinds & (1u << k))
			cJSON_AddItemToArray(kinds, cJSON_CreateString(ray_kind_name(k)));
	if ((cfg->ray_kinds & (1u << RAY_SHADOW)) && cfg->has_light)
		cJSON_AddItemToObject(r, "light", cJSON_CreateFloatArray(cfg->ray_light, 3));
	if (cfg->ray_kinds & (1u << RAY_AO))
		cJSON_AddNumberToObject(r, "ao_length", cfg->ray_ao_length);
}

static cJSON *rays_json(const struct config *cfg)
{
	cJSON *r = cJSON_CreateObject(), *names = cJSON_AddArrayToObject(r, "traversals");
	const struct results_number settings[] = {
		{"width", cfg->ray_width},     {"height", cfg->ray_height},
		{"diffuse", cfg->ray_diffuse}, {"threads", cfg->ray_threads},
		{"min_ms", cfg->ray_min_ms},   {"rounds", cfg->ray_rounds},
	};
	results_add_numbers(r, settings, RESULTS_NUMBERS(settings));
	cJSON_AddStringToObject(r, "traversal", bvhlab_traversal_name(cfg->ray_traversal));
	for (int k = 0; k < BVHLAB_TRAVERSAL_COUNT; k++)
		if (cfg->ray_traversals & (1u << k))
			cJSON_AddItemToArray(names, cJSON_CreateString(bvhlab_traversal_name(k)));
	if (cfg->ray_device)
		cJSON_AddStringToObject(r, "device", cfg->ray_device);
	add_kinds(r, cfg);
	if (cfg->has_camera) {
		const bvhlab_camera *c = &cfg->camera;
		const float v[10] = {c->position[0], c->position[1], c->position[2], c->target[0],
		                     c->target[1], c->target[2], c->up[0], c->up[1], c->up[2],
		                     c->fov_deg};
		cJSON_AddItemToObject(r, "camera", cJSON_CreateFloatArray(v, 10));
	}
	return r;
}

/* The measurement settings as this sweep uses them (command-line
 * overrides included); rays_per_frame only where there are frames. */
static cJSON *measure_json(const struct config *cfg, bool animated)
{
	cJSON *m = cJSON_CreateObject();
	cJSON_AddNumberToObject(m, "repeat", cfg->repeat);
	cJSON_AddNumberToObject(m, "warmup", cfg->warmup);
	cJSON_AddBoolToObject(m, "validate", cfg->validate);
	cJSON_AddNumberToObject(m, "validate_rays", cfg->validate_rays);
	cJSON_AddBoolToObject(m, "pin", cfg->pin);
	cJSON_AddItemToObject(m, "rays", rays_json(cfg));
	if (animated)
		cJSON_AddNumberToObject(m, "rays_per_frame", (double)cfg->rays_per_frame);
	return m;
}

static int json_hash(const cJSON *o, char out[17])
{
	char *text = o ? cJSON_PrintUnformatted(o) : NULL;
	if (!text)
		return -ENOMEM;
	plan_hash_text(text, out);
	free(text);
	return 0;
}

int plan_identity_make(struct run_list *list, const struct plan_builder *builders)
{
	const struct config *cfg = list->cfg;
	size_t ns = cfg->scene_count + 1, nb = cfg->builder_count + 1;
	struct plan_identity *id = &list->identity;
	id->scene_hash = calloc(ns, sizeof(*id->scene_hash));
	id->measure_hash = calloc(ns, sizeof(*id->measure_hash));
	id->measure_config = calloc(ns, sizeof(*id->measure_config));
	id->builder_hash = calloc(nb, sizeof(*id->builder_hash));
	id->builder_config = calloc(nb, sizeof(*id->builder_config));
	int r = id->scene_hash && id->measure_hash && id->measure_config && id->builder_hash &&
	        id->builder_config ? 0 : -ENOMEM;
	for (size_t s = 0; r == 0 && s < cfg->scene_count; s++) {
		id->measure_config[s] = measure_json(cfg, cfg->scenes[s].frames > 0);
		r = scene_hash(cfg, s, id->scene_hash[s]);
		if (r == 0)
			r = json_hash(id->measure_config[s], id->measure_hash[s]);
	}
	for (size_t b = 0; r == 0 && builders && b < cfg->builder_count; b++) {
		if (!builders[b].builder_hash)
			continue;
		snprintf(id->builder_hash[b], 17, "%s", builders[b].builder_hash);
		if (builders[b].builder_config &&
		    !(id->builder_config[b] = cJSON_Duplicate(builders[b].builder_config, 1)))
			r = -ENOMEM;
	}
	return r;
}

void plan_identity_key(struct run_list *list, struct plan_run *run)
{
	struct plan_identity *id = &list->identity;
	const char *builder = id->builder_hash[run->builder];
	struct run_identity *key = &run->key;
	key->scene_hash = id->scene_hash[run->scene];
	key->measure_hash = id->measure_hash[run->scene];
	key->scene_config = cJSON_GetArrayItem(
		cJSON_GetObjectItemCaseSensitive(list->cfg->root, "scenes"), (int)run->scene);
	key->measure_config = id->measure_config[run->scene];
	key->builder_config = id->builder_config[run->builder];
	/* "" for a builder whose plugin could not be opened: its failed runs
	 * still follow their scene and measurement. */
	key->builder_hash = builder;
	char text[3 * 17 + 3];
	snprintf(text, sizeof(text), "%s %s %s", key->scene_hash, builder, key->measure_hash);
	plan_hash_text(text, run->hash);
	key->hash = run->hash;
}

void plan_identity_finish(struct run_list *list)
{
	struct plan_identity *id = &list->identity;
	for (size_t s = 0; id->measure_config && s < list->cfg->scene_count; s++)
		cJSON_Delete(id->measure_config[s]);
	for (size_t b = 0; id->builder_config && b < list->cfg->builder_count; b++)
		cJSON_Delete(id->builder_config[b]);
	free(id->scene_hash);
	free(id->measure_hash);
	free(id->measure_config);
	free(id->builder_hash);
	free(id->builder_config);
	memset(id, 0, sizeof(*id));
}
