/*
 * Which scenes a builder runs on: its "scenes", a list of the config's
 * scene names, or every scene. A config mixing scenes no one-level tree
 * can hold (a two-level forest of billions of instanced triangles) with
 * scenes small enough to flatten needs it: without it every builder meets
 * every scene, and the one-level builders' runs on the forest can only
 * fail. The list is checked once, here; the run list (plan_runs.c) leaves
 * out the runs it excludes, so `run`, `plan`, `--resume`, merge and the
 * reports never see them.
 */
#include <stdio.h>
#include <string.h>

#include "config/config_internal.h"

bool config_builder_runs_on(const struct config_builder *b, const struct config_scene *sc)
{
	const cJSON *name;
	if (!b->scenes)
		return true;
	cJSON_ArrayForEach(name, b->scenes)
		if (cJSON_IsString(name) && strcmp(name->valuestring, sc->name) == 0)
			return true;
	return false;
}

/* The scene named `name`, or -1. */
static long scene_index(const struct config *cfg, const char *name)
{
	for (size_t s = 0; s < cfg->scene_count; s++)
		if (strcmp(cfg->scenes[s].name, name) == 0)
			return (long)s;
	return -1;
}

/* An element naming no scene of the config: the names there are, and the
 * closest one. */
static int unknown_scene(const struct config *cfg, const cJSON *item, const char *key,
                         size_t k, const struct config_builder *b, bvhlab_error *err)
{
	char list[256] = "", hint[96] = "";
	size_t used = 0;
	struct config_suggestion s;
	config_suggest_init(&s);
	for (size_t i = 0; i < cfg->scene_count; i++) {
		config_suggest_consider(&s, item->valuestring, cfg->scenes[i].name);
		if (used < sizeof(list))
			used += (size_t)snprintf(list + used, sizeof(list) - used, "%s%s",
			                         i ? ", " : "", cfg->scenes[i].name);
	}
	if (used >= sizeof(list))
		memcpy(list + sizeof(list) - 4, "...", 4);
	if (s.best)
		snprintf(hint, sizeof(hint), "; did you mean '%s'?", s.best);
	return config_error(cfg, item, false, err, "'%s[%zu]' of builder '%s': no scene is named "
	                    "'%s' (the config's scenes: %s)%s", key, k, b->name,
	                    item->valuestring, list, hint);
}

/* Every element a name of one of the config's scenes, none twice. */
static int check_names(const struct config *cfg, const cJSON *list, const char *key,
                       const struct config_builder *b, bvhlab_error *err)
{
	char got[48];
	size_t k = 0;
	for (const cJSON *e = list->child; e; e = e->next, k++) {
		if (!cJSON_IsString(e))
			return config_error(cfg, e, false, err, "'%s[%zu]' of builder '%s' must be a "
			                    "scene's name, not %s", key, k, b->name,
			                    config_describe(cfg, e, got, sizeof(got)));
		if (scene_index(cfg, e->valuestring) < 0)
			return unknown_scene(cfg, e, key, k, b, err);
		for (const cJSON *f = list->child; f != e; f = f->next)
			if (strcmp(f->valuestring, e->valuestring) == 0)
				return config_error(cfg, e, false, err, "'%s[%zu]' of builder '%s': scene "
				                    "'%s' is listed twice", key, k, b->name, e->valuestring);
	}
	return 0;
}

/* A two-level builder meets two-level scenes only (the ones it runs on). */
static int two_level_scenes(const struct config *cfg, const cJSON *obj, const char *prefix,
                            const struct config_builder *b, bvhlab_error *err)
{
	for (size_t s = 0; b->top && s < cfg->scene_count; s++)
		if (!cfg->scenes[s].meshes && config_builder_runs_on(b, &cfg->scenes[s]))
			return config_error(cfg, config_member(obj, b->scenes ? "scenes" : "bottom"), true,
			                    err, "'%s%s' of builder '%s': a two-level builder runs on "
			                    "two-level scenes only, and scene '%s' has no 'instances'%s",
			                    prefix, b->scenes ? "scenes" : "bottom", b->name,
			                    cfg->scenes[s].name,
			                    b->scenes ? "" : " (list the scenes it runs on in its "
			                    "\"scenes\")");
	return 0;
}

int config_parse_builder_scenes(struct config *cfg, const cJSON *obj, size_t index,
                                struct config_builder *b, bvhlab_error *err)
{
	const cJSON *list = config_member(obj, "scenes");
	char key[CONFIG_NAME_SIZE], prefix[CONFIG_NAME_SIZE], got[48];
	snprintf(key, sizeof(key), "builders[%zu].scenes", index);
	snprintf(prefix, sizeof(prefix), "builders[%zu].", index);
	if (list && !cJSON_IsArray(list))
		return config_error(cfg, list, false, err, "'%s' of builder '%s' must be an array of "
		                    "scene names, not %s", key, b->name,
		                    config_describe(cfg, list, got, sizeof(got)));
	if (list && !list->child)
		return config_error(cfg, list, true, err, "'%s' of builder '%s' is empty: list the "
		                    "scenes it runs on, or leave the key out to run it on every "
		                    "scene", key, b->name);
	int rc = list ? check_names(cfg, list, key, b, err) : 0;
	b->scenes = rc ? NULL : list;
	return rc ? rc : two_level_scenes(cfg, obj, prefix, b, err);
}
