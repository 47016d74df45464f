/*
 * Experiment configs (private to the core and the bvhlab command).
 *
 * A config is plain JSON (README.md, "Experiment configs"; every key is
 * declared once, in config_keys.c). Loading checks
 * the syntax and every key and type; errors read
 *   FILE:LINE:COLUMN: message naming the key
 * Builder options are checked later, against the plugin's declarations,
 * by config_apply_options, with the same FILE:LINE:COLUMN prefix.
 */
#ifndef BVHLAB_CORE_CONFIG_H
#define BVHLAB_CORE_CONFIG_H

#include <stdbool.h>
#include <stddef.h>
#include <stdint.h>

#include <bvhlab/host.h>
#include <bvhlab/trace.h>
#include <bvhlab/scene.h>

struct cJSON;
struct json_locations;

struct config_part;
struct config_mesh;
struct config_instance;

/* What a scene's or part's "deform" names (config_anim.c). */
enum config_deform { CONFIG_DEFORM_NONE, CONFIG_DEFORM_WAVE, CONFIG_DEFORM_EXPLODE };

/* How a scene or a composite's part moves over the scene's frames
 * (config_anim.c; docs/animation.md). */
struct config_motion {
	bool animate;          /* "animate" given: a rigid motion */
	double rotate[3];      /* "animate.rotate": degrees added by the last frame */
	double translate[3];   /* "animate.translate": offset reached by the last frame */
	double scale;          /* "animate.scale": factor reached by the last frame (1) */
	int deform;            /* "deform": enum config_deform */
	double amplitude;      /* "amplitude": a fraction of the mesh's extent; 0: default */
};

struct config_scene {
	char *name;        /* "name", default: file stem, generator name or "composite" */
	char *path;        /* "path" resolved against the config's folder, or NULL */
	char *generator;   /* "generator", or NULL; exactly one of path/generator/parts */
	bvhlab_gen_params gen; /* "frequency", "count", "size", "seed", "width" */
	uint32_t subdivide; /* "subdivide", default 0 */
	int line, column;  /* where the scene's object starts */
	struct config_part *parts; /* "parts" of a composite scene, or NULL */
	size_t part_count;
	/* A two-level scene (config_instances.c; docs/instances.md): its "meshes",
	 * each loaded once, and its "instances" placing them; NULL otherwise. */
	struct config_mesh *meshes;
	size_t mesh_count;
	struct config_instance *instances;
	size_t instance_count;   /* entries of "instances" (a scatter is one) */
	uint64_t instance_total; /* instances once every scatter is expanded */
	/* Animation (config_anim.c): "frames": N, or {"pattern", "count", "first"}. */
	uint32_t frames;     /* frames of the animation; 0: a static scene */
	char *frame_pattern; /* frame files, one %d conversion (resolved), or NULL */
	uint32_t frame_first; /* the number frame 0's file carries */
	struct config_motion motion; /* the whole scene's motion ("animate", "deform") */
	bool has_camera;   /* "camera" given: the scene's rays start there, not from
	                    * "rays"' camera or the framing */
	bvhlab_camera camera;
};

/* One entry of a composite scene's "parts": a mesh or generator (src, whose
 * name is unused) placed by "scale", "rotate" (degrees) and "translate". */
struct config_part {
	struct config_scene src;
	bvhlab_transform xf;
	struct config_motion motion; /* "animate", "deform", "amplitude" */
};

/* One of a two-level scene's "meshes": a source named for its instances. */
struct config_mesh {
	char *name;             /* "name", required, unique in the scene */
	struct config_scene src; /* path or generator (its name unused) */
};

/* How a scatter turns its instances: "rotate" "none" or "random-y". */
enum config_scatter_rotate { CONFIG_SCATTER_NONE, CONFIG_SCATTER_RANDOM_Y };

/* One entry of "instances": one placed mesh, or a "scatter" of many. */
struct config_instance {
	uint32_t mesh;       /* index into the scene's meshes ("mesh" names it) */
	double xf[12];       /* row-major 3x4 object-to-world matrix: "matrix", or
	                      * "scale", "rotate", "translate" as a composite part's */
	bool scatter;        /* "scatter": {...}: the fields below, xf unused */
	uint32_t count;      /* "count": instances, 1 .. CONFIG_MAX_INSTANCES */
	uint64_t seed;       /* "seed", default 1 */
	double lo[3], hi[3]; /* "bounds": [[x, y, z], [x, y, z]] the positions are drawn in */
	double scale[2];     /* "scale": [a, b], 0 < a <= b, drawn uniformly; default [1, 1] */
	int rotate;          /* "rotate": enum config_scatter_rotate, default none */
	struct config_motion motion; /* "animate" (config_anim.c): a rigid motion over
	                      * the scene's frames, turning about the instance's own
	                      * origin (each of a scatter's); docs/instances.md */
};

/* Most instances a scene may hold, all entries and scatters together: the
 * top level's primitive ids are 32 bits, and a 16 M-instance scene is far
 * beyond what the two-level experiments need. */
#define CONFIG_MAX_INSTANCES (UINT32_C(1) << 24)

/* One refinement stage of a builder (config_refine.c). */
struct config_refine {
	char *plugin;      /* "plugin": a refining plugin's name or a path to a .so */
	const struct cJSON *options; /* "options" object (may be NULL), owned by root */
	int line, column;  /* where the stage's object starts */
};

/* Most stages in one builder's "refine" list. */
#define CONFIG_MAX_REFINE 8

/* A builder's strategy on an animated scene, "animation" (config_anim.c):
 * frames after the first are updated by `update` (then refined by the
 * stages), and rebuilt every rebuild_every frames; no "animation": every
 * frame is rebuilt. Owned by the config (shared by a grid's builders). */
struct config_animation {
	char *update;      /* "update": a plugin with an update function (ABI 1.4) */
	uint32_t rebuild_every; /* "rebuild_every": K > 0 rebuilds frames K, 2K, ...; 0: never */
	struct config_refine *refine; /* "refine": stages after each update, or NULL */
	size_t refine_count;
	bool allow_static; /* "allow_static", default false: the builder may run on the
	                    * config's static scenes (as a plain build); without it a
	                    * static scene beside an animation is a config error */
	struct config_animation *next_owned; /* the config's list, for freeing */
};

struct config_builder {
	char *plugin;      /* "plugin": a name on the search path or a path to a .so */
	char *name;        /* "name", default: plugin, then "+stage" per refine stage */
	uint32_t *threads; /* "threads" override, or NULL for the config's list */
	size_t thread_count;
	double timeout_s;  /* "timeout_s" override, or 0 for the config's */
	uint64_t memory_limit_mb; /* "memory_limit_mb" override, or 0 for the config's */
	const struct cJSON *options; /* "options" object (may be NULL), owned by root */
	bool optional;     /* "optional", default false: a plugin that is not there (not
	                    * built, say) drops the builder from the sweep instead of
	                    * failing its runs */
	struct config_refine *refine; /* "refine": stages applied in order after the
	                               * build, or NULL */
	size_t refine_count;
	int line, column;  /* where the builder's object starts */
	const struct config_animation *animation; /* "animation", or NULL: rebuild */
	/* A two-level builder (docs/instances.md): "bottom" (the plugin above,
	 * building one tree per mesh, with "options") and "top", a plugin that
	 * builds over boxes (BVHLAB_BUILDER_BOXES) with "top_options"; NULL
	 * for a one-level builder. Two-level scenes only. */
	char *top;
	const struct cJSON *top_options; /* "top_options" object (may be NULL), owned by root */
	/* An option grid's builder (config_grid.c): the value it takes of each grid. */
	struct config_grid_pick *picks;
	size_t pick_count;
	/* "scenes" (config_filter.c): the names of the scenes it runs on, each
	 * one of the config's, an array owned by root; NULL: every scene. */
	const struct cJSON *scenes;
};

/* One option of a grid builder: {"grid": [...]} under member, value the chosen element. */
struct config_grid_pick {
	const struct cJSON *member;
	const struct cJSON *value;
	size_t index;
};

/* The kinds of rays a run is measured with ("rays": "kinds"): primary from
 * the camera; from their hits diffuse bounces (closest hit), shadow rays
 * toward a point light and short ambient-occlusion rays (both any hit). */
enum ray_kind { RAY_PRIMARY, RAY_DIFFUSE, RAY_SHADOW, RAY_AO, RAY_KINDS };
#define RAY_KINDS_DEFAULT (1u << RAY_PRIMARY | 1u << RAY_DIFFUSE)
#define DEFAULT_AO_LENGTH 0.05

/* "primary", "diffuse", "shadow", "ao" (the keys of results.json's rays);
 * NULL for another value. (config.c) */
const char *ray_kind_name(int kind);
/* Whether a kind's rays are any-hit (occlusion) rays. */
static inline bool ray_kind_any(int kind)
{
	return kind == RAY_SHADOW || kind == RAY_AO;
}

struct config {
	char *path;        /* the file as given */
	char *dir;         /* its folder: relative paths resolve against it */
	char *text;        /* file contents */
	struct cJSON *root;
	struct json_locations *locations;

	int format_version; /* "format_version", must be 1 */
	char *output;      /* "output" resolved against dir; default "results" */
	uint32_t repeat;   /* "repeat", default 5, >= 1 */
	uint32_t warmup;   /* "warmup", default 1 */
	uint32_t *threads; /* "threads", default [1]; 0 = all hardware threads */
	size_t thread_count;
	bool validate;     /* "validate", default true */
	uint32_t validate_rays; /* "validate_rays", default 256 */
	uint32_t ray_width, ray_height, ray_diffuse; /* "rays": width/height/diffuse,
	                                              * default 256, 256, 1 */
	uint32_t ray_threads; /* "rays": "threads", default 1; 0 = all hardware threads */
	double ray_min_ms; /* "rays": "min_ms", default 200: each batch repeated this long */
	uint32_t ray_rounds; /* "rays": "rounds", default 8: min_ms is spread over this many
	                      * slices, interleaved over a scene's trees (1: each run's
	                      * batches timed in one stretch in its own child) */
	unsigned ray_traversals; /* "rays": "traversal" wide|stack|stackless|both or an array
	                          * of names, default wide: bit (1 << enum
	                          * bvhlab_traversal) per traversal */
	int ray_traversal; /* the main one (stack for "both", the first of an array) */
	unsigned ray_kinds; /* "rays": "kinds", an array of ray_kind names, default
	                     * ["primary", "diffuse"]: bit (1 << enum ray_kind) per kind
	                     * measured; primary always (the others start at its hits) */
	float ray_light[3]; /* "rays": "light", the shadow rays' point light */
	bool has_light;     /* "light" given; else bvhlab_light_frame of each scene */
	double ray_ao_length; /* "rays": "ao_length", the AO rays' length as a fraction of
	                       * the scene's diagonal, default 0.05 */
	char *ray_device; /* "rays": "device", the cl_ traversals' OpenCL device spec
	                   * (auto|gpu|cpu|P:D); NULL: auto */
	char *report_reference; /* "report": {"reference"}, default "sah_seq": a builder
	                         * name or, failing that, a plugin name */
	bool has_camera;   /* "rays": {"camera": ...} given; else framed per scene */
	bvhlab_camera camera;
	bool images;       /* "images", default false */
	bool isolate;      /* "isolate", default true: each run's builds in a child process */
	bool pin;          /* "pin", default false: host->pin_thread binds builder threads
	                    * to distinct physical cores */
	double timeout_s;  /* "timeout_s", default 600: an isolated run is killed after it */
	uint64_t memory_limit_mb; /* "memory_limit_mb", default 0 = none: the child's RLIMIT_AS */
	uint64_t rays_per_frame; /* "rays_per_frame", default 1000000: the rays an animated
	                          * scene's frame is costed for (cost_ms) */
	struct config_animation *animations; /* the builders' "animation"s, owned */

	struct config_scene *scenes;
	size_t scene_count;
	struct config_builder *builders;
	size_t builder_count;
};

/* Reads and checks a config file. On error err holds FILE:LINE:COLUMN: ... */
int config_load(struct config *cfg, const char *path, bvhlab_error *err);

/* Same, from text already in memory; `path` is used for messages and dir. */
int config_parse(struct config *cfg, const char *path, const char *text, bvhlab_error *err);

void config_finish(struct config *cfg);

/*
 * Applies a builder's "options" to opts (initialised from the plugin's
 * declarations). Unknown keys, wrong types and bad values are errors with
 * FILE:LINE:COLUMN of the offending key and the builder's name.
 */
int config_apply_options(const struct config *cfg, const struct config_builder *b,
                         bvhlab_options *opts, bvhlab_error *err);

/* The most threads a run may ask for, in a config or on the command line:
 * beyond any machine this runs on, and small enough that a plugin's
 * per-thread arrays stay reasonable. */
#define CONFIG_MAX_THREADS 1024
/*
 * The value a builder gives an option member: the member itself, or for a
 * grid option {"grid": [...]} the element this builder was expanded with.
 * *index gets its position in the grid (SIZE_MAX for a plain value).
 */
const struct cJSON *config_grid_value(const struct config_builder *b,
                                      const struct cJSON *member, size_t *index);
/* Same for the options of stage k of the builder's "refine" list. */
int config_apply_refine_options(const struct config *cfg, const struct config_builder *b,
                                size_t k, bvhlab_options *opts, bvhlab_error *err);

/* Stage k of a builder's "animation.refine" (config_anim.c), like
 * config_apply_refine_options. */
int config_apply_anim_refine_options(const struct config *cfg, const struct config_builder *b,
                                     size_t k, bvhlab_options *opts, bvhlab_error *err);
/*
 * Puts a builder's error in the form every config error has,
 * FILE:LINE:COLUMN: builder 'NAME': message (the builder's object, or the
 * refine stage k's when k < b->refine_count), unless the message already
 * starts with the config's path (config_apply_options' do).
 */
void config_locate_builder_error(const struct config *cfg, const struct config_builder *b,
                                 size_t stage, bvhlab_error *err);

/* Whether builder b runs on scene sc: its "scenes" names it, or it has
 * none (config_filter.c). The run list (plan_runs.c) asks, and nothing
 * else decides it. */
bool config_builder_runs_on(const struct config_builder *b, const struct config_scene *sc);

/* Replaces the thread list (command line --threads). */
int config_set_threads(struct config *cfg, const uint32_t *threads, size_t count);

#endif /* BVHLAB_CORE_CONFIG_H */
