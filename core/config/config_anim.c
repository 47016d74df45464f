/*
 * Animated scenes in configs (docs/animation.md): a scene's "frames" (a
 * count, or frame files {"pattern", "count", "first"}), the motion of a
 * scene or of a composite's part ("animate": {"rotate", "translate",
 * "scale"}, "deform": "wave" | "explode", "amplitude"), the top level's
 * "rays_per_frame" (a table key) and a builder's strategy over the frames,
 * "animation": {"update", "rebuild_every", "refine", "allow_static"}.
 */
#include <errno.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "config/config_internal.h"

/* More frames than anyone would time; keeps per-run reports bounded. */
#define MAX_FRAMES 100000

static int out_of_memory(const struct config *cfg, bvhlab_error *err)
{
	error_set(err, "%s: out of memory", cfg->path);
	return -ENOMEM;
}

/* The one conversion of a frame pattern: %d, %Nd or %0Nd, nothing else
 * but %%. */
static bool pattern_ok(const char *p)
{
	int conversions = 0;
	for (; *p; p++) {
		if (*p != '%')
			continue;
		if (p[1] == '%') {
			p++;
			continue;
		}
		p++;
		while (*p >= '0' && *p <= '9')
			p++;
		if (*p != 'd')
			return false;
		conversions++;
	}
	return conversions == 1;
}

static int frames_object(struct config *cfg, const cJSON *item, const char *prefix,
                         struct config_scene *sc, bvhlab_error *err)
{
	static const struct config_key keys[] = {
		{"pattern", CONFIG_CUSTOM, 0, 0, 0, 0, 0}, {"count", CONFIG_CUSTOM, 0, 0, 0, 0, 0},
		{"first", CONFIG_CUSTOM, 0, 0, 0, 0, 0}, {NULL, CONFIG_CUSTOM, 0, 0, 0, 0, 0}};
	char sub[CONFIG_NAME_SIZE + 8], where[CONFIG_NAME_SIZE + 16];
	snprintf(sub, sizeof(sub), "%sframes.", prefix);
	snprintf(where, sizeof(where), "in %sframes", prefix);
	int rc = config_check_keys(cfg, item, keys, where, err);
	if (!rc)
		rc = config_get_string(cfg, item, "pattern", sub, &sc->frame_pattern, err);
	if (!rc)
		rc = config_get_u32(cfg, item, "count", sub, 1, MAX_FRAMES, &sc->frames, err);
	if (!rc)
		rc = config_get_u32(cfg, item, "first", sub, 0, 1000000000, &sc->frame_first, err);
	if (rc)
		return rc;
	if (!sc->frame_pattern || !sc->frames)
		return config_error(cfg, item, false, err, "'%sframes' needs a 'pattern' (a file "
		                    "name with one %%d) and a 'count'", prefix);
	if (!pattern_ok(sc->frame_pattern))
		return config_error(cfg, config_member(item, "pattern"), false, err,
		                    "'%sframes.pattern' must hold exactly one %%d (or %%0Nd), not "
		                    "'%s'", prefix, sc->frame_pattern);
	return 0;
}

/* The pattern resolved against the config; frame 0's file becomes the
 * scene's path when it has no source of its own. That path is taken from
 * the pattern as written: the scene's path is resolved once, with the
 * scene (a resolved one would be resolved again, sub/sub/...). */
static int pattern_paths(struct config *cfg, const cJSON *obj, const char *prefix,
                         struct config_scene *sc, bvhlab_error *err)
{
	char *resolved, first[4096];
	if (config_member(obj, "generator") || config_member(obj, "parts"))
		return config_error(cfg, config_member(obj, "frames"), true, err,
		                    "'%sframes' with a 'pattern' takes its frames from files: not "
		                    "with a 'generator' or 'parts'", prefix);
	if (!sc->path) {
		snprintf(first, sizeof(first), sc->frame_pattern, (int)sc->frame_first);
		if (!(sc->path = strdup(first)))
			return out_of_memory(cfg, err);
	}
	if (config_resolve(cfg, sc->frame_pattern, &resolved))
		return out_of_memory(cfg, err);
	size_t head = strlen(resolved) - strlen(sc->frame_pattern);
	free(sc->frame_pattern);
	sc->frame_pattern = util_pattern_folder(resolved, head);
	return sc->frame_pattern ? 0 : out_of_memory(cfg, err);
}

int config_parse_frames(struct config *cfg, const cJSON *obj, const char *prefix,
                        struct config_scene *sc, bvhlab_error *err)
{
	const cJSON *item = config_member(obj, "frames");
	char got[48];
	int rc;
	if (!item)
		return config_parse_motion(cfg, obj, prefix, &sc->motion, err);
	if (cJSON_IsObject(item)) {
		rc = frames_object(cfg, item, prefix, sc, err);
		return rc ? rc : pattern_paths(cfg, obj, prefix, sc, err);
	}
	if (!cJSON_IsNumber(item) || item->valuedouble != floor(item->valuedouble) ||
	    item->valuedouble < 1 || item->valuedouble > MAX_FRAMES)
		return config_error(cfg, item, false, err, "'%sframes' must be a whole number of "
		                    "frames from 1 to %d or {\"pattern\", \"count\"}, not %s", prefix,
		                    MAX_FRAMES, config_describe(cfg, item, got, sizeof(got)));
	sc->frames = (uint32_t)item->valuedouble;
	return config_parse_motion(cfg, obj, prefix, &sc->motion, err);
}

static int parse_animate(struct config *cfg, const cJSON *item, const char *prefix,
                         struct config_motion *m, bvhlab_error *err)
{
	static const struct config_key keys[] = {
		{"rotate", CONFIG_CUSTOM, 0, 0, 0, 0, 0}, {"translate", CONFIG_CUSTOM, 0, 0, 0, 0, 0},
		{"scale", CONFIG_CUSTOM, 0, 0, 0, 0, 0}, {NULL, CONFIG_CUSTOM, 0, 0, 0, 0, 0}};
	char sub[2 * CONFIG_NAME_SIZE + 8], where[2 * CONFIG_NAME_SIZE + 16], got[48];
	snprintf(sub, sizeof(sub), "%sanimate.", prefix);
	snprintf(where, sizeof(where), "in %sanimate", prefix);
	if (!cJSON_IsObject(item))
		return config_error(cfg, item, false, err, "'%sanimate' must be an object "
		                    "{\"rotate\", \"translate\", \"scale\"}, not %s", prefix,
		                    config_describe(cfg, item, got, sizeof(got)));
	m->animate = true;
	m->scale = 1;
	int rc = config_check_keys(cfg, item, keys, where, err);
	if (!rc)
		rc = config_get_dvec3(cfg, item, "rotate", sub, m->rotate, err);
	if (!rc)
		rc = config_get_dvec3(cfg, item, "translate", sub, m->translate, err);
	if (!rc)
		rc = config_get_positive(cfg, item, "scale", sub, &m->scale, err);
	return rc;
}

int config_parse_motion(struct config *cfg, const cJSON *obj, const char *prefix,
                        struct config_motion *m, bvhlab_error *err)
{
	const cJSON *animate = config_member(obj, "animate"), *deform = config_member(obj, "deform");
	char got[48];
	m->scale = 1;
	if (animate) {
		int rc = parse_animate(cfg, animate, prefix, m, err);
		if (rc)
			return rc;
	}
	if (deform && cJSON_IsString(deform) && strcmp(deform->valuestring, "wave") == 0)
		m->deform = CONFIG_DEFORM_WAVE;
	else if (deform && cJSON_IsString(deform) && strcmp(deform->valuestring, "explode") == 0)
		m->deform = CONFIG_DEFORM_EXPLODE;
	else if (deform && cJSON_IsString(deform))
		return config_error(cfg, deform, false, err, "'%sdeform' must be \"wave\" or "
		                    "\"explode\", not \"%.40s\"", prefix, deform->valuestring);
	else if (deform)
		return config_error(cfg, deform, false, err, "'%sdeform' must be \"wave\" or "
		                    "\"explode\", not %s", prefix,
		                    config_describe(cfg, deform, got, sizeof(got)));
	if (m->amplitude > 0 && !m->deform)
		return config_error(cfg, config_member(obj, "amplitude"), true, err,
		                    "'%samplitude' applies to a 'deform' only", prefix);
	return 0;
}

static bool moves(const struct config_motion *m)
{
	return m->animate || m->deform;
}

/* Motion needs frames to happen in, and frame files bring their own. */
int config_check_scene_anim(struct config *cfg, const cJSON *obj, const char *prefix,
                            const struct config_scene *sc, bvhlab_error *err)
{
	bool any = moves(&sc->motion);
	if (any && sc->parts)
		return config_error(cfg, obj, false, err, "'%.*s' has 'parts': give 'animate' or "
		                    "'deform' to the parts that move", (int)strlen(prefix) - 1, prefix);
	for (size_t i = 0; i < sc->part_count; i++)
		any = any || moves(&sc->parts[i].motion);
	for (size_t i = 0; !sc->frames && i < sc->instance_count; i++)
		if (sc->instances[i].motion.animate)
			return config_error(cfg, obj, false, err, "'%sinstances[%zu]%s.animate': the "
			                    "scene has no 'frames' for its instances to move in", prefix,
			                    i, sc->instances[i].scatter ? ".scatter" : "");
	if (any && !sc->frames)
		return config_error(cfg, obj, false, err, "'%.*s' moves ('animate' or 'deform') but "
		                    "has no 'frames'", (int)strlen(prefix) - 1, prefix);
	if (any && sc->frame_pattern)
		return config_error(cfg, config_member(obj, "frames"), true, err,
		                    "'%.*s' takes its frames from files: no 'animate' or 'deform' "
		                    "with them", (int)strlen(prefix) - 1, prefix);
	return 0;
}

/* ---- a builder's "animation" -------------------------------------------------- */

static int append(char **name, const char *what)
{
	size_t size = strlen(*name) + strlen(what) + 1;
	char *s = malloc(size);
	if (!s)
		return -ENOMEM;
	snprintf(s, size, "%s%s", *name, what);
	free(*name);
	*name = s;
	return 0;
}

/* "lbvh+refit+reinsert[rebuild_every=8]" for a builder without "name". */
static int anim_name(struct config_builder *b, const struct config_animation *a,
                     const char *stage_names)
{
	char every[48] = "";
	if (a->rebuild_every)
		snprintf(every, sizeof(every), "[rebuild_every=%u]", a->rebuild_every);
	int rc = append(&b->name, "+");
	if (!rc)
		rc = append(&b->name, a->update);
	if (!rc)
		rc = append(&b->name, stage_names);
	return rc ? rc : append(&b->name, every);
}

static int anim_body(struct config *cfg, const cJSON *item, size_t index,
                     struct config_animation *a, char **stage_names, bvhlab_error *err)
{
	static const struct config_key keys[] = {
		{"update", CONFIG_CUSTOM, 0, 0, 0, 0, 0}, {"rebuild_every", CONFIG_CUSTOM, 0, 0, 0, 0, 0},
		{"refine", CONFIG_CUSTOM, 0, 0, 0, 0, 0}, {"allow_static", CONFIG_CUSTOM, 0, 0, 0, 0, 0},
		{NULL, CONFIG_CUSTOM, 0, 0, 0, 0, 0}};
	char sub[CONFIG_NAME_SIZE + 16], where[CONFIG_NAME_SIZE + 24];
	struct config_builder stages = {.name = strdup("")};
	snprintf(sub, sizeof(sub), "builders[%zu].animation.", index);
	snprintf(where, sizeof(where), "in builders[%zu].animation", index);
	int rc = stages.name ? config_check_keys(cfg, item, keys, where, err) : -ENOMEM;
	if (!rc)
		rc = config_get_string(cfg, item, "update", sub, &a->update, err);
	if (!rc)
		rc = config_get_u32(cfg, item, "rebuild_every", sub, 1, MAX_FRAMES, &a->rebuild_every,
		                    err);
	if (!rc)
		rc = config_get_bool(cfg, item, "allow_static", sub, &a->allow_static, err);
	if (!rc && !a->update)
		rc = config_error(cfg, item, false, err, "'builders[%zu].animation' needs an 'update' "
		                  "(a plugin with an update function, such as \"refit\")", index);
	/* The stages read like a builder's "refine" (names appended to a blank). */
	if (!rc)
		rc = config_parse_refine(cfg, item, index, &stages, err);
	a->refine = stages.refine;
	a->refine_count = stages.refine_count;
	*stage_names = stages.name;
	return rc == -ENOMEM ? out_of_memory(cfg, err) : rc;
}

int config_check_static_scenes(struct config *cfg, const cJSON *obj, size_t index,
                               const struct config_builder *b, bvhlab_error *err)
{
	const struct config_animation *a = b->animation;
	const cJSON *item = config_member(obj, "animation");
	for (size_t s = 0; a && !a->allow_static && s < cfg->scene_count; s++)
		if (!cfg->scenes[s].frames && config_builder_runs_on(b, &cfg->scenes[s]))
			return config_error(cfg, item, false, err, "'builders[%zu].animation': scene "
			                    "'%s' (scenes[%zu]) is static (no 'frames'), where the "
			                    "animation would be ignored: give the scene 'frames', leave "
			                    "it out of the builder's \"scenes\", or set \"allow_static\": "
			                    "true to run this builder on static scenes as a plain build",
			                    index, cfg->scenes[s].name, s);
	return 0;
}

int config_parse_animation(struct config *cfg, const cJSON *obj, size_t index,
                           struct config_builder *b, bvhlab_error *err)
{
	const cJSON *item = config_member(obj, "animation");
	char got[48], *stage_names = NULL;
	if (!item)
		return 0;
	if (!cJSON_IsObject(item))
		return config_error(cfg, item, false, err, "'builders[%zu].animation' must be an "
		                    "object {\"update\", \"rebuild_every\", \"refine\"}, not %s", index,
		                    config_describe(cfg, item, got, sizeof(got)));
	struct config_animation *a = calloc(1, sizeof(*a));
	if (!a)
		return out_of_memory(cfg, err);
	a->next_owned = cfg->animations; /* owned from here on, whatever follows */
	cfg->animations = a;
	b->animation = a;
	int rc = anim_body(cfg, item, index, a, &stage_names, err);
	if (!rc && b->top && a->refine_count)
		rc = config_error(cfg, config_member(item, "refine"), true, err,
		                  "'builders[%zu].animation.refine': a two-level builder's top is "
		                  "rebuilt or updated without refinement stages (not yet)", index);
	if (!rc && !config_member(obj, "name") && anim_name(b, a, stage_names) < 0)
		rc = out_of_memory(cfg, err);
	free(stage_names);
	return rc;
}

void config_anim_finish(struct config *cfg)
{
	while (cfg->animations) {
		struct config_animation *a = cfg->animations;
		struct config_builder stages = {.refine = a->refine, .refine_count = a->refine_count};
		cfg->animations = a->next_owned;
		config_refine_finish(&stages);
		free(a->update);
		free(a);
	}
}

int config_apply_anim_refine_options(const struct config *cfg, const struct config_builder *b,
                                     size_t k, bvhlab_options *opts, bvhlab_error *err)
{
	return config_apply_stage_options(cfg, b, b->animation->refine, "animation refine stage",
	                                  k, opts, err);
}
