/*
 * Two-level runs in report.md and report.html (docs/instances.md): per
 * scene, each two-level builder's levels apart (plugins, build times,
 * nodes, SAH) and the whole's two-level SAH; then, where the scene also
 * ran flattened, each two-level run against the flat run of its bottom's
 * plugin at the same thread count: build time, tree memory and primary
 * Mrays/s, and what instancing costs in trace speed. The cells are made
 * once; each format only writes them.
 */
#include <math.h>
#include <stdio.h>
#include <string.h>

#include "output/report.h"

/* The levels' columns: key under "two_level", format. */
static const char *const columns[][2] = {
	{"bottom.build_ms", "%.3f"}, {"top.build_ms", "%.3f"}, {"build_ms", "%.3f"},
	{"bottom.trees", "%.0f"}, {"bottom.nodes", "%.0f"}, {"top.nodes", "%.0f"},
	{"bottom.sah_cost", "%.3f"}, {"top.sah_cost", "%.3f"}, {"sah_cost", "%.3f"},
};
#define COLUMNS (sizeof(columns) / sizeof(columns[0]))

static const char levels_intro[] =
	"Two-level builds (docs/instances.md): bottom build ms summed over the meshes (each "
	"mesh's median), top over the instances' boxes; SAH: the bottom trees' mean, the "
	"top's, and the two-level SAH of the whole; peak MiB: the run's child's peak resident "
	"set (builds, validation, tracing; memory.run_peak_rss_bytes).";
static const char *const levels_heads[] = {
	"builder", "threads", "bottom", "top", "bottom ms", "top ms", "sum ms", "meshes",
	"bottom nodes", "top nodes", "bottom SAH", "top SAH", "two-level SAH", "peak MiB"};

static const char flat_intro[] =
	"Two-level against flat: each two-level run beside the flattened scene's run of its "
	"bottom's plugin at the same thread count. Build ms: medians (the two-level one "
	"builds every mesh's tree and the top); tree MiB: every tree's nodes and indices; "
	"primary Mrays/s: the main traversal's (the two-level one at both levels, the same "
	"camera). Trace cost: how much slower instancing traces here.";
static const char *const flat_heads[] = {
	"two-level", "flat", "threads", "two-level ms", "flat ms", "two-level tree MiB",
	"flat tree MiB", "two-level Mrays/s", "flat Mrays/s", "trace cost"};
#define HEADS(h) (sizeof(h) / sizeof(h[0]))

/* One rendering's ways of writing a table (report_md_cell's or <td>s). */
struct table_format {
	void (*head)(struct strbuf *sb, const char *intro, const char *const *heads, size_t n);
	void (*row_start)(struct strbuf *sb);
	void (*cell)(struct strbuf *sb, const char *text);
	void (*row_end)(struct strbuf *sb);
	void (*end)(struct strbuf *sb);
};

static void cell_num(const struct table_format *f, struct strbuf *sb, const char *fmt, double v)
{
	char buf[64];
	snprintf(buf, sizeof(buf), fmt, v);
	f->cell(sb, isfinite(v) ? buf : "");
}

static void levels_row(const struct table_format *f, struct strbuf *sb, const cJSON *run)
{
	const cJSON *t = cJSON_GetObjectItemCaseSensitive(run, "two_level");
	f->row_start(sb);
	f->cell(sb, report_str(run, "builder"));
	cell_num(f, sb, "%.0f", report_num(run, "threads"));
	f->cell(sb, report_str(t, "bottom.plugin"));
	f->cell(sb, report_str(t, "top.plugin"));
	for (size_t k = 0; k < COLUMNS; k++)
		cell_num(f, sb, columns[k][1], report_num(t, columns[k][0]));
	cell_num(f, sb, "%.1f", report_num(run, "memory.run_peak_rss_bytes") / 1048576.0);
	f->row_end(sb);
}

static bool two_level(const cJSON *run)
{
	return cJSON_GetObjectItemCaseSensitive(run, "two_level") != NULL;
}

/* The ok flat run of the two-level run's bottom plugin at its thread
 * count, or NULL. */
static const cJSON *flat_twin(const cJSON *run, const cJSON *const *runs, size_t n)
{
	const char *plugin = report_str(run, "two_level.bottom.plugin");
	for (size_t k = 0; k < n; k++)
		if (!two_level(runs[k]) && !strcmp(report_str(runs[k], "status"), "ok") &&
		    !strcmp(report_str(runs[k], "plugin"), plugin) &&
		    report_num(runs[k], "threads") == report_num(run, "threads"))
			return runs[k];
	return NULL;
}

static void flat_row(const struct table_format *f, struct strbuf *sb, const cJSON *run,
                     const cJSON *flat)
{
	double mr = report_num(run, "rays.primary.mrays_per_s");
	double mf = report_num(flat, "rays.primary.mrays_per_s");
	char cost[64] = "";
	f->row_start(sb);
	f->cell(sb, report_str(run, "builder"));
	f->cell(sb, report_str(flat, "builder"));
	cell_num(f, sb, "%.0f", report_num(run, "threads"));
	cell_num(f, sb, "%.3f", report_num(run, "build_ms.median"));
	cell_num(f, sb, "%.3f", report_num(flat, "build_ms.median"));
	cell_num(f, sb, "%.2f", report_num(run, "tree.memory_bytes") / 1048576.0);
	cell_num(f, sb, "%.2f", report_num(flat, "tree.memory_bytes") / 1048576.0);
	cell_num(f, sb, "%.2f", mr);
	cell_num(f, sb, "%.2f", mf);
	if (mr > 0 && mf > 0)
		snprintf(cost, sizeof(cost), "%+.1f %%", 100.0 * (1.0 - mr / mf));
	f->cell(sb, cost);
	f->row_end(sb);
}

static void render(const struct table_format *f, struct strbuf *sb, const cJSON *const *runs,
                   size_t n)
{
	size_t shown = 0, pairs = 0;
	for (size_t k = 0; k < n; k++) {
		if (!two_level(runs[k]))
			continue;
		if (shown++ == 0)
			f->head(sb, levels_intro, levels_heads, HEADS(levels_heads));
		levels_row(f, sb, runs[k]);
	}
	if (shown)
		f->end(sb);
	for (size_t k = 0; k < n; k++) {
		const cJSON *flat = two_level(runs[k]) ? flat_twin(runs[k], runs, n) : NULL;
		if (!flat)
			continue;
		if (pairs++ == 0)
			f->head(sb, flat_intro, flat_heads, HEADS(flat_heads));
		flat_row(f, sb, runs[k], flat);
	}
	if (pairs)
		f->end(sb);
}

static void md_head(struct strbuf *sb, const char *intro, const char *const *heads, size_t n)
{
	sb_printf(sb, "\n%s\n\n|", intro);
	for (size_t k = 0; k < n; k++)
		sb_printf(sb, " %s |", heads[k]);
	sb_printf(sb, "\n|");
	for (size_t k = 0; k < n; k++) /* names left, figures right */
		sb_printf(sb, "%s|", k == 0 || !strcmp(heads[k], "bottom") || !strcmp(heads[k], "top") ||
		                     !strcmp(heads[k], "flat") ? "---" : "---:");
	sb_printf(sb, "\n");
}

static void md_row_start(struct strbuf *sb)
{
	sb_printf(sb, "|");
}

static void md_row_end(struct strbuf *sb)
{
	sb_printf(sb, "\n");
}

static void md_end(struct strbuf *sb)
{
	(void)sb;
}

void report_two_level_md(struct strbuf *sb, const cJSON *const *runs, size_t n)
{
	static const struct table_format md = {md_head, md_row_start, report_md_cell, md_row_end,
	                                       md_end};
	render(&md, sb, runs, n);
}

static void html_head(struct strbuf *sb, const char *intro, const char *const *heads, size_t n)
{
	sb_printf(sb, "<p>%s</p>\n<table class=\"runs two-level\"><tr>", intro);
	for (size_t k = 0; k < n; k++)
		sb_printf(sb, "<th>%s</th>", heads[k]);
	sb_printf(sb, "</tr>\n");
}

static void html_row_start(struct strbuf *sb)
{
	sb_printf(sb, "<tr>");
}

static void html_cell(struct strbuf *sb, const char *text)
{
	sb_printf(sb, "<td>");
	report_escape(sb, text);
	sb_printf(sb, "</td>");
}

static void html_row_end(struct strbuf *sb)
{
	sb_printf(sb, "</tr>\n");
}

static void html_end(struct strbuf *sb)
{
	sb_printf(sb, "</table>\n");
}

void report_two_level_html(struct strbuf *sb, const cJSON *const *runs, size_t n)
{
	static const struct table_format html = {html_head, html_row_start, html_cell,
	                                         html_row_end, html_end};
	render(&html, sb, runs, n);
}
