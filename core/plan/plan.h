/*
 * Sweeps split across machines (private to the core and the command):
 * the runs of a config with stable ids, plan.json, and joining the
 * results folders of a plan's parts into one.
 *
 * A run's id is its position in the run list, the order `bvhlab run`
 * takes the runs: scenes outermost, then the builders that run on the
 * scene (grids expanded; a builder's "scenes" may leave it out), then
 * the builder's thread counts as configured, one for a serial builder. Ids
 * depend on the config and the builders' PARALLEL flags, never on the
 * machine's thread count.
 */
#ifndef BVHLAB_CORE_PLAN_H
#define BVHLAB_CORE_PLAN_H

#include <stdbool.h>
#include <stddef.h>
#include <stdint.h>

#include <bvhlab/types.h>

#include "config/config.h"
#include "output/results.h"

struct cJSON;

/* ---- the run list (plan_runs.c) ---------------------------------------------- */

/* What the run list needs of a config builder (harness_builders.c opens them). */
struct plan_builder {
	bool serial;              /* its plugin loaded without the PARALLEL flag */
	const char *options_hash; /* of its resolved options and stages, or NULL */
	const char *builder_hash; /* of builder_config, or NULL: not usable */
	const struct cJSON *builder_config; /* plugin, options, stages, animation as
	                                     * resolved (copied into the list) */
};

/* One run: its identity (results.h) and where it comes from in the config. */
struct plan_run {
	struct run_identity key;  /* id, scene, builder, threads, hashes, fragments */
	size_t scene, builder;    /* indexes into the config's arrays */
	uint32_t threads;         /* as configured: 0 = all cores of the machine */
	char hash[17];            /* key.hash's text */
};

/* The identity parts of a list's runs (plan_identity.c), by scene and builder. */
struct plan_identity {
	char (*scene_hash)[17], (*measure_hash)[17]; /* [scene_count] */
	struct cJSON **measure_config;               /* [scene_count] */
	char (*builder_hash)[17];                    /* [builder_count], "" when unusable */
	struct cJSON **builder_config;               /* [builder_count] */
};

/* A builder's thread counts in the list: configured, resolved, and which one
 * a serial builder runs at (the others are not applicable). */
struct plan_threads {
	const uint32_t *configured;
	uint32_t *resolved;       /* [count] */
	size_t count;
	bool serial;
	size_t first;             /* serial: the index of the one count it runs at */
};

struct run_list {
	const struct config *cfg;
	struct plan_run *runs;    /* [count], in id order */
	size_t count;
	size_t *scene_first;      /* [scene_count + 1]: scene s has runs [first[s], first[s + 1]) */
	struct plan_threads *threads; /* [builder_count] */
	struct plan_identity identity;
};

/* The builder's thread counts: its own list or the config's. */
const uint32_t *plan_builder_threads(const struct config *cfg, const struct config_builder *b,
                                     size_t *count);
/*
 * Refuses (-EINVAL, err naming the list and "duplicate thread count N") a
 * thread list of cfg in which 0 (all cores) resolves to a count it
 * already has: the two would be one run twice.
 */
int plan_check_threads(const struct config *cfg, bvhlab_error *err);
/*
 * The config's runs, made once: scenes outermost, then the builders that
 * run on the scene (config_builder_runs_on; grids expanded), then the
 * builder's thread counts as configured, ids from 0 in
 * that order. Thread counts are resolved here and nowhere else (0 becomes
 * this machine's hardware threads; plan_check_threads first). A builder
 * with `serial` runs once per scene, at the first of its counts that
 * resolves to 1 (else its first): its other counts are not in the list.
 * builders ([builder_count]) NULL: every builder parallel, no hashes.
 * 0, -EINVAL (err set) or -ENOMEM.
 */
int plan_list_make(struct run_list *list, const struct config *cfg,
                   const struct plan_builder *builders, bvhlab_error *err);
void plan_list_finish(struct run_list *list);
/* The scenes' and builders' hashes and fragments of list (its cfg set). */
int plan_identity_make(struct run_list *list, const struct plan_builder *builders);
/* A run's hashes and fragments into its key (after plan_identity_make). */
void plan_identity_key(struct run_list *list, struct plan_run *run);
void plan_identity_finish(struct run_list *list);
/* The run of scene x builder at its configured thread index, or NULL. */
const struct plan_run *plan_list_find(const struct run_list *list, size_t scene,
                                      size_t builder, size_t thread_index);
/* A builder's first run in scene s, or NULL (it does not run on s). */
const struct plan_run *plan_list_first(const struct run_list *list, size_t scene,
                                       size_t builder);

/*
 * "3,7,10-12" into a selection of ids: (*only)[id] is true for the chosen
 * ones. An id past the config's runs is an error naming it and the range.
 */
int plan_parse_only(const char *text, size_t run_count, bool **only, bvhlab_error *err);

/* 64-bit FNV-1a of text, as 16 hex digits. */
void plan_hash_text(const char *text, char out[17]);

/* ---- plan.json (plan_file.c) ------------------------------------------------- */

struct plan_file {
	char *path;          /* plan.json as given */
	char hash[17];       /* of the config copy: the plan's identity */
	char *source;        /* the config file planned from (absolute), or NULL */
	char source_hash[17];
	struct cJSON *doc;   /* the whole file */
	size_t run_count;
};

/*
 * Writes DIR/plan.json for a loaded config's run list: the config with
 * every path made absolute, its hash, the source file's hash and the runs
 * (threads as configured). An
 * existing plan.json is kept when it is the same plan and refused (-EEXIST,
 * err naming it) when it is another. *plan is filled as plan_file_load would.
 */
int plan_file_write(const struct run_list *list, const char *dir, struct plan_file *plan,
                    bvhlab_error *err);

/* The whole file's text (malloc'd); err names the file. */
int plan_read_file(const char *path, char **out, bvhlab_error *err);

/* Whether the file is a plan (has "bvhlab_plan") rather than a config. */
bool plan_file_detect(const char *path);

/*
 * Reads plan.json and checks it: its hash against its config copy (and
 * scene files' record), and the config file it was planned from against
 * the hash recorded then (changed: an error, -ESTALE; gone: fine, the copy
 * is complete). With cfg non-NULL, also parses the copy into it and checks
 * the scene files here against the record (plan_check_scene_files).
 */
int plan_file_load(struct plan_file *plan, const char *path, struct config *cfg,
                   bvhlab_error *err);
void plan_file_finish(struct plan_file *plan);
/* The run list made here against the plan's: the same runs under the same
 * ids, or -EINVAL with err saying where they part (plan again). */
int plan_check_list(const struct plan_file *plan, const struct run_list *list,
                    bvhlab_error *err);

/* ---- scene files (plan_scenes.c) ------------------------------------------- */

/* A file's size and 64-bit FNV-1a of its bytes. */
struct plan_fingerprint {
	double size;
	char hash[17];
};
/* 0, or a negative errno when the file cannot be read (-EINVAL: not a
 * regular file). */
int plan_fingerprint(const char *path, struct plan_fingerprint *fp);
/* What a scene file is to its scene, for messages: "" (its own path),
 * "part 2: " or "frame 3: ". */
typedef int (*plan_file_fn)(const char *path, const char *what, size_t k, void *ctx);
/* Calls fn for every file scene cs reads (its path, its parts' paths, every
 * frame file of its pattern), *k counting up; stops at fn's first non-zero. */
int plan_scene_each_file(const struct config_scene *cs, plan_file_fn fn, size_t *k, void *ctx);

/* "scene_files": [{"path", "size", "hash"}] of every file cfg's scenes
 * read (in config order; size and hash missing for one not readable here). */
struct cJSON *plan_scene_files(const struct config *cfg);
/* The files cfg (parsed from the plan) reads against the plan's record:
 * -ESTALE, err naming the file, when one here has other content. */
int plan_check_scene_files(const struct plan_file *plan, const struct config *cfg,
                           bvhlab_error *err);

/* ---- merging parts (plan_merge.c) ------------------------------------------- */

struct results;
/* "plan": {"hash", "runs"} in a results document: the results of (part of) a plan. */
int results_set_plan(struct results *res, const char *hash, size_t runs, bvhlab_error *err);

/* What a merge found, for the command to report. */
struct merge_summary {
	size_t runs, present;
	uint32_t *missing;   /* ids without a run in any part */
	size_t missing_count;
	uint32_t *not_ok;    /* ids of runs whose status is not "ok" */
	size_t not_ok_count;
	size_t machines;     /* distinct machines the runs come from */
};

/*
 * Joins the results folders `parts` of the plan into dir: results.json
 * (every part's runs as they are, in id order, each with its part's machine
 * record), results.csv, report.md, report.html and the images. Refuses
 * (-EINVAL, err naming the part) a part without results.json, of another
 * plan, or claiming a run another part has, or (unless mixed_versions) run
 * by another bvhlab_version than the first part; refuses a results.json in
 * dir that is not an earlier merge of the same plan. Each run keeps its
 * part's version, "merged.versions" lists the parts'.
 */
int plan_merge(const struct plan_file *plan, const char *const *parts, size_t part_count,
               const char *dir, bool mixed_versions, struct merge_summary *sum,
               bvhlab_error *err);
void merge_summary_finish(struct merge_summary *sum);

/* DIR/results.json parsed into *doc; -ENOENT when there is none, -EINVAL
 * (with err) when it is not a results document (plan_parts.c). */
int plan_part_read(const char *dir, struct cJSON **doc, bvhlab_error *err);
/* 0 when doc, read from part folder dir, was run from this plan; else
 * -EINVAL with err saying how to run it or which plan it came from. */
int plan_part_check(const struct plan_file *plan, const char *dir,
                    const struct cJSON *doc, bvhlab_error *err);
/* The plan hash a results document records, or NULL. */
const char *plan_part_hash(const struct cJSON *doc);

/*
 * The ids each part folder under parts_dir holds a finished run of
 * ((*done)[id] true), for `plan --missing`. Folders without results.json
 * hold none; one of another plan is an error.
 */
int plan_done_runs(const struct plan_file *plan, const char *parts_dir, bool **done,
                   bvhlab_error *err);

#endif
