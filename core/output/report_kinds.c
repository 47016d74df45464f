/*
 * The reports' "Rays by kind" table of a scene (report.md and
 * report.html): when some run measured shadow or ambient-occlusion rays
 * (rays.kinds), each run's primary, diffuse, shadow and AO rays by every
 * traversal it was traced with, one row per traversal. The any-hit kinds
 * stop at the first hit, so their Mrays/s is not comparable with the
 * closest-hit kinds', only with the same kind's on another tree.
 */
#include <math.h>
#include <stdio.h>

#include <bvhlab/trace.h>

#include "config/config.h"
#include "output/report.h"
#include "output/report_doc.h"

/* "rays.KIND.WHAT" for the main traversal, "rays.T.KIND.WHAT" for another. */
static double kind_num(const cJSON *run, const char *traversal, int kind, const char *what)
{
	char key[96];
	if (traversal)
		snprintf(key, sizeof(key), "rays.%s.%s.%s", traversal, ray_kind_name(kind), what);
	else
		snprintf(key, sizeof(key), "rays.%s.%s", ray_kind_name(kind), what);
	return report_num(run, key);
}

/* Which kinds some run measured, as bits; 0 when none measured shadow
 * or AO rays (the run table already says the rest). */
static unsigned scene_kinds(const cJSON *const *runs, size_t n)
{
	unsigned kinds = 0;
	for (size_t i = 0; i < n; i++)
		for (int kind = 0; kind < RAY_KINDS; kind++)
			kinds |= isfinite(kind_num(runs[i], NULL, kind, "mrays_per_s")) ? 1u << kind : 0;
	return kinds & (1u << RAY_SHADOW | 1u << RAY_AO) ? kinds : 0;
}

static void cell(struct strbuf *sb, bool html, double v, const char *fmt)
{
	char buf[64] = "";
	if (isfinite(v))
		snprintf(buf, sizeof(buf), fmt, v);
	if (html)
		sb_printf(sb, "<td>%s</td>", buf);
	else
		report_md_cell(sb, buf);
}

static void text_cell(struct strbuf *sb, bool html, const char *text)
{
	if (!html) {
		report_md_cell(sb, text);
		return;
	}
	sb_printf(sb, "<td class=\"l\">");
	report_escape(sb, text);
	sb_printf(sb, "</td>");
}

/* One row: the run by one traversal (NULL: its main one, which also
 * gives the nodes and triangles per ray; the others' are not counted). */
static void row(struct strbuf *sb, bool html, const cJSON *run, const char *traversal,
                unsigned kinds)
{
	sb_printf(sb, html ? "<tr>" : "|");
	text_cell(sb, html, report_str(run, "builder"));
	cell(sb, html, report_num(run, "threads"), "%.0f");
	text_cell(sb, html, traversal ? traversal : report_str(run, "rays.traversal"));
	for (int kind = 0; kind < RAY_KINDS; kind++) {
		if (!(kinds & (1u << kind)))
			continue;
		cell(sb, html, kind_num(run, traversal, kind, "mrays_per_s"), "%.2f");
		cell(sb, html, traversal ? NAN : kind_num(run, NULL, kind, "nodes_per_ray"), "%.1f");
	}
	sb_printf(sb, html ? "</tr>\n" : "\n");
}

static void head(struct strbuf *sb, bool html, unsigned kinds)
{
	sb_printf(sb, html ? "<h3>Rays by kind</h3>\n<p>" : "\n**Rays by kind.** ");
	sb_printf(sb, "Shadow rays run from each primary hit to the point light, AO rays a "
	              "short way from it (rays.ao_length of the scene's diagonal); both are "
	              "any-hit: the first hit ends them. Nodes/ray are counted by the stack "
	              "traversal on the binary tree, in the main traversal's row.%s",
	          html ? "</p>\n<table class=\"runs kinds\"><tr><th class=\"l\">builder</th>"
	                 "<th>threads</th><th class=\"l\">traversal</th>"
	               : "\n\n| builder | threads | traversal |");
	int cols = 0;
	for (int kind = 0; kind < RAY_KINDS; kind++) {
		if (!(kinds & (1u << kind)))
			continue;
		const char *k = ray_kind_name(kind);
		sb_printf(sb, html ? "<th>%s Mrays/s</th><th>%s nodes/ray</th>"
		                   : " %s Mrays/s | %s nodes/ray |", k, k);
		cols += 2;
	}
	if (html) {
		sb_printf(sb, "</tr>\n");
		return;
	}
	sb_printf(sb, "\n|---|---:|---|");
	for (int c = 0; c < cols; c++)
		sb_printf(sb, "---:|");
	sb_printf(sb, "\n");
}

void report_kinds(struct strbuf *sb, const cJSON *const *runs, size_t n, bool html)
{
	unsigned kinds = scene_kinds(runs, n);
	if (!kinds)
		return;
	head(sb, html, kinds);
	for (size_t i = 0; i < n; i++) {
		if (!report_at(runs[i], "rays.primary"))
			continue;
		row(sb, html, runs[i], NULL, kinds);
		for (int k = 0; k < BVHLAB_TRAVERSAL_COUNT; k++) {
			char key[64];
			snprintf(key, sizeof(key), "rays.%s", bvhlab_traversal_name(k));
			if (report_at(runs[i], key))
				row(sb, html, runs[i], bvhlab_traversal_name(k), kinds);
		}
	}
	if (html)
		sb_printf(sb, "</table>\n");
}
