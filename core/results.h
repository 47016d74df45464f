/*
 * results.json (DESIGN.md schema), results.csv and report.md of one output
 * folder. The document lives in memory as cJSON and every file is rewritten
 * through a temporary file and rename after each run, so an interrupted
 * sweep always leaves complete files with every finished run.
 */
#ifndef BVHLAB_CORE_RESULTS_H
#define BVHLAB_CORE_RESULTS_H

#include <stdbool.h>
#include <stdint.h>

#include <bvhlab/bvhlab.h>

#include "config.h"
#include "machine.h"

struct cJSON;

struct results {
	struct cJSON *doc;
	struct cJSON *scenes;
	struct cJSON *runs;
	char *dir;
};

/* Everything known about one run; fields beyond status are optional. */
struct run_record {
	const char *scene;
	const char *builder;   /* the config's label for the builder */
	const char *plugin;    /* the descriptor's name */
	uint32_t threads;      /* resolved thread count */
	const bvhlab_options *opts; /* resolved options, or NULL */
	const char *status;    /* "ok", "invalid", "failed", ... */
	const char *error;     /* message when status is not "ok", or NULL */
	const double *samples_ms;
	uint32_t sample_count; /* 0: no timing */
	uint32_t triangles;
	const bvhlab_tree_stats *stats; /* or NULL */
	bool validated;
	bool valid;
	uint64_t rays_checked, mismatches;
};

/* Creates the folder (and parents) and the document. */
int results_init(struct results *res, const struct config *cfg, const char *dir,
                 bvhlab_error *err);
void results_finish(struct results *res);

int results_add_scene(struct results *res, const char *name, const char *source,
                      uint32_t triangles, const char *error);
int results_add_run(struct results *res, const struct run_record *run);

/* Rewrites results.json, results.csv and report.md atomically. */
int results_write(const struct results *res, bvhlab_error *err);

/* Writes `text` to dir/name through dir/.name.tmp and rename. */
int results_write_file(const char *dir, const char *name, const char *text, bvhlab_error *err);

/* The CSV and Markdown renderings of a results document (malloc'd text). */
char *results_csv(const struct cJSON *doc);
char *report_markdown(const struct cJSON *doc);

#endif
