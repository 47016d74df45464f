/*
 * Reading a results document for the reports (report_doc.c): values by
 * dotted path, the machine a run was measured on, and the small text
 * forms every rendering shares. The renderers (report*.c) only read the
 * document through these, so none of them depends on another's helpers.
 */
#ifndef BVHLAB_CORE_REPORT_DOC_H
#define BVHLAB_CORE_REPORT_DOC_H

#include <stdbool.h>
#include <stddef.h>

#include <cJSON.h>

#include "util/util.h"

/* The member at a dotted path ("build_ms.median"), or NULL. */
const cJSON *report_at(const cJSON *o, const char *path);
/* The string at path, or "". */
const char *report_str(const cJSON *o, const char *path);
/* The number at path, or NaN. */
double report_num(const cJSON *o, const char *path);

/* A two-level scene's counts, ", N instances of M meshes (U unique
 * triangles, I instanced)", or nothing for a one-level scene. */
void report_scene_instances(struct strbuf *sb, const cJSON *scene);

/* The machine a run was measured on: its own "machine" (a merged sweep's
 * runs carry their part's), else the document's. */
const cJSON *report_machine(const cJSON *doc, const cJSON *run);
/* Whether two machine objects name the same machine (hostname, CPU and
 * cores); two absent ones count as the same. */
bool report_same_machine(const cJSON *a, const cJSON *b);

/* The colour scale (nodes per ray, *lo to *hi) the run's heat map was drawn
 * with: its own "heat_scale" (a merged sweep's parts each drew theirs),
 * else the scene's; false when neither is known. */
bool report_heat_scale(const cJSON *scene, const cJSON *run, double *lo, double *hi);
/* Whether the scene's heat maps were not all drawn on one scale (a merged
 * sweep's parts), so each map must be read against its own. */
bool report_heat_scales_differ(const cJSON *scene, const cJSON *const *runs, size_t n);

/* Text with & < > " ' escaped for HTML and SVG. */
void report_escape(struct strbuf *sb, const char *text);
/* v with `decimals`, or "not measured" for NaN (a figure absent or null).
 * Returns buf. */
const char *report_figure(char *buf, size_t size, double v, int decimals);
/* A run's build_phases as "upload 1.50, device 2.50" ("" when none). */
const char *report_phases(char *buf, size_t size, const cJSON *run);
/* Whether some run has build_phases (the tables then add their column). */
bool report_any_phases(const cJSON *const *runs, size_t n);
/* Text for Markdown: & < > as entities (no raw HTML passes), pipes
 * escaped, newlines and other control characters as spaces. */
void report_md_text(struct strbuf *sb, const char *text);
/* "bvhlab VERSION, CREATED. Machine: CPU": the reports' first line, its
 * values through `text` (report_md_text or report_escape). */
void report_byline(struct strbuf *sb, const cJSON *doc,
                   void (*text)(struct strbuf *sb, const char *text));
/* " text |": a Markdown table cell of report_md_text. */
void report_md_cell(struct strbuf *sb, const char *text);
/* A CSV field and its separator (',', or a newline when last): quoted
 * when it holds a separator, quote or newline; text a spreadsheet would
 * run as a formula (starting = + - @, not a number) quoted with a leading
 * '. Every CSV writer's cells go through here. */
void report_csv_field(struct strbuf *sb, const char *s, bool last);
/* A plain number with the decimals its size needs ("2140", "21.4", "2.14"),
 * never an exponent; "" for NaN. Returns buf. */
const char *report_plain(char *buf, size_t size, double v);

#endif
