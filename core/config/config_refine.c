/*
 * A builder's "refine" list: refinement stages (ABI 1.2 refine functions)
 * applied in order to the builder's finished tree,
 *   "refine": [{"plugin": "reinsert", "options": {"batch": 0.05}}, ...]
 * Each stage names a plugin like a builder does; its options are checked
 * against that plugin's declarations when the harness opens it.
 */
#include <errno.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "config/config_internal.h"
#include "config/json_locate.h"

static int out_of_memory(const struct config *cfg, bvhlab_error *err)
{
	error_set(err, "%s: out of memory", cfg->path);
	return -ENOMEM;
}

static bool is_plugin_path(const char *plugin)
{
	size_t n = strlen(plugin);
	return strchr(plugin, '/') || (n >= 3 && strcmp(plugin + n - 3, ".so") == 0);
}

/* "NAME+stage": the stage's plugin name, or its file's stem for a path. */
static int append_name(struct config_builder *b, const char *plugin)
{
	char *stem = is_plugin_path(plugin) ? config_stem(plugin) : strdup(plugin);
	size_t size = strlen(b->name) + 1 + (stem ? strlen(stem) : 0) + 1;
	char *name = stem ? malloc(size) : NULL;
	if (name)
		snprintf(name, size, "%s+%s", b->name, stem);
	free(stem);
	if (!name)
		return -ENOMEM;
	free(b->name);
	b->name = name;
	return 0;
}

/* The stage's plugin, resolved against the config's folder when a path. */
static int stage_plugin(struct config *cfg, const cJSON *obj, const char *prefix,
                        struct config_refine *r, bvhlab_error *err)
{
	char *resolved;
	int rc = config_get_string(cfg, obj, "plugin", prefix, &r->plugin, err);
	if (rc)
		return rc;
	if (!r->plugin)
		return config_error(cfg, obj, false, err, "'%.*s' needs a 'plugin' (a refining "
		                    "plugin's name or a path to a .so)", (int)strlen(prefix) - 1, prefix);
	if (!is_plugin_path(r->plugin))
		return 0;
	if (config_resolve(cfg, r->plugin, &resolved))
		return out_of_memory(cfg, err);
	free(r->plugin);
	r->plugin = resolved;
	return 0;
}

static int parse_stage(struct config *cfg, const cJSON *obj, const char *prefix,
                       struct config_refine *r, bvhlab_error *err)
{
	char where[CONFIG_NAME_SIZE + 8], got[48];
	const cJSON *options;
	snprintf(where, sizeof(where), "in %.*s", (int)strlen(prefix) - 1, prefix);
	if (!cJSON_IsObject(obj))
		return config_error(cfg, obj, false, err, "'%.*s' must be an object, not %s",
		                    (int)strlen(prefix) - 1, prefix,
		                    config_describe(cfg, obj, got, sizeof(got)));
	json_locate_value(cfg->locations, obj, &r->line, &r->column);
	int rc = config_check_keys(cfg, obj, config_refine_keys, where, err);
	if (!rc)
		rc = stage_plugin(cfg, obj, prefix, r, err);
	if (rc || !(options = config_member(obj, "options")))
		return rc;
	if (!cJSON_IsObject(options))
		return config_error(cfg, options, false, err, "'%soptions' must be an object, not %s",
		                    prefix, config_describe(cfg, options, got, sizeof(got)));
	r->options = options;
	return config_check_duplicates(cfg, options, where, err);
}

int config_parse_refine(struct config *cfg, const cJSON *obj, size_t index,
                        struct config_builder *b, bvhlab_error *err)
{
	const cJSON *list = config_member(obj, "refine");
	char prefix[CONFIG_NAME_SIZE + 16], got[48];
	size_t n, k = 0;
	if (!list)
		return 0;
	n = cJSON_IsArray(list) ? (size_t)cJSON_GetArraySize(list) : 0;
	if (n < 1 || n > CONFIG_MAX_REFINE)
		return config_error(cfg, list, false, err, "'builders[%zu].refine' must be an array "
		                    "of 1 to %d stages, not %s", index, CONFIG_MAX_REFINE,
		                    config_describe(cfg, list, got, sizeof(got)));
	if (!(b->refine = calloc(n, sizeof(*b->refine))))
		return out_of_memory(cfg, err);
	b->refine_count = n; /* before filling, so config_refine_finish frees what was filled */
	for (const cJSON *e = list->child; e; e = e->next, k++) {
		snprintf(prefix, sizeof(prefix), "builders[%zu].refine[%zu].", index, k);
		int rc = parse_stage(cfg, e, prefix, &b->refine[k], err);
		if (rc)
			return rc;
		if (!config_member(obj, "name") && append_name(b, b->refine[k].plugin) < 0)
			return out_of_memory(cfg, err);
	}
	return 0;
}

void config_refine_finish(struct config_builder *b)
{
	for (size_t k = 0; b->refine && k < b->refine_count; k++)
		free(b->refine[k].plugin);
	free(b->refine);
	b->refine = NULL;
	b->refine_count = 0;
}

/* Stage k of `stages` (a builder's "refine" or its animation's) through the
 * builder's option checks, under a label that names the stage
 * ("lbvh+reinsert, refine stage 1 (reinsert)"). */
int config_apply_stage_options(const struct config *cfg, const struct config_builder *b,
                               const struct config_refine *stages, const char *kind, size_t k,
                               bvhlab_options *opts, bvhlab_error *err)
{
	char label[256];
	struct config_builder stage = *b;
	snprintf(label, sizeof(label), "%s, %s %zu (%s)", b->name, kind, k + 1, stages[k].plugin);
	stage.name = label;
	stage.options = stages[k].options;
	return config_apply_options(cfg, &stage, opts, err);
}

int config_apply_refine_options(const struct config *cfg, const struct config_builder *b,
                                size_t k, bvhlab_options *opts, bvhlab_error *err)
{
	return config_apply_stage_options(cfg, b, b->refine, "refine stage", k, opts, err);
}
