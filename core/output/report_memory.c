/*
 * A scene's memory per triangle (report.md and report.html): for each run
 * with a memory figure, the builds' own peak, the same with the scene they
 * read (the figure a memory budget is held against), the whole child's
 * peak resident set, each divided by the scene's triangles; the scene's own
 * share (vertices, indices, primitive boxes and centroids) is stated once.
 */
#include <math.h>
#include <stdio.h>

#include "output/report.h"

/* Its columns: results.json's memory keys and their heads. */
static const char *const columns[][2] = {
	{"memory.build_bytes_per_triangle", "build"},
	{"memory.with_scene_bytes_per_triangle", "build + scene"},
	{"memory.child_bytes_per_triangle", "whole child"},
};
#define COLUMNS (sizeof(columns) / sizeof(columns[0]))

static bool has_memory(const cJSON *run)
{
	return isfinite(report_num(run, "memory.child_bytes_per_triangle"));
}

/* The scene's share, from the first run that states it; NaN if none does. */
static double scene_share(const cJSON *const *runs, size_t n, double *bytes)
{
	for (size_t k = 0; k < n; k++)
		if (has_memory(runs[k])) {
			*bytes = report_num(runs[k], "memory.scene_bytes");
			return report_num(runs[k], "memory.scene_bytes_per_triangle");
		}
	return NAN;
}

static const char intro[] =
	"Bytes per triangle at the peak: what the builds added to the resident set "
	"(build), that with the scene's own arrays (build + scene), and the whole "
	"run's child (its code and libraries too). The scene's arrays (vertices, "
	"indices, primitive boxes and centroids) are %.1f bytes per triangle "
	"(%.1f MiB).";

void report_memory_md(struct strbuf *sb, const cJSON *const *runs, size_t n)
{
	double bytes = 0, share = scene_share(runs, n, &bytes);
	char buf[64];
	if (isnan(share))
		return;
	sb_printf(sb, "\n### Memory per triangle\n\n");
	sb_printf(sb, intro, share, bytes / 1048576.0);
	sb_printf(sb, "\n\n| builder | threads |");
	for (size_t c = 0; c < COLUMNS; c++)
		sb_printf(sb, " %s B/tri |", columns[c][1]);
	sb_printf(sb, "\n|---|---:|---:|---:|---:|\n");
	for (size_t k = 0; k < n; k++) {
		if (!has_memory(runs[k]))
			continue;
		sb_printf(sb, "|");
		report_md_cell(sb, report_str(runs[k], "builder"));
		snprintf(buf, sizeof(buf), "%.0f", report_num(runs[k], "threads"));
		report_md_cell(sb, report_on_device(runs[k]) ? "device" : buf);
		for (size_t c = 0; c < COLUMNS; c++) {
			double v = report_num(runs[k], columns[c][0]);
			snprintf(buf, sizeof(buf), "%.1f", v);
			report_md_cell(sb, isfinite(v) ? buf : "");
		}
		sb_printf(sb, "\n");
	}
}

void report_memory_html(struct strbuf *sb, const cJSON *const *runs, size_t n)
{
	double bytes = 0, share = scene_share(runs, n, &bytes);
	if (isnan(share))
		return;
	sb_printf(sb, "<h3>Memory per triangle</h3>\n<p>");
	sb_printf(sb, intro, share, bytes / 1048576.0);
	sb_printf(sb, "</p>\n<table class=\"runs memory\"><tr><th class=\"l\">builder</th>"
	              "<th>threads</th>");
	for (size_t c = 0; c < COLUMNS; c++)
		sb_printf(sb, "<th>%s B/tri</th>", columns[c][1]);
	sb_printf(sb, "</tr>\n");
	for (size_t k = 0; k < n; k++) {
		if (!has_memory(runs[k]))
			continue;
		sb_printf(sb, "<tr><td class=\"l\">");
		report_escape(sb, report_str(runs[k], "builder"));
		if (report_on_device(runs[k]))
			sb_printf(sb, "</td><td>device</td>");
		else
			sb_printf(sb, "</td><td>%.0f</td>", report_num(runs[k], "threads"));
		for (size_t c = 0; c < COLUMNS; c++) {
			double v = report_num(runs[k], columns[c][0]);
			if (isfinite(v))
				sb_printf(sb, "<td>%.1f</td>", v);
			else
				sb_printf(sb, "<td></td>");
		}
		sb_printf(sb, "</tr>\n");
	}
	sb_printf(sb, "</table>\n");
}
