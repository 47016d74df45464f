/*
 * Helpers shared by config.c, config_keys.c, config_check.c and
 * config_entries.c. Every
 * error is -EINVAL (or -ENOMEM) with err->message starting FILE:LINE:COL.
 * `prefix` arguments name the enclosing object for messages ("",
 * "rays.", "scenes[2]."); `where` says the same in words ("at the top
 * level", "in scenes[2]").
 */
#ifndef BVHLAB_CORE_CONFIG_INTERNAL_H
#define BVHLAB_CORE_CONFIG_INTERNAL_H

#include <stdbool.h>
#include <stddef.h>
#include <stdint.h>

#include <cJSON.h>

#include "config/config.h"
#include "util/util.h"

/* Long enough for "builders[18446744073709551615]." and the like. */
#define CONFIG_NAME_SIZE 64

/* "FILE:LINE:COL: message" at the item's key (at_key) or value; -EINVAL. */
int config_error(const struct config *cfg, const cJSON *item, bool at_key,
                 bvhlab_error *err, const char *fmt, ...) UTIL_PRINTF(5, 6);

/* "a string", "2.5", "true", "null", "an array", "an object". */
const char *config_describe(const struct config *cfg, const cJSON *item, char *buf,
                            size_t size);

/* Closest name within edit distance 2 (transpositions count 1), if any. */
struct config_suggestion {
	const char *best;
	int distance;
};
void config_suggest_init(struct config_suggestion *s);
void config_suggest_consider(struct config_suggestion *s, const char *typed,
                             const char *candidate);

/* What a key's value must be, and how it is read (config_keys.c). */
enum config_kind {
	CONFIG_CUSTOM,   /* read by its own code; in the table so it is known */
	CONFIG_U32,      /* an integer in [min, max] into a uint32_t */
	CONFIG_U64,      /* an integer in [min, max] into a uint64_t */
	CONFIG_BOOL,     /* true or false into a bool */
	CONFIG_POSITIVE, /* a finite number > 0 into a double */
	CONFIG_STRING,   /* a non-empty string, copied into a char * */
	CONFIG_THREADS,  /* distinct thread counts into a uint32_t * and a size_t */
	CONFIG_VEC3,     /* an array of 3 finite numbers into a float[3] */
};

/* Flags of a key. */
enum {
	CONFIG_GENERATED = 1u << 0, /* a scene key for generators only, not with a 'path' */
};

/* One key of a config object. Tables end with a NULL name. */
struct config_key {
	const char *name;
	enum config_kind kind;
	uint64_t min, max;   /* CONFIG_U32, CONFIG_U64: inclusive range */
	size_t offset;       /* the field the value goes to, in the object's struct */
	size_t count_offset; /* CONFIG_THREADS: the field the count goes to */
	unsigned flags;
};

/* The keys of the top level, "rays", a scene, a builder and "rays.camera",
 * in the order they are listed in messages and read. */
extern const struct config_key config_top_keys[];   /* struct config */
extern const struct config_key config_ray_keys[];   /* struct config */
extern const struct config_key config_report_keys[]; /* struct config */
extern const struct config_key config_scene_keys[]; /* struct config_scene */
extern const struct config_key config_part_keys[];  /* struct config_part */
extern const struct config_key config_mesh_keys[];  /* struct config_mesh */
extern const struct config_key config_instance_keys[]; /* read by config_instances.c */
extern const struct config_key config_scatter_keys[]; /* struct config_instance */
extern const struct config_key config_builder_keys[]; /* struct config_builder */
extern const struct config_key config_camera_keys[]; /* bvhlab_camera */
extern const struct config_key config_refine_keys[]; /* struct config_refine */

/* Reads every key of the table present in obj into base (the table's
 * struct), in table order; CONFIG_CUSTOM keys are left to the caller. */
int config_read_keys(const struct config *cfg, const cJSON *obj,
                     const struct config_key *table, const char *prefix, void *base,
                     bvhlab_error *err);

/* Unknown keys (not in the table) and duplicate keys of obj. */
int config_check_keys(const struct config *cfg, const cJSON *obj,
                      const struct config_key *table, const char *where, bvhlab_error *err);
int config_check_duplicates(const struct config *cfg, const cJSON *obj, const char *where,
                            bvhlab_error *err);

/* The member `key` of obj (exact case), or NULL. */
const cJSON *config_member(const cJSON *obj, const char *key);

/* Typed members; an absent key leaves *out untouched and returns 0. */
int config_get_uint(const struct config *cfg, const cJSON *obj, const char *key,
                    const char *prefix, uint64_t min, uint64_t max, uint64_t *out,
                    bvhlab_error *err);
int config_get_u32(const struct config *cfg, const cJSON *obj, const char *key,
                   const char *prefix, uint32_t min, uint32_t max, uint32_t *out,
                   bvhlab_error *err);
int config_get_bool(const struct config *cfg, const cJSON *obj, const char *key,
                    const char *prefix, bool *out, bvhlab_error *err);
/* A finite number > 0 (a duration, say). */
int config_get_positive(const struct config *cfg, const cJSON *obj, const char *key,
                        const char *prefix, double *out, bvhlab_error *err);
/* A non-empty string, copied into *out (freeing what was there). */
int config_get_string(const struct config *cfg, const cJSON *obj, const char *key,
                      const char *prefix, char **out, bvhlab_error *err);
/* A [x, y, z] array of finite numbers (magnitude <= 1e30) into out; absent
 * keeps out. */
int config_get_dvec3(const struct config *cfg, const cJSON *obj, const char *key,
                     const char *prefix, double out[3], bvhlab_error *err);
/* The same into floats. */
int config_get_vec3(const struct config *cfg, const cJSON *obj, const char *key,
                    const char *prefix, float out[3], bvhlab_error *err);
/* A non-empty array of distinct thread counts (0 = all hardware threads). */
int config_get_threads(const struct config *cfg, const cJSON *obj, const char *key,
                       const char *prefix, uint32_t **out, size_t *count,
                       bvhlab_error *err);

/* `path` as seen from the config's folder (absolute paths unchanged). */
int config_resolve(const struct config *cfg, const char *path, char **out);
/* The file name without folder and last extension ("a/b/ogre.obj" -> "ogre"). */
char *config_stem(const char *path);

/* Highest "memory_limit_mb": the limit in bytes must fit in 64 bits. */
#define CONFIG_MAX_MEMORY_MB (UINT64_MAX >> 20)

/* "rays": {"camera": {position, target, up, fov}}; absent: automatic framing. */
int config_parse_camera(struct config *cfg, const cJSON *rays, bvhlab_error *err);
/* scenes[index]'s own "camera", if any, into sc (config_camera.c). */
int config_parse_scene_camera(const struct config *cfg, const cJSON *scene, size_t index,
                              struct config_scene *sc, bvhlab_error *err);
int config_parse_scenes(struct config *cfg, bvhlab_error *err);
/* After its table's keys are read: a scene's (or a part's) one source,
 * without generator parameters (the table's CONFIG_GENERATED keys) for a
 * file. */
int config_scene_source(struct config *cfg, const cJSON *obj, const char *prefix,
                        const struct config_key *table, struct config_scene *sc,
                        bvhlab_error *err);
/* "parts" of the composite scene obj (config_parts.c); freed in config_finish. */
int config_parse_parts(struct config *cfg, const cJSON *obj, const char *prefix,
                       struct config_scene *sc, bvhlab_error *err);
void config_parts_free(struct config_scene *sc);
/* A scene's own source keys ("path", "generator", generator parameters)
 * beside "parts" or "meshes" (what) would be ignored: an error saying to
 * give them to `to` ("a part"). */
int config_no_own_source(struct config *cfg, const cJSON *obj, const char *prefix,
                         const char *what, const char *to, bvhlab_error *err);
/* "meshes" and "instances" of the two-level scene obj (config_instances.c);
 * freed in config_finish by config_instances_free. */
int config_parse_instances(struct config *cfg, const cJSON *obj, const char *prefix,
                           struct config_scene *sc, bvhlab_error *err);
void config_instances_free(struct config_scene *sc);
int config_parse_builders(struct config *cfg, bvhlab_error *err);
/* Expands builders with {"grid": [...]} option values into one builder per
 * combination, named "NAME[key=value,...]" (config_grid.c); `array` is the
 * config's "builders" array, one element per builder before expansion. */
int config_expand_grids(struct config *cfg, const cJSON *array, bvhlab_error *err);
/* builders[index]'s "refine" list (config_refine.c); without a "name",
 * "+PLUGIN" of each stage is appended to the builder's name. */
int config_parse_refine(struct config *cfg, const cJSON *obj, size_t index,
                        struct config_builder *b, bvhlab_error *err);
void config_refine_finish(struct config_builder *b);
/* Animation (config_anim.c): a scene's "frames" (before its source is
 * checked: a frame pattern gives the path), the motion keys of a scene or
 * part, a builder's "animation"; freed in config_finish. */
int config_parse_frames(struct config *cfg, const cJSON *obj, const char *prefix,
                        struct config_scene *sc, bvhlab_error *err);
int config_parse_motion(struct config *cfg, const cJSON *obj, const char *prefix,
                        struct config_motion *m, bvhlab_error *err);
int config_check_scene_anim(struct config *cfg, const cJSON *obj, const char *prefix,
                            const struct config_scene *sc, bvhlab_error *err);
/* Stage k of `stages` (a builder's "refine" or its animation's, `kind`
 * naming which) through config_apply_options (config_refine.c). */
int config_apply_stage_options(const struct config *cfg, const struct config_builder *b,
                               const struct config_refine *stages, const char *kind, size_t k,
                               bvhlab_options *opts, bvhlab_error *err);
int config_parse_animation(struct config *cfg, const cJSON *obj, size_t index,
                           struct config_builder *b, bvhlab_error *err);
void config_anim_finish(struct config *cfg);
/* An animation on a static scene the builder runs on would be ignored,
 * silently: an error unless its "allow_static" says that is meant. After
 * the builder's "scenes" (config_parse_builder_scenes). */
int config_check_static_scenes(struct config *cfg, const cJSON *obj, size_t index,
                               const struct config_builder *b, bvhlab_error *err);
/* builders[index]'s "scenes" (config_filter.c): a non-empty array of the
 * config's scene names, none twice, into b->scenes; then a two-level
 * builder's scenes must all be two-level. After the builder's name is
 * final, which its messages use. */
int config_parse_builder_scenes(struct config *cfg, const cJSON *obj, size_t index,
                                struct config_builder *b, bvhlab_error *err);

#endif /* BVHLAB_CORE_CONFIG_INTERNAL_H */
