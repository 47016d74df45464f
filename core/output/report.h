/*
 * The renderings of a results document (results.csv, report.md,
 * report.html; results.c writes them) and the pieces they share: document
 * access and the inline SVG charts.
 */
#ifndef BVHLAB_CORE_REPORT_H
#define BVHLAB_CORE_REPORT_H

#include <stddef.h>

#include <cJSON.h>

#include "util/util.h"

/* The CSV and Markdown renderings of a results document (malloc'd text). */
char *report_csv(const struct cJSON *doc);
char *report_markdown(const struct cJSON *doc);
/* report.html: self-contained but for the PNGs it names (images/...). */
char *report_html(const struct cJSON *doc);


/* The member at a dotted path ("build_ms.median"), or NULL. */
const cJSON *report_at(const cJSON *o, const char *path);
/* The string at path, or "". */
const char *report_str(const cJSON *o, const char *path);
/* The number at path, or NaN. */
double report_num(const cJSON *o, const char *path);
/* A document's runs by scene, for rendering in time linear in their
 * number (report_index.c). */
struct report_slot;
struct report_index {
	struct report_slot *scenes, *pairs; /* open-addressed tables of cap slots */
	const cJSON **order;                /* every run, grouped by scene */
	size_t cap;
};

/* 0, or -ENOMEM (the index is then empty, and finishing it is safe). */
int report_index_init(struct report_index *ix, const cJSON *doc);
void report_index_finish(struct report_index *ix);
/* The scene's runs, in document order; *count 0 when it has none. */
const cJSON *const *report_scene_runs(const struct report_index *ix, const char *scene,
                                      size_t *count);
/* Build-time speedup of a run over the same builder's 1-thread run on
 * the same scene, or NaN when there is none. */
double report_speedup(const struct report_index *ix, const cJSON *run);

/* Appends the thesis-style speedup tables (parallel builders against
 * sah_seq on 1 thread, per thread count > 1) to a report; nothing when the
 * document has no such runs. ix: the document's runs by scene.
 * report_thesis.c. */
void report_thesis(struct strbuf *sb, const struct cJSON *doc, const struct report_index *ix);

/* A section listing the machines the runs come from, when there are several
 * (a merged sweep; report_machines.c); nothing otherwise. */
void report_machines_md(struct strbuf *sb, const cJSON *doc);
void report_machines_html(struct strbuf *sb, const cJSON *doc);

/* A scene's animation section (report_frames.c): its runs' frames summed
 * up, the cheapest strategy, and in HTML SAH and cumulative cost over the
 * frames as charts; nothing for a scene without frames. */
void report_frames_md(struct strbuf *sb, const struct report_index *ix, const cJSON *scene);
void report_frames_html(struct strbuf *sb, const struct report_index *ix, const cJSON *scene);

/* Text with & < > " ' escaped for HTML and SVG. */
void report_escape(struct strbuf *sb, const char *text);

/* One point or bar: a label and its values. */
struct svg_point {
	const char *label;
	const char *group; /* lines: the series it belongs to */
	double x, y;
};

/* Horizontal bars of y, one per point, labelled. */
void svg_bars(struct strbuf *sb, const char *title, const char *unit,
              const struct svg_point *p, size_t n);
/* Points at (x, y), labelled, with axes named. */
void svg_scatter(struct strbuf *sb, const char *title, const char *xname, const char *yname,
                 const struct svg_point *p, size_t n);
/* One polyline per group, points in the given order. */
void svg_lines(struct strbuf *sb, const char *title, const char *xname, const char *yname,
               const struct svg_point *p, size_t n);

/* ---- the summary across scenes (report_summary.c) ------------------------ */

#define SUMMARY_METRICS 5 /* build time, SAH, EPO, primary and diffuse nodes/ray */

/* One builder x thread count: geometric means over scenes of its figures
 * relative to the reference builder's (NaN: no scene had both). */
struct summary_row {
	const char *builder; /* points into the document */
	double threads;
	int scenes;          /* scenes with ok runs of both */
	double ratio[SUMMARY_METRICS];
};

/* The rows (malloc'd, in run order) and the reference builder's label;
 * 0 rows (and *ref NULL) when the reference builder has no run. */
int report_summary(const cJSON *doc, struct summary_row **rows, const char **ref);
/* The column name of metric m. */
const char *report_summary_metric(int m);
/* The summary section of report.md / report.html. */
void report_summary_md(struct strbuf *sb, const cJSON *doc);
void report_summary_html(struct strbuf *sb, const cJSON *doc);

#endif
