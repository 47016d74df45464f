/*
 * Config entries: the "scenes" and "builders" arrays, and applying a
 * builder's "options" to its plugin's declared options.
 */
#include <errno.h>
#include <math.h>
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

/* The array under `key`, required and non-empty; *count entries allocated. */
static int entry_array(struct config *cfg, const char *key, size_t size, const cJSON **array,
                       void **entries, size_t *count, bvhlab_error *err)
{
	const cJSON *item = config_member(cfg->root, key);
	char got[48];
	if (!item)
		return config_error(cfg, cfg->root, false, err,
		                    "missing '%s' (an array of at least one entry)", key);
	if (!cJSON_IsArray(item))
		return config_error(cfg, item, false, err, "'%s' must be an array, not %s", key,
		                    config_describe(cfg, item, got, sizeof(got)));
	size_t n = (size_t)cJSON_GetArraySize(item);
	if (n == 0)
		return config_error(cfg, item, false, err, "'%s' must not be empty", key);
	*entries = calloc(n, size);
	if (!*entries)
		return out_of_memory(cfg, err);
	*count = n; /* before filling, so config_finish frees whatever was filled */
	*array = item;
	return 0;
}

/* The code point at *p (UTF-8, advancing p), or -1 for no valid UTF-8
 * (overlong forms, surrogates, past U+10FFFF). */
static int32_t next_code_point(const unsigned char **p)
{
	const unsigned char *q = *p;
	int n = *q < 0x80 ? 0 : (*q & 0xe0) == 0xc0 ? 1 : (*q & 0xf0) == 0xe0 ? 2
	        : (*q & 0xf8) == 0xf0 ? 3 : -1;
	if (n < 0 || (n == 1 && *q < 0xc2) || (n == 3 && *q > 0xf4))
		return -1;
	uint32_t cp = *q & (0x7f >> n);
	for (int k = 1; k <= n; k++) {
		if ((q[k] & 0xc0) != 0x80)
			return -1;
		cp = cp << 6 | (q[k] & 0x3f);
	}
	if ((n == 2 && (cp < 0x800 || (cp >= 0xd800 && cp <= 0xdfff))) ||
	    (n == 3 && (cp < 0x10000 || cp > 0x10ffff)))
		return -1;
	*p = q + n + 1;
	return (int32_t)cp;
}

/* Characters that reorder or hide what follows them in a report or a
 * terminal: U+061C, U+200E/F, U+202A-E, U+2066-9. */
static bool bidi_control(uint32_t cp)
{
	return cp == 0x61c || cp == 0x200e || cp == 0x200f || (cp >= 0x202a && cp <= 0x202e) ||
	       (cp >= 0x2066 && cp <= 0x2069);
}

/* What is wrong with a name, written into why; false when nothing.
 * Names go into results.json (JSON readers must read them), reports and
 * progress lines: printable text, something besides blanks. */
static bool bad_name(const char *s, char *why, size_t size)
{
	const unsigned char *p = (const unsigned char *)s;
	bool visible = false;
	while (*p) {
		int32_t cp = next_code_point(&p);
		if (cp < 0)
			return snprintf(why, size, "is not valid UTF-8 (results.json could not be read)"),
			       true;
		if (cp < 0x20 || (cp >= 0x7f && cp < 0xa0) || bidi_control((uint32_t)cp))
			return snprintf(why, size, "holds %s U+%04X", bidi_control((uint32_t)cp)
			                ? "the bidirectional control" : "the control character",
			                (unsigned)cp), true;
		visible = visible || cp != ' ';
	}
	if (!visible)
		snprintf(why, size, "is %s", *s ? "only blanks" : "empty");
	return !visible;
}

/* Scene and builder names label runs and reports: two alike would mix them up. */
static int unique_names(const struct config *cfg, const cJSON *array, const char **names,
                        const char *what, const char *key, bvhlab_error *err)
{
	size_t i = 0;
	for (const cJSON *e = array->child; e; e = e->next, i++) {
		char why[96];
		if (bad_name(names[i], why, sizeof(why))) {
			const cJSON *name = config_member(e, "name");
			return config_error(cfg, name ? name : e, false, err,
			                    "%s[%zu]: its %s name %s: give it a \"name\" of printable "
			                    "text", key, i, what, why);
		}
		for (size_t j = 0; j < i; j++) {
			if (strcmp(names[i], names[j]) != 0)
				continue;
			const cJSON *name = config_member(e, "name");
			return config_error(cfg, name ? name : e, false, err,
			                    "duplicate %s name '%s': %s[%zu] has it too%s", what,
			                    names[i], key, j,
			                    name ? "" : "; set 'name' to tell them apart");
		}
	}
	return 0;
}

/* ---- scenes ------------------------------------------------------------------ */

/* After the table's keys are read: exactly one source, and no generator
 * parameters (the table's CONFIG_GENERATED keys) for a file. */
int config_scene_source(struct config *cfg, const cJSON *obj, const char *prefix,
                        const struct config_key *table, struct config_scene *sc,
                        bvhlab_error *err)
{
	if (sc->path && sc->generator)
		return config_error(cfg, config_member(obj, "generator"), true, err,
		                    "'%.*s' has both 'path' and 'generator': give exactly one",
		                    (int)strlen(prefix) - 1, prefix);
	if (!sc->path && !sc->generator)
		return config_error(cfg, obj, false, err,
		                    "'%.*s' needs a 'path' (a mesh file) or a 'generator'",
		                    (int)strlen(prefix) - 1, prefix);
	for (const struct config_key *k = table; sc->path && k->name; k++) {
		const cJSON *item = config_member(obj, k->name);
		if (item && (k->flags & CONFIG_GENERATED))
			return config_error(cfg, item, true, err,
			                    "'%s%s' applies to generated scenes only, not to a 'path'",
			                    prefix, k->name);
	}
	return 0;
}

/* The default name (file stem, generator or "composite"), and the path as
 * seen from here. */
static int scene_name_and_path(struct config *cfg, struct config_scene *sc,
                               bvhlab_error *err)
{
	if (!sc->name) {
		sc->name = sc->path        ? config_stem(sc->path)
		           : sc->generator ? strdup(sc->generator)
		           : sc->meshes    ? strdup("instances")
		                           : strdup("composite");
		if (!sc->name)
			return out_of_memory(cfg, err);
	}
	if (sc->path) {
		char *resolved;
		if (config_resolve(cfg, sc->path, &resolved))
			return out_of_memory(cfg, err);
		free(sc->path);
		sc->path = resolved;
	}
	return 0;
}

static int parse_scene(struct config *cfg, const cJSON *obj, size_t index,
                       bvhlab_error *err)
{
	struct config_scene *sc = &cfg->scenes[index];
	char prefix[CONFIG_NAME_SIZE], where[CONFIG_NAME_SIZE], got[48];
	snprintf(prefix, sizeof(prefix), "scenes[%zu].", index);
	snprintf(where, sizeof(where), "in scenes[%zu]", index);
	if (!cJSON_IsObject(obj))
		return config_error(cfg, obj, false, err, "'scenes[%zu]' must be an object, not %s",
		                    index, config_describe(cfg, obj, got, sizeof(got)));
	json_locate_value(cfg->locations, obj, &sc->line, &sc->column);
	bvhlab_gen_params_init(&sc->gen);
	int rc = config_check_keys(cfg, obj, config_scene_keys, where, err);
	if (!rc)
		rc = config_read_keys(cfg, obj, config_scene_keys, prefix, sc, err);
	if (!rc) /* animation: frames, motion (config_anim.c) */
		rc = config_parse_frames(cfg, obj, prefix, sc, err);
	if (!rc && (config_member(obj, "instances") || config_member(obj, "meshes")))
		rc = config_parse_instances(cfg, obj, prefix, sc, err);
	else if (!rc && config_member(obj, "parts"))
		rc = config_parse_parts(cfg, obj, prefix, sc, err);
	else if (!rc)
		rc = config_scene_source(cfg, obj, prefix, config_scene_keys, sc, err);
	if (!rc)
		rc = config_parse_scene_camera(cfg, obj, index, sc, err);
	if (!rc)
		rc = scene_name_and_path(cfg, sc, err);
	if (!rc)
		rc = config_check_scene_anim(cfg, obj, prefix, sc, err);
	return rc;
}

int config_parse_scenes(struct config *cfg, bvhlab_error *err)
{
	const cJSON *array;
	void *entries;
	int rc = entry_array(cfg, "scenes", sizeof(*cfg->scenes), &array, &entries,
	                     &cfg->scene_count, err);
	if (rc)
		return rc;
	cfg->scenes = entries;
	size_t i = 0;
	for (const cJSON *e = array->child; e && !rc; e = e->next, i++)
		rc = parse_scene(cfg, e, i, err);
	if (rc)
		return rc;
	const char **names = malloc(cfg->scene_count * sizeof(*names));
	if (!names)
		return out_of_memory(cfg, err);
	for (i = 0; i < cfg->scene_count; i++)
		names[i] = cfg->scenes[i].name;
	rc = unique_names(cfg, array, names, "scene", "scenes", err);
	free(names);
	return rc;
}

/* ---- builders ---------------------------------------------------------------- */

static bool is_plugin_path(const char *plugin)
{
	size_t n = strlen(plugin);
	return strchr(plugin, '/') || (n >= 3 && strcmp(plugin + n - 3, ".so") == 0);
}

/* After the table's keys are read: the plugin is required; a path is
 * resolved against the config's folder. */
static int builder_plugin(struct config *cfg, const cJSON *obj, const char *prefix,
                          struct config_builder *b, bvhlab_error *err)
{
	if (!b->plugin)
		return config_error(cfg, obj, false, err,
		                    "'%.*s' needs a 'plugin' (a plugin name or a path to a .so)",
		                    (int)strlen(prefix) - 1, prefix);
	if (!is_plugin_path(b->plugin)) {
		b->name = b->name ? b->name : strdup(b->plugin);
		return b->name ? 0 : out_of_memory(cfg, err);
	}
	/* A path: relative to the config, and named after the file by default. */
	char *resolved;
	if (!b->name && !(b->name = config_stem(b->plugin)))
		return out_of_memory(cfg, err);
	if (config_resolve(cfg, b->plugin, &resolved))
		return out_of_memory(cfg, err);
	free(b->plugin);
	b->plugin = resolved;
	return 0;
}

/* "bottom" and "top" come together; "bottom" is the builder's plugin (its
 * "options" are the bottom's), default name "two-level[top=T,bottom=B]".
 * Refinement of two-level trees is not there yet; an "animation" updates
 * the top (config_anim.c). */
static int two_level(struct config *cfg, const cJSON *obj, const char *prefix,
                     struct config_builder *b, bvhlab_error *err)
{
	const cJSON *bottom = config_member(obj, "bottom"), *other;
	const cJSON *top_options = config_member(obj, "top_options");
	char got[48];
	if (top_options && !b->top)
		return config_error(cfg, top_options, true, err, "'%stop_options' without '%stop'",
		                    prefix, prefix);
	if (top_options && !cJSON_IsObject(top_options))
		return config_error(cfg, top_options, false, err, "'%stop_options' must be an "
		                    "object, not %s", prefix,
		                    config_describe(cfg, top_options, got, sizeof(got)));
	b->top_options = top_options;
	if (!bottom && !b->top)
		return 0;
	if (!bottom || !b->top)
		return config_error(cfg, bottom ? bottom : config_member(obj, "top"), true, err,
		                    "'%s%s' without '%s%s': a two-level builder names both",
		                    prefix, bottom ? "bottom" : "top", prefix, bottom ? "top" : "bottom");
	if (!cJSON_IsString(bottom) || !bottom->valuestring[0])
		return config_error(cfg, bottom, false, err, "'%sbottom' must be a plugin name, "
		                    "not %s", prefix, config_describe(cfg, bottom, got, sizeof(got)));
	static const char *const not_with[] = {"plugin", "refine"};
	for (size_t k = 0; k < 2; k++)
		if ((other = config_member(obj, not_with[k])))
			return config_error(cfg, other, true, err, "'%s%s' does not apply to a "
			                    "two-level builder ('bottom' and 'top')%s", prefix,
			                    not_with[k], k ? " yet" : ": 'bottom' is its plugin");
	if (!(b->plugin = strdup(bottom->valuestring)))
		return out_of_memory(cfg, err);
	if (!b->name) {
		size_t n = strlen(b->top) + strlen(b->plugin) + 32;
		if (!(b->name = malloc(n)))
			return out_of_memory(cfg, err);
		snprintf(b->name, n, "two-level[top=%s,bottom=%s]", b->top, b->plugin);
	}
	return 0;
}

static int builder_options(struct config *cfg, const cJSON *obj, size_t index,
                           struct config_builder *b, bvhlab_error *err)
{
	const cJSON *options = config_member(obj, "options");
	char where[CONFIG_NAME_SIZE], got[48];
	if (!options)
		return 0;
	if (!cJSON_IsObject(options))
		return config_error(cfg, options, false, err,
		                    "'builders[%zu].options' must be an object, not %s", index,
		                    config_describe(cfg, options, got, sizeof(got)));
	snprintf(where, sizeof(where), "in builders[%zu].options", index);
	b->options = options;
	return config_check_duplicates(cfg, options, where, err);
}

static int parse_builder(struct config *cfg, const cJSON *obj, size_t index,
                         bvhlab_error *err)
{
	struct config_builder *b = &cfg->builders[index];
	char prefix[CONFIG_NAME_SIZE], where[CONFIG_NAME_SIZE], got[48];
	snprintf(prefix, sizeof(prefix), "builders[%zu].", index);
	snprintf(where, sizeof(where), "in builders[%zu]", index);
	if (!cJSON_IsObject(obj))
		return config_error(cfg, obj, false, err, "'builders[%zu]' must be an object, not %s",
		                    index, config_describe(cfg, obj, got, sizeof(got)));
	json_locate_value(cfg->locations, obj, &b->line, &b->column);
	int rc = config_check_keys(cfg, obj, config_builder_keys, where, err);
	if (!rc)
		rc = config_read_keys(cfg, obj, config_builder_keys, prefix, b, err);
	if (!rc)
		rc = two_level(cfg, obj, prefix, b, err);
	if (!rc)
		rc = builder_plugin(cfg, obj, prefix, b, err);
	if (!rc)
		rc = builder_options(cfg, obj, index, b, err);
	if (!rc)
		rc = config_parse_refine(cfg, obj, index, b, err);
	if (!rc)
		rc = config_parse_animation(cfg, obj, index, b, err);
	if (!rc) /* its name final: config_filter.c */
		rc = config_parse_builder_scenes(cfg, obj, index, b, err);
	if (!rc)
		rc = config_check_static_scenes(cfg, obj, index, b, err);
	return rc;
}

int config_parse_builders(struct config *cfg, bvhlab_error *err)
{
	const cJSON *array;
	void *entries;
	int rc = entry_array(cfg, "builders", sizeof(*cfg->builders), &array, &entries,
	                     &cfg->builder_count, err);
	if (rc)
		return rc;
	cfg->builders = entries;
	size_t i = 0;
	for (const cJSON *e = array->child; e && !rc; e = e->next, i++)
		rc = parse_builder(cfg, e, i, err);
	if (rc)
		return rc;
	const char **names = malloc(cfg->builder_count * sizeof(*names));
	if (!names)
		return out_of_memory(cfg, err);
	for (i = 0; i < cfg->builder_count; i++)
		names[i] = cfg->builders[i].name;
	rc = unique_names(cfg, array, names, "builder", "builders", err);
	free(names);
	return rc ? rc : config_expand_grids(cfg, array, err);
}

/* ---- options ----------------------------------------------------------------- */

static int unknown_option(const struct config *cfg, const struct config_builder *b,
                          const bvhlab_options *opts, const cJSON *m, bvhlab_error *err)
{
	const bvhlab_builder *desc = opts->builder;
	char list[256] = "", hint[96] = "";
	size_t used = 0;
	struct config_suggestion s;
	config_suggest_init(&s);
	for (uint32_t i = 0; desc && i < desc->option_count; i++) {
		const char *name = desc->options[i].name;
		config_suggest_consider(&s, m->string, name);
		if (used >= sizeof(list))
			continue;
		used += (size_t)snprintf(list + used, sizeof(list) - used, "%s%s", i ? ", " : "", name);
		if (used >= sizeof(list)) /* a long list: say it goes on */
			memcpy(list + sizeof(list) - 4, "...", 4);
	}
	if (s.best)
		snprintf(hint, sizeof(hint), "; did you mean '%s'?", s.best);
	if (used == 0)
		return config_error(cfg, m, true, err,
		                    "builder '%s': unknown option '%s' for plugin '%s' (it takes no "
		                    "options)", b->name, m->string, desc->name);
	return config_error(cfg, m, true, err,
	                    "builder '%s': unknown option '%s' for plugin '%s' (known: %s)%s",
	                    b->name, m->string, desc->name, list, hint);
}

/* " in [lo, hi]", " (one of a|b)": what a declaration allows beyond its type. */
static void allowed(const bvhlab_builder *desc, const bvhlab_option_decl *d, char *buf,
                    size_t size)
{
	size_t n = 0;
	buf[0] = '\0';
	if (d->min <= d->max && (d->type == BVHLAB_OPTION_INT || d->type == BVHLAB_OPTION_FLOAT))
		n = (size_t)snprintf(buf, size, " in [%.15g, %.15g]", d->min, d->max);
	if (d->choices && n < size && (d->type == BVHLAB_OPTION_STRING ||
	                               (d->type == BVHLAB_OPTION_INT &&
	                                bvhlab_builder_int_choices(desc))))
		snprintf(buf + n, size - n, " (one of %s)", d->choices);
}

static int wrong_type(const struct config *cfg, const struct config_builder *b,
                      const bvhlab_options *opts, const cJSON *m, const cJSON *v,
                      const char *expected, bvhlab_error *err)
{
	char got[48], also[160];
	const bvhlab_builder *desc = opts->builder;
	allowed(desc, &desc->options[bvhlab_options_find(opts, m->string)], also, sizeof(also));
	return config_error(cfg, v, true, err,
	                    "builder '%s': option '%s' of plugin '%s' must be %s%s, not %s",
	                    b->name, m->string, desc->name, expected, also,
	                    config_describe(cfg, v, got, sizeof(got)));
}

/* 0 when the JSON value v of member m fits the declared type; *i gets an INT's value. */
static int check_type(const struct config *cfg, const struct config_builder *b,
                      const bvhlab_options *opts, const cJSON *m, const cJSON *v,
                      uint32_t type, int64_t *i, bvhlab_error *err)
{
	switch (type) {
	case BVHLAB_OPTION_BOOL:
		return cJSON_IsBool(v) ? 0 : wrong_type(cfg, b, opts, m, v, "true or false", err);
	case BVHLAB_OPTION_INT:
		switch (cJSON_IsNumber(v) ? json_get_int64(cfg->locations, v, i) : -EINVAL) {
		case 0:
			return 0;
		case -ERANGE:
			return wrong_type(cfg, b, opts, m, v, "an integer that fits in 64 bits", err);
		default:
			return wrong_type(cfg, b, opts, m, v, "an integer", err);
		}
	case BVHLAB_OPTION_FLOAT:
		if (!cJSON_IsNumber(v) || !isfinite(v->valuedouble))
			return wrong_type(cfg, b, opts, m, v, "a finite number", err);
		return 0;
	case BVHLAB_OPTION_STRING:
		return cJSON_IsString(v) ? 0 : wrong_type(cfg, b, opts, m, v, "a string", err);
	default:
		return config_error(cfg, m, true, err, "builder '%s': option '%s' has no valid type (%u)",
		                    b->name, m->string, type);
	}
}

static int set_value(bvhlab_options *opts, const char *key, const cJSON *v, uint32_t type,
                     int64_t i, bvhlab_error *err)
{
	switch (type) {
	case BVHLAB_OPTION_BOOL:
		return bvhlab_options_set_bool(opts, key, cJSON_IsTrue(v), err);
	case BVHLAB_OPTION_INT:
		return bvhlab_options_set_int(opts, key, i, err);
	case BVHLAB_OPTION_FLOAT:
		return bvhlab_options_set_float(opts, key, v->valuedouble, err);
	default:
		return bvhlab_options_set_string(opts, key, v->valuestring, err);
	}
}

/* A grid value's error also says which element of the grid it is. */
static int grid_note(int rc, const cJSON *m, size_t index, bvhlab_error *err)
{
	char old[sizeof(err->message)];
	if (!rc || index == SIZE_MAX)
		return rc;
	memcpy(old, err->message, sizeof(old));
	error_set(err, "%s (options.%s.grid[%zu])", old, m->string, index);
	return rc;
}

int config_apply_options(const struct config *cfg, const struct config_builder *b,
                         bvhlab_options *opts, bvhlab_error *err)
{
	for (const cJSON *m = b->options ? b->options->child : NULL; m; m = m->next) {
		int index = bvhlab_options_find(opts, m->string);
		if (index < 0)
			return unknown_option(cfg, b, opts, m, err);
		size_t at;
		const cJSON *v = config_grid_value(b, m, &at);
		uint32_t type = opts->builder->options[index].type;
		int64_t i = 0;
		int rc = check_type(cfg, b, opts, m, v, type, &i, err);
		if (rc)
			return grid_note(rc, m, at, err);
		/* The setter's message (range, choices) gets the position and the name. */
		bvhlab_error inner = { "" };
		rc = set_value(opts, m->string, v, type, i, &inner);
		if (rc) {
			config_error(cfg, v, true, err, "builder '%s': %s", b->name, inner.message);
			return grid_note(rc, m, at, err);
		}
	}
	bvhlab_error inner = { "" };
	if (bvhlab_options_check(opts, &inner) < 0)
		return config_error(cfg, b->options, true, err, "builder '%s': %s", b->name,
		                    inner.message);
	return 0;
}
