/*
 * Sweeps split across machines (private to the core and the command):
 * the runs of a config with stable ids, plan.json, and joining the
 * results folders of a plan's parts into one.
 *
 * A run's id is its position in the order `bvhlab run` takes the runs:
 * scenes outermost, then builders (grids expanded), then the builder's
 * thread counts as configured. Ids depend on the config alone, never on
 * the machine (threads 0 stays 0 until a run resolves it).
 */
#ifndef BVHLAB_CORE_PLAN_H
#define BVHLAB_CORE_PLAN_H

#include <stdbool.h>
#include <stddef.h>
#include <stdint.h>

#include <bvhlab/types.h>

#include "config/config.h"

struct cJSON;

/* ---- runs (plan_runs.c) ------------------------------------------------------ */

struct plan_run {
	uint32_t id;
	size_t scene, builder; /* indexes into the config's arrays */
	uint32_t threads;      /* as configured: 0 = all cores of the machine that runs it */
};

/* The builder's thread counts: its own list or the config's. */
const uint32_t *plan_builder_threads(const struct config *cfg, const struct config_builder *b,
                                     size_t *count);
/*
 * A run's thread count is resolved once, when the run list is made: 0
 * becomes this machine's hardware threads. plan_check_threads refuses
 * (-EINVAL, err naming the list and "duplicate thread count N") a list in
 * which 0 resolves to a count it already has; plan_resolve_threads checks
 * and then resolves every list of cfg in place (ids do not change).
 */
int plan_check_threads(const struct config *cfg, bvhlab_error *err);
int plan_resolve_threads(struct config *cfg, bvhlab_error *err);
size_t plan_run_count(const struct config *cfg);
/* The id of scene x builder x thread_index. */
uint32_t plan_run_id(const struct config *cfg, size_t scene, size_t builder,
                     size_t thread_index);
/* Every run in id order; *runs is malloc'd ([plan_run_count]). */
int plan_runs(const struct config *cfg, struct plan_run **runs, size_t *count);

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
 * Writes DIR/plan.json for a loaded config: the config with every path
 * made absolute, its hash, the source file's hash and the run list. An
 * existing plan.json is kept when it is the same plan and refused (-EEXIST,
 * err naming it) when it is another. *plan is filled as plan_file_load would.
 */
int plan_file_write(const struct config *cfg, const char *dir, struct plan_file *plan,
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

/* ---- scene files (plan_scenes.c) ------------------------------------------- */

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
 * plan, or claiming a run another part has; refuses a results.json in dir
 * that is not an earlier merge of the same plan.
 */
int plan_merge(const struct plan_file *plan, const char *const *parts, size_t part_count,
               const char *dir, struct merge_summary *sum, bvhlab_error *err);
void merge_summary_finish(struct merge_summary *sum);

/*
 * The ids each part folder under parts_dir holds a finished run of
 * ((*done)[id] true), for `plan --missing`. Folders without results.json
 * hold none; one of another plan is an error.
 */
int plan_done_runs(const struct plan_file *plan, const char *parts_dir, bool **done,
                   bvhlab_error *err);

#endif
