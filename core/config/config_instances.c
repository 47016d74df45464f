/*
 * Two-level scenes in configs (docs/instances.md): "meshes", each a named
 * path or generator loaded once, and "instances" placing them, one by one
 * (a "matrix", or a part's "scale", "rotate", "translate") or many at a
 * time ("scatter"). Everything that can be wrong is found here, before any
 * output folder: an unknown mesh, a singular matrix, a zero or huge count.
 */
#include <errno.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "config/config_internal.h"
#include "scene/instances.h"

static int out_of_memory(const struct config *cfg, bvhlab_error *err)
{
	error_set(err, "%s: out of memory", cfg->path);
	return -ENOMEM;
}

/* A non-empty array member, its element count in *n. */
static int nonempty_array(struct config *cfg, const cJSON *obj, const char *key,
                          const char *prefix, const char *of, size_t *n, bvhlab_error *err)
{
	const cJSON *a = config_member(obj, key);
	char got[48];
	if (!cJSON_IsArray(a) || (*n = (size_t)cJSON_GetArraySize(a)) == 0)
		return config_error(cfg, a ? a : obj, false, err,
		                    "'%s%s' must be a non-empty array of %s, not %s", prefix, key, of,
		                    a ? config_describe(cfg, a, got, sizeof(got)) : "missing");
	return 0;
}

static int object_entry(struct config *cfg, const cJSON *e, const char *prefix,
                        bvhlab_error *err)
{
	char got[48];
	if (cJSON_IsObject(e))
		return 0;
	return config_error(cfg, e, false, err, "'%.*s' must be an object, not %s",
	                    (int)strlen(prefix) - 1, prefix,
	                    config_describe(cfg, e, got, sizeof(got)));
}

static int parse_mesh(struct config *cfg, const cJSON *obj, const char *prefix,
                      const char *where, struct config_mesh *m, bvhlab_error *err)
{
	bvhlab_gen_params_init(&m->src.gen);
	int rc = object_entry(cfg, obj, prefix, err);
	if (!rc)
		rc = config_check_keys(cfg, obj, config_mesh_keys, where, err);
	if (!rc)
		rc = config_read_keys(cfg, obj, config_mesh_keys, prefix, m, err);
	if (!rc && !m->name)
		return config_error(cfg, obj, false, err, "'%.*s' needs a 'name' its instances "
		                    "give as 'mesh'", (int)strlen(prefix) - 1, prefix);
	if (!rc)
		rc = config_scene_source(cfg, obj, prefix, config_mesh_keys, &m->src, err);
	char *resolved;
	if (!rc && m->src.path) {
		if (config_resolve(cfg, m->src.path, &resolved))
			return out_of_memory(cfg, err);
		free(m->src.path);
		m->src.path = resolved;
	}
	return rc;
}

static int parse_meshes(struct config *cfg, const cJSON *obj, const char *prefix,
                        struct config_scene *sc, bvhlab_error *err)
{
	char p[2 * CONFIG_NAME_SIZE], where[2 * CONFIG_NAME_SIZE];
	size_t n, i = 0;
	int rc = nonempty_array(cfg, obj, "meshes", prefix, "meshes", &n, err);
	if (rc)
		return rc;
	sc->meshes = calloc(n, sizeof(*sc->meshes));
	if (!sc->meshes)
		return out_of_memory(cfg, err);
	sc->mesh_count = n; /* before filling, so config_instances_free frees what was filled */
	for (const cJSON *e = config_member(obj, "meshes")->child; e && !rc; e = e->next, i++) {
		snprintf(p, sizeof(p), "%smeshes[%zu].", prefix, i);
		snprintf(where, sizeof(where), "in %smeshes[%zu]", prefix, i);
		rc = parse_mesh(cfg, e, p, where, &sc->meshes[i], err);
		for (size_t k = 0; !rc && k < i; k++)
			if (strcmp(sc->meshes[k].name, sc->meshes[i].name) == 0)
				rc = config_error(cfg, config_member(e, "name"), false, err,
				                  "'%sname': mesh '%s' is also %smeshes[%zu]'s name", p,
				                  sc->meshes[i].name, prefix, k);
	}
	return rc;
}

/* "mesh": the name of one of the scene's meshes. */
static int mesh_of(struct config *cfg, const cJSON *obj, const char *prefix,
                   const struct config_scene *sc, uint32_t *out, bvhlab_error *err)
{
	const cJSON *item = config_member(obj, "mesh");
	struct config_suggestion s;
	char got[48];
	if (!cJSON_IsString(item))
		return config_error(cfg, item ? item : obj, false, err,
		                    "'%smesh' must name one of the scene's 'meshes', not %s", prefix,
		                    item ? config_describe(cfg, item, got, sizeof(got)) : "missing");
	config_suggest_init(&s);
	for (size_t m = 0; m < sc->mesh_count; m++) {
		if (strcmp(sc->meshes[m].name, item->valuestring) == 0) {
			*out = (uint32_t)m;
			return 0;
		}
		config_suggest_consider(&s, item->valuestring, sc->meshes[m].name);
	}
	return config_error(cfg, item, false, err,
	                    "'%smesh': scene '%s' has no mesh '%s'%s%s%s", prefix,
	                    sc->name ? sc->name : "", item->valuestring,
	                    s.best ? " (did you mean '" : "", s.best ? s.best : "",
	                    s.best ? "'?)" : "");
}

/* item as an array of exactly n finite numbers (magnitude <= 1e30). */
static bool numbers_of(const cJSON *item, int n, double *out)
{
	const cJSON *e;
	int k = 0;
	if (!cJSON_IsArray(item) || cJSON_GetArraySize(item) != n)
		return false;
	cJSON_ArrayForEach(e, item) {
		if (!cJSON_IsNumber(e) || !isfinite(e->valuedouble) || fabs(e->valuedouble) > 1e30)
			return false;
		out[k++] = e->valuedouble;
	}
	return true;
}

/* "matrix": 12 finite numbers, row-major 3x4, invertible. */
static int parse_matrix(struct config *cfg, const cJSON *item, const char *prefix,
                        double m[12], bvhlab_error *err)
{
	double inv[12];
	char got[48];
	if (!numbers_of(item, 12, m))
		return config_error(cfg, item, false, err,
		                    "'%smatrix' must be an array of 12 finite numbers (3 rows of "
		                    "4, row-major), not %s", prefix,
		                    config_describe(cfg, item, got, sizeof(got)));
	if (scene_matrix_invert(m, inv))
		return config_error(cfg, item, false, err, "'%smatrix' is singular: an instance "
		                    "must keep its volume", prefix);
	return 0;
}

/* One placed instance: a matrix, or scale/rotate/translate. */
static int parse_placed(struct config *cfg, const cJSON *obj, const char *prefix,
                        struct config_instance *in, bvhlab_error *err)
{
	const cJSON *matrix = config_member(obj, "matrix");
	static const char *const parts[] = {"scale", "rotate", "translate"};
	bvhlab_transform xf;
	for (int k = 0; matrix && k < 3; k++)
		if (config_member(obj, parts[k]))
			return config_error(cfg, config_member(obj, parts[k]), true, err,
			                    "'%s%s' and '%smatrix' both place the instance: give one",
			                    prefix, parts[k], prefix);
	if (matrix)
		return parse_matrix(cfg, matrix, prefix, in->xf, err);
	bvhlab_transform_init(&xf);
	int rc = config_get_positive(cfg, obj, "scale", prefix, &xf.scale, err);
	if (!rc)
		rc = config_get_dvec3(cfg, obj, "rotate", prefix, xf.rotate, err);
	if (!rc)
		rc = config_get_dvec3(cfg, obj, "translate", prefix, xf.translate, err);
	if (!rc)
		scene_transform_matrix(&xf, in->xf);
	return rc;
}

/* "bounds": [[x, y, z], [x, y, z]], the first <= the second. */
static int parse_bounds(struct config *cfg, const cJSON *obj, const char *prefix,
                        struct config_instance *in, bvhlab_error *err)
{
	const cJSON *b = config_member(obj, "bounds");
	char got[48];
	bool ok = cJSON_IsArray(b) && cJSON_GetArraySize(b) == 2 &&
	          numbers_of(cJSON_GetArrayItem(b, 0), 3, in->lo) &&
	          numbers_of(cJSON_GetArrayItem(b, 1), 3, in->hi);
	for (int k = 0; ok && k < 3; k++)
		ok = in->lo[k] <= in->hi[k];
	if (ok)
		return 0;
	return config_error(cfg, b ? b : obj, false, err,
	                    "'%sbounds' must be [[x, y, z], [x, y, z]], the first corner below "
	                    "the second, not %s", prefix,
	                    b ? config_describe(cfg, b, got, sizeof(got)) : "missing");
}

/* "scale": [a, b], 0 < a <= b; "rotate": "none" or "random-y". */
static int parse_spread(struct config *cfg, const cJSON *obj, const char *prefix,
                        struct config_instance *in, bvhlab_error *err)
{
	const cJSON *scale = config_member(obj, "scale"), *rotate = config_member(obj, "rotate");
	char got[48];
	in->scale[0] = in->scale[1] = 1.0;
	if (scale && !(numbers_of(scale, 2, in->scale) && in->scale[0] > 0 &&
	               in->scale[0] <= in->scale[1]))
		return config_error(cfg, scale, false, err,
		                    "'%sscale' must be [a, b] with 0 < a <= b, not %s", prefix,
		                    config_describe(cfg, scale, got, sizeof(got)));
	in->rotate = CONFIG_SCATTER_NONE;
	if (!rotate || (cJSON_IsString(rotate) && strcmp(rotate->valuestring, "none") == 0))
		return 0;
	if (cJSON_IsString(rotate) && strcmp(rotate->valuestring, "random-y") == 0) {
		in->rotate = CONFIG_SCATTER_RANDOM_Y;
		return 0;
	}
	return config_error(cfg, rotate, false, err,
	                    "'%srotate' must be \"none\" or \"random-y\", not %s", prefix,
	                    config_describe(cfg, rotate, got, sizeof(got)));
}

static int parse_scatter(struct config *cfg, const cJSON *obj, const char *prefix,
                         const struct config_scene *sc, struct config_instance *in,
                         bvhlab_error *err)
{
	char where[2 * CONFIG_NAME_SIZE];
	snprintf(where, sizeof(where), "in %.*s", (int)strlen(prefix) - 1, prefix);
	in->scatter = true;
	in->seed = 1;
	int rc = object_entry(cfg, obj, prefix, err);
	if (!rc)
		rc = config_check_keys(cfg, obj, config_scatter_keys, where, err);
	if (!rc)
		rc = config_read_keys(cfg, obj, config_scatter_keys, prefix, in, err);
	if (!rc && !config_member(obj, "count"))
		return config_error(cfg, obj, false, err, "'%scount' is missing: how many "
		                    "instances to scatter (1 to %u)", prefix, CONFIG_MAX_INSTANCES);
	if (!rc)
		rc = mesh_of(cfg, obj, prefix, sc, &in->mesh, err);
	if (!rc)
		rc = parse_bounds(cfg, obj, prefix, in, err);
	if (!rc)
		rc = parse_spread(cfg, obj, prefix, in, err);
	return rc ? rc : config_parse_motion(cfg, obj, prefix, &in->motion, err);
}

static int parse_instance(struct config *cfg, const cJSON *obj, const char *prefix,
                          struct config_scene *sc, struct config_instance *in,
                          bvhlab_error *err)
{
	char where[2 * CONFIG_NAME_SIZE], sp[3 * CONFIG_NAME_SIZE];
	const cJSON *scatter = config_member(obj, "scatter");
	snprintf(where, sizeof(where), "in %.*s", (int)strlen(prefix) - 1, prefix);
	int rc = object_entry(cfg, obj, prefix, err);
	if (!rc)
		rc = config_check_keys(cfg, obj, config_instance_keys, where, err);
	if (rc)
		return rc;
	if (scatter) {
		for (const cJSON *m = obj->child; m; m = m->next)
			if (m != scatter)
				return config_error(cfg, m, true, err, "'%s%s' beside 'scatter': give "
				                    "it inside the scatter", prefix, m->string);
		snprintf(sp, sizeof(sp), "%sscatter.", prefix);
		return parse_scatter(cfg, scatter, sp, sc, in, err);
	}
	in->count = 1;
	rc = mesh_of(cfg, obj, prefix, sc, &in->mesh, err);
	if (!rc)
		rc = parse_placed(cfg, obj, prefix, in, err);
	return rc ? rc : config_parse_motion(cfg, obj, prefix, &in->motion, err);
}

static int parse_instances(struct config *cfg, const cJSON *obj, const char *prefix,
                           struct config_scene *sc, bvhlab_error *err)
{
	char p[2 * CONFIG_NAME_SIZE];
	size_t n, i = 0;
	int rc = nonempty_array(cfg, obj, "instances", prefix, "instances", &n, err);
	if (rc)
		return rc;
	sc->instances = calloc(n, sizeof(*sc->instances));
	if (!sc->instances)
		return out_of_memory(cfg, err);
	sc->instance_count = n;
	for (const cJSON *e = config_member(obj, "instances")->child; e && !rc;
	     e = e->next, i++) {
		snprintf(p, sizeof(p), "%sinstances[%zu].", prefix, i);
		rc = parse_instance(cfg, e, p, sc, &sc->instances[i], err);
		sc->instance_total += sc->instances[i].count;
	}
	if (!rc && sc->instance_total > CONFIG_MAX_INSTANCES)
		rc = config_error(cfg, config_member(obj, "instances"), false, err,
		                  "'%sinstances': %llu instances in all, more than the %u a scene "
		                  "may hold", prefix, (unsigned long long)sc->instance_total,
		                  CONFIG_MAX_INSTANCES);
	return rc;
}

/* What a two-level scene cannot have: its own source, subdivision of the
 * whole, parts, a motion of the whole (its instances move: "animate" on
 * them), frame files. */
static int refuse_others(struct config *cfg, const cJSON *obj, const char *prefix,
                         bvhlab_error *err)
{
	static const char *const keys[] = {"parts", "subdivide", "animate", "deform", "amplitude"};
	const cJSON *frames = config_member(obj, "frames");
	int rc = config_no_own_source(cfg, obj, prefix, "meshes", "a mesh", err);
	for (size_t k = 0; !rc && k < sizeof(keys) / sizeof(keys[0]); k++)
		if (config_member(obj, keys[k]))
			rc = config_error(cfg, config_member(obj, keys[k]), true, err,
			                  "'%s%s' does not apply to a scene with 'instances'%s", prefix,
			                  keys[k], k < 2 ? ": give it to a mesh"
			                           : ": give 'animate' to the instances that move (they "
			                             "move rigidly; a mesh does not deform)");
	if (!rc && cJSON_IsObject(frames))
		rc = config_error(cfg, frames, true, err, "'%sframes' of a scene with 'instances' "
		                  "is a number of frames: its instances move by their 'animate', "
		                  "not from frame files", prefix);
	return rc;
}

int config_parse_instances(struct config *cfg, const cJSON *obj, const char *prefix,
                           struct config_scene *sc, bvhlab_error *err)
{
	int rc = refuse_others(cfg, obj, prefix, err);
	if (!rc && !config_member(obj, "instances"))
		rc = config_error(cfg, config_member(obj, "meshes"), true, err,
		                  "'%smeshes' without 'instances': place the meshes", prefix);
	if (!rc)
		rc = parse_meshes(cfg, obj, prefix, sc, err);
	return rc ? rc : parse_instances(cfg, obj, prefix, sc, err);
}

void config_instances_free(struct config_scene *sc)
{
	for (size_t i = 0; sc->meshes && i < sc->mesh_count; i++) {
		free(sc->meshes[i].name);
		free(sc->meshes[i].src.path);
		free(sc->meshes[i].src.generator);
	}
	free(sc->meshes);
	free(sc->instances);
	sc->meshes = NULL;
	sc->instances = NULL;
	sc->mesh_count = sc->instance_count = 0;
}
