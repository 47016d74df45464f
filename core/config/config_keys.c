/*
 * Every config key, declared once: its name, JSON type, range and the field
 * it fills. One table per object (the top level, "rays", a scene, a
 * builder, "rays.camera") drives both the unknown-key check (config_check_keys, with its
 * did-you-mean) and the reading (config_read_keys), in the table's order.
 * A key whose value needs more than a typed read (an object, the list of
 * scenes, a path resolved later) is CONFIG_CUSTOM: declared here so it is
 * known, read by config.c or config_entries.c after the table's keys.
 * A new key is one line here and one field in config.h.
 */
#include <stddef.h>
#include <stdint.h>

#include "config/config_internal.h"

/* Image sides beyond this are mistakes, and width * height stays far from 2^32. */
#define MAX_RAY_SIDE 16384
#define MAX_DIFFUSE 1024
#define MAX_RAY_THREADS 1024
#define MAX_RAY_ROUNDS 1000
/* 16 subdivisions turn one triangle into 4^16 = 2^32, past a uint32_t count. */
#define MAX_SUBDIVIDE 15

#define KEY(type, name, kind, field, min, max, flags) \
	{ name, kind, min, max, offsetof(type, field), 0, flags }
#define CUSTOM(name) { name, CONFIG_CUSTOM, 0, 0, 0, 0, 0 }
#define THREADS(type, name, field, count) \
	{ name, CONFIG_THREADS, 0, UINT32_MAX, offsetof(type, field), offsetof(type, count), 0 }
#define END { NULL, CONFIG_CUSTOM, 0, 0, 0, 0, 0 }

#define TOP(name, kind, field, min, max) KEY(struct config, name, kind, field, min, max, 0)
const struct config_key config_top_keys[] = {
	CUSTOM("format_version"),
	TOP("output", CONFIG_STRING, output, 0, 0),
	TOP("repeat", CONFIG_U32, repeat, 1, UINT32_MAX),
	TOP("warmup", CONFIG_U32, warmup, 0, UINT32_MAX),
	THREADS(struct config, "threads", threads, thread_count),
	TOP("validate", CONFIG_BOOL, validate, 0, 0),
	TOP("validate_rays", CONFIG_U32, validate_rays, 1, UINT32_MAX),
	CUSTOM("rays"),
	TOP("images", CONFIG_BOOL, images, 0, 0),
	TOP("isolate", CONFIG_BOOL, isolate, 0, 0),
	TOP("timeout_s", CONFIG_POSITIVE, timeout_s, 0, 0),
	TOP("memory_limit_mb", CONFIG_U64, memory_limit_mb, 1, CONFIG_MAX_MEMORY_MB),
	TOP("pin", CONFIG_BOOL, pin, 0, 0),
	TOP("rays_per_frame", CONFIG_U64, rays_per_frame, 1, UINT64_C(1000000000000)),
	CUSTOM("report"),
	CUSTOM("scenes"),
	CUSTOM("builders"),
	END,
};

const struct config_key config_ray_keys[] = {
	TOP("width", CONFIG_U32, ray_width, 1, MAX_RAY_SIDE),
	TOP("height", CONFIG_U32, ray_height, 1, MAX_RAY_SIDE),
	TOP("diffuse", CONFIG_U32, ray_diffuse, 0, MAX_DIFFUSE),
	CUSTOM("camera"),
	TOP("threads", CONFIG_U32, ray_threads, 0, MAX_RAY_THREADS),
	TOP("min_ms", CONFIG_POSITIVE, ray_min_ms, 0, 0),
	TOP("rounds", CONFIG_U32, ray_rounds, 1, MAX_RAY_ROUNDS),
	CUSTOM("traversal"), /* a name, "both" or an array of names: config.c */
	TOP("device", CONFIG_STRING, ray_device, 0, 0), /* checked in config.c */
	CUSTOM("kinds"), /* an array of ray kind names: config.c */
	TOP("light", CONFIG_VEC3, ray_light, 0, 0),
	TOP("ao_length", CONFIG_POSITIVE, ray_ao_length, 0, 0),
	END,
};

const struct config_key config_report_keys[] = {
	TOP("reference", CONFIG_STRING, report_reference, 0, 0),
	END,
};

#define SCENE(name, kind, field, min, max, flags) \
	KEY(struct config_scene, name, kind, field, min, max, flags)
const struct config_key config_scene_keys[] = {
	SCENE("name", CONFIG_STRING, name, 0, 0, 0),
	SCENE("path", CONFIG_STRING, path, 0, 0, 0),
	SCENE("generator", CONFIG_STRING, generator, 0, 0, 0),
	CUSTOM("parts"), /* a composite scene: config_parts.c */
	CUSTOM("meshes"), /* a two-level scene: config_instances.c */
	CUSTOM("instances"),
	SCENE("frequency", CONFIG_U32, gen.frequency, 1, UINT32_MAX, CONFIG_GENERATED),
	SCENE("count", CONFIG_U32, gen.count, 1, UINT32_MAX, CONFIG_GENERATED),
	SCENE("size", CONFIG_U32, gen.size, 1, UINT32_MAX, CONFIG_GENERATED),
	SCENE("seed", CONFIG_U64, gen.seed, 0, UINT64_MAX, CONFIG_GENERATED),
	SCENE("width", CONFIG_POSITIVE, gen.width, 0, 0, CONFIG_GENERATED),
	SCENE("subdivide", CONFIG_U32, subdivide, 0, MAX_SUBDIVIDE, 0),
	CUSTOM("frames"),  /* animation: config_anim.c */
	CUSTOM("animate"),
	CUSTOM("deform"),
	SCENE("amplitude", CONFIG_POSITIVE, motion.amplitude, 0, 0, 0),
	CUSTOM("camera"), /* the scene's own view: config_camera.c */
	END,
};

/* The keys that say where a part's or a mesh's triangles come from: both
 * structs keep them in a `src` (a struct config_scene). */
#define SOURCE_KEYS(K) \
	K("path", CONFIG_STRING, src.path, 0, 0, 0), \
	K("generator", CONFIG_STRING, src.generator, 0, 0, 0), \
	K("frequency", CONFIG_U32, src.gen.frequency, 1, UINT32_MAX, CONFIG_GENERATED), \
	K("count", CONFIG_U32, src.gen.count, 1, UINT32_MAX, CONFIG_GENERATED), \
	K("size", CONFIG_U32, src.gen.size, 1, UINT32_MAX, CONFIG_GENERATED), \
	K("seed", CONFIG_U64, src.gen.seed, 0, UINT64_MAX, CONFIG_GENERATED), \
	K("width", CONFIG_POSITIVE, src.gen.width, 0, 0, CONFIG_GENERATED), \
	K("subdivide", CONFIG_U32, src.subdivide, 0, MAX_SUBDIVIDE, 0)

/* One of a composite scene's "parts": a scene's source keys, and where it goes. */
#define PART(name, kind, field, min, max, flags) \
	KEY(struct config_part, name, kind, field, min, max, flags)
const struct config_key config_part_keys[] = {
	SOURCE_KEYS(PART),
	PART("scale", CONFIG_POSITIVE, xf.scale, 0, 0, 0),
	CUSTOM("rotate"),    /* degrees, doubles: config_parts.c */
	CUSTOM("translate"),
	CUSTOM("animate"), /* animation: config_anim.c */
	CUSTOM("deform"),
	PART("amplitude", CONFIG_POSITIVE, motion.amplitude, 0, 0, 0),
	END,
};

/* One of a two-level scene's "meshes": a name and a scene's source keys. */
#define MESH(name, kind, field, min, max, flags) \
	KEY(struct config_mesh, name, kind, field, min, max, flags)
const struct config_key config_mesh_keys[] = {
	MESH("name", CONFIG_STRING, name, 0, 0, 0),
	SOURCE_KEYS(MESH),
	END,
};

/* What an instance and a scatter both name: the mesh they place, its
 * scale and its rotation (one instance's values, or a scatter's range and
 * rule: config_instances.c). */
#define PLACEMENT_KEYS CUSTOM("mesh"), CUSTOM("scale"), CUSTOM("rotate")

/* One of a two-level scene's "instances": a mesh placed by a matrix or by a
 * part's keys, or a "scatter" of many (config_instances.c). */
const struct config_key config_instance_keys[] = {
	PLACEMENT_KEYS,
	CUSTOM("translate"),
	CUSTOM("matrix"),
	CUSTOM("scatter"),
	CUSTOM("animate"),
	END,
};

#define SCATTER(name, kind, field, min, max) \
	KEY(struct config_instance, name, kind, field, min, max, 0)
const struct config_key config_scatter_keys[] = {
	PLACEMENT_KEYS,
	SCATTER("count", CONFIG_U32, count, 1, CONFIG_MAX_INSTANCES),
	SCATTER("seed", CONFIG_U64, seed, 0, UINT64_MAX),
	CUSTOM("bounds"),
	CUSTOM("animate"),
	END,
};

#define BUILDER(name, kind, field, min, max) \
	KEY(struct config_builder, name, kind, field, min, max, 0)
const struct config_key config_builder_keys[] = {
	BUILDER("plugin", CONFIG_STRING, plugin, 0, 0),
	BUILDER("name", CONFIG_STRING, name, 0, 0),
	THREADS(struct config_builder, "threads", threads, thread_count),
	BUILDER("timeout_s", CONFIG_POSITIVE, timeout_s, 0, 0),
	BUILDER("memory_limit_mb", CONFIG_U64, memory_limit_mb, 1, CONFIG_MAX_MEMORY_MB),
	CUSTOM("options"),
	BUILDER("optional", CONFIG_BOOL, optional, 0, 0),
	CUSTOM("refine"), /* config_refine.c */
	CUSTOM("animation"), /* config_anim.c */
	CUSTOM("bottom"), /* a two-level builder: config_entries.c */
	BUILDER("top", CONFIG_STRING, top, 0, 0),
	CUSTOM("top_options"),
	CUSTOM("scenes"), /* the scenes it runs on: config_filter.c */
	END,
};

#define STAGE(name, kind, field) KEY(struct config_refine, name, kind, field, 0, 0, 0)
const struct config_key config_refine_keys[] = {
	STAGE("plugin", CONFIG_STRING, plugin),
	CUSTOM("options"),
	END,
};

#define CAMERA(name, kind, field) KEY(bvhlab_camera, name, kind, field, 0, 0, 0)
const struct config_key config_camera_keys[] = {
	CAMERA("position", CONFIG_VEC3, position),
	CAMERA("target", CONFIG_VEC3, target),
	CAMERA("up", CONFIG_VEC3, up),
	CUSTOM("fov"), /* a float below 180 degrees: config_camera.c */
	END,
};

/* Reads one key into its field; an absent key leaves the field as it is. */
static int read_key(const struct config *cfg, const cJSON *obj, const struct config_key *k,
                    const char *prefix, void *base, bvhlab_error *err)
{
	char *field = (char *)base + k->offset;
	switch (k->kind) {
	case CONFIG_U32:
		return config_get_u32(cfg, obj, k->name, prefix, (uint32_t)k->min, (uint32_t)k->max,
		                      (uint32_t *)(void *)field, err);
	case CONFIG_U64:
		return config_get_uint(cfg, obj, k->name, prefix, k->min, k->max,
		                       (uint64_t *)(void *)field, err);
	case CONFIG_BOOL:
		return config_get_bool(cfg, obj, k->name, prefix, (bool *)(void *)field, err);
	case CONFIG_POSITIVE:
		return config_get_positive(cfg, obj, k->name, prefix, (double *)(void *)field, err);
	case CONFIG_STRING:
		return config_get_string(cfg, obj, k->name, prefix, (char **)(void *)field, err);
	case CONFIG_THREADS:
		return config_get_threads(cfg, obj, k->name, prefix, (uint32_t **)(void *)field,
		                          (size_t *)(void *)((char *)base + k->count_offset), err);
	case CONFIG_VEC3:
		return config_get_vec3(cfg, obj, k->name, prefix, (float *)(void *)field, err);
	case CONFIG_CUSTOM:
		break;
	}
	return 0;
}

int config_read_keys(const struct config *cfg, const cJSON *obj,
                     const struct config_key *table, const char *prefix, void *base,
                     bvhlab_error *err)
{
	int rc = 0;
	for (const struct config_key *k = table; k->name && !rc; k++)
		rc = read_key(cfg, obj, k, prefix, base, err);
	return rc;
}
