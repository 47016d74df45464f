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

/* Appends the thesis-style speedup tables (parallel builders against
 * sah_seq on 1 thread, per thread count > 1) to a report; nothing when the
 * document has no such runs. report_thesis.c. */
void report_thesis(struct strbuf *sb, const struct cJSON *doc);


/* The member at a dotted path ("build_ms.median"), or NULL. */
const cJSON *report_at(const cJSON *o, const char *path);
/* The string at path, or "". */
const char *report_str(const cJSON *o, const char *path);
/* The number at path, or NaN. */
double report_num(const cJSON *o, const char *path);
/* Build-time speedup of a run over the same builder's 1-thread run on
 * the same scene, or NaN when there is none. */
double report_speedup(const cJSON *runs, const cJSON *run);

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

#endif
