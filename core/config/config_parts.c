/*
 * Composite scenes in configs: a scene whose "parts" are meshes or
 * generators, each placed with "scale", "rotate" (degrees about x, y, z)
 * and "translate" and optionally subdivided, merged into one scene when it
 * is loaded (harness_load_scene).
 */
#include <errno.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "config/config_internal.h"

static int part_path(struct config *cfg, struct config_scene *src, bvhlab_error *err)
{
	char *resolved;

	if (!src->path)
		return 0;
	if (config_resolve(cfg, src->path, &resolved)) {
		error_set(err, "%s: out of memory", cfg->path);
		return -ENOMEM;
	}
	free(src->path);
	src->path = resolved;
	return 0;
}

static int parse_part(struct config *cfg, const cJSON *obj, const char *scene_prefix,
                      size_t index, struct config_part *part, bvhlab_error *err)
{
	char prefix[2 * CONFIG_NAME_SIZE], where[2 * CONFIG_NAME_SIZE], got[48];
	int rc;

	snprintf(prefix, sizeof(prefix), "%sparts[%zu].", scene_prefix, index);
	snprintf(where, sizeof(where), "in %sparts[%zu]", scene_prefix, index);
	if (!cJSON_IsObject(obj))
		return config_error(cfg, obj, false, err, "'%.*s' must be an object, not %s",
		                    (int)strlen(prefix) - 1, prefix,
		                    config_describe(cfg, obj, got, sizeof(got)));
	bvhlab_gen_params_init(&part->src.gen);
	bvhlab_transform_init(&part->xf);
	rc = config_check_keys(cfg, obj, config_part_keys, where, err);
	if (!rc)
		rc = config_read_keys(cfg, obj, config_part_keys, prefix, part, err);
	if (!rc)
		rc = config_scene_source(cfg, obj, prefix, config_part_keys, &part->src, err);
	if (!rc)
		rc = config_get_dvec3(cfg, obj, "rotate", prefix, part->xf.rotate, err);
	if (!rc)
		rc = config_get_dvec3(cfg, obj, "translate", prefix, part->xf.translate, err);
	if (!rc)
		rc = config_parse_motion(cfg, obj, prefix, &part->motion, err);
	return rc ? rc : part_path(cfg, &part->src, err);
}

int config_no_own_source(struct config *cfg, const cJSON *obj, const char *prefix,
                         const char *what, const char *to, bvhlab_error *err)
{
	for (const struct config_key *k = config_scene_keys; k->name; k++) {
		const cJSON *item = config_member(obj, k->name);
		bool source = strcmp(k->name, "path") == 0 || strcmp(k->name, "generator") == 0;
		if (item && (source || (k->flags & CONFIG_GENERATED)))
			return config_error(cfg, item, true, err,
			                    "'%s%s' does not apply to a scene with '%s': give it "
			                    "to %s", prefix, k->name, what, to);
	}
	return 0;
}

int config_parse_parts(struct config *cfg, const cJSON *obj, const char *prefix,
                       struct config_scene *sc, bvhlab_error *err)
{
	const cJSON *parts = config_member(obj, "parts");
	char got[48];
	size_t n, i = 0;
	int rc = config_no_own_source(cfg, obj, prefix, "parts", "a part", err);

	if (rc)
		return rc;
	if (!cJSON_IsArray(parts) || (n = (size_t)cJSON_GetArraySize(parts)) == 0)
		return config_error(cfg, parts, false, err,
		                    "'%sparts' must be a non-empty array of parts, not %s", prefix,
		                    config_describe(cfg, parts, got, sizeof(got)));
	sc->parts = calloc(n, sizeof(*sc->parts));
	if (!sc->parts) {
		error_set(err, "%s: out of memory", cfg->path);
		return -ENOMEM;
	}
	sc->part_count = n; /* before filling, so config_parts_free frees what was filled */
	for (const cJSON *e = parts->child; e && !rc; e = e->next, i++)
		rc = parse_part(cfg, e, prefix, i, &sc->parts[i], err);
	return rc;
}

void config_parts_free(struct config_scene *sc)
{
	for (size_t i = 0; sc->parts && i < sc->part_count; i++) {
		free(sc->parts[i].src.path);
		free(sc->parts[i].src.generator);
	}
	free(sc->parts);
	sc->parts = NULL;
	sc->part_count = 0;
}
