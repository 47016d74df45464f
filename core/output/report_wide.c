/*
 * A scene's wide trees (report.md and report.html, the same content): its
 * runs' width, the collapse that made each wide tree, the SAH before and
 * after it, traversal counts and memory per triangle, next to the binary
 * runs'; then "does the collapse change the ranking?": per collapse, the
 * 8-wide runs ranked by the binary tree's SAH and by the measured 8-wide
 * cost (nodes + triangles per primary ray, and Mrays/s), the Spearman
 * correlation of the rankings, and which builder and collapse are on the
 * front of build time against wide ray cost. Nothing for a scene without
 * a wide tree.
 */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "output/report.h"

#define RANK_WIDTH 8 /* the width ranked: the widest, what CPU and GPU tracers use */

/* One table or paragraph at a time, in Markdown or HTML. */
struct out {
	struct strbuf *sb;
	bool html;
};

static void text(const struct out *o, const char *s)
{
	if (o->html)
		report_escape(o->sb, s);
	else
		report_md_text(o->sb, s);
}

/* A heading; its text escaped (a method name comes from the document). */
static void heading(const struct out *o, const char *title)
{
	sb_printf(o->sb, o->html ? "<h3>" : "\n### ");
	text(o, title);
	sb_printf(o->sb, o->html ? "</h3>\n" : "\n\n");
}

static void table_begin(const struct out *o, const char *const *heads, size_t n)
{
	sb_printf(o->sb, o->html ? "<table class=\"wide\"><tr>" : "|");
	for (size_t k = 0; k < n; k++)
		if (o->html)
			sb_printf(o->sb, "<th%s>%s</th>", k == 0 ? " class=\"l\"" : "", heads[k]);
		else
			sb_printf(o->sb, " %s |", heads[k]);
	sb_printf(o->sb, o->html ? "</tr>\n" : "\n|---|");
	for (size_t k = 1; !o->html && k < n; k++)
		sb_printf(o->sb, "---:|");
	if (!o->html)
		sb_printf(o->sb, "\n");
}

/* A row: the first cell a name (left, escaped), the rest figures. */
static void table_row(const struct out *o, const char *const *cells, size_t n)
{
	sb_printf(o->sb, o->html ? "<tr><td class=\"l\">" : "|");
	if (o->html)
		report_escape(o->sb, cells[0]);
	else
		report_md_cell(o->sb, cells[0]);
	for (size_t k = 1; k < n; k++) {
		sb_printf(o->sb, o->html ? "</td><td>" : "");
		if (o->html)
			report_escape(o->sb, cells[k]);
		else
			report_md_cell(o->sb, cells[k]);
	}
	sb_printf(o->sb, o->html ? "</td></tr>\n" : "\n");
}

static void table_end(const struct out *o)
{
	sb_printf(o->sb, o->html ? "</table>\n" : "");
}

/* ---- a run's wide figures ------------------------------------------------ */

static bool ok(const cJSON *run)
{
	return strcmp(report_str(run, "status"), "ok") == 0;
}

static double width_of(const cJSON *run)
{
	double w = report_num(run, "tree.width");
	return isnan(w) ? 2 : w;
}

/* The index of the run's last "collapse" stage, or -1. */
static int collapse_stage(const cJSON *run)
{
	const cJSON *stages = cJSON_GetObjectItemCaseSensitive(run, "stages");
	for (int k = cJSON_GetArraySize(stages); k-- > 0;)
		if (strcmp(report_str(cJSON_GetArrayItem(stages, k), "plugin"), "collapse") == 0)
			return k;
	return -1;
}

/* What made the run's tree wide: the collapse's method, "native" (the
 * builder's own wide tree) or "" (binary). */
static const char *wide_method(const cJSON *run)
{
	int k = collapse_stage(run);
	if (k < 0)
		return width_of(run) > 2 ? "native" : "";
	const cJSON *refine = report_at(run, "config.builder.refine");
	const char *m = report_str(cJSON_GetArrayItem(refine, k), "options.method");
	return *m ? m : "sah";
}

/* The SAH cost of the binary tree the collapse started from (a binary
 * run's own), NaN for a native wide tree. */
static double binary_sah(const cJSON *run)
{
	int k = collapse_stage(run);
	if (k >= 0)
		return report_num(cJSON_GetArrayItem(cJSON_GetObjectItemCaseSensitive(run, "stages"), k),
		                  "sah_before");
	return width_of(run) > 2 ? NAN : report_num(run, "tree.sah_cost");
}

static const char *fig(char *buf, size_t size, double v, int decimals)
{
	if (isnan(v))
		return "—";
	snprintf(buf, size, "%.*f", decimals, v);
	return buf;
}

static void wide_table(const struct out *o, const cJSON *const *runs, size_t n)
{
	static const char *const heads[] = {
		"builder", "threads", "width", "collapse", "binary SAH", "SAH", "primary nodes/ray",
		"primary tris/ray", "diffuse nodes/ray", "bytes/tri", "packed bytes/tri"};
	char b[10][32];
	heading(o, "Wide trees");
	sb_printf(o->sb, o->html ? "<p>" : "");
	text(o, "Each run's tree width, the collapse that made it wide (native: the builder's "
	        "own), the SAH cost of the binary tree before it and of the tree after (an inner "
	        "node of k children weighs k/2), nodes and triangles per ray counted in the tree "
	        "as it is (a wide node visited is one node), and bytes per triangle as stored "
	        "(32-byte nodes) and packed (28 bytes per child slot of each inner node, 4 per "
	        "reference).");
	sb_printf(o->sb, o->html ? "</p>\n" : "\n\n");
	table_begin(o, heads, 11);
	for (size_t k = 0; k < n; k++) {
		const cJSON *r = runs[k];
		if (!ok(r) || isnan(report_num(r, "tree.sah_cost")))
			continue;
		const char *cells[11] = {
			report_str(r, "builder"), fig(b[0], 32, report_num(r, "threads"), 0),
			fig(b[1], 32, width_of(r), 0), *wide_method(r) ? wide_method(r) : "—",
			fig(b[2], 32, binary_sah(r), 3), fig(b[3], 32, report_num(r, "tree.sah_cost"), 3),
			fig(b[4], 32, report_num(r, "rays.primary.nodes_per_ray"), 1),
			fig(b[5], 32, report_num(r, "rays.primary.tris_per_ray"), 1),
			fig(b[6], 32, report_num(r, "rays.diffuse.nodes_per_ray"), 1),
			fig(b[7], 32, report_num(r, "tree.bytes_per_triangle"), 1),
			fig(b[8], 32, report_num(r, "tree.packed_bytes_per_triangle"), 1)};
		table_row(o, cells, 11);
	}
	table_end(o);
}

/* ---- does the collapse change the ranking? ------------------------------- */

/* Ranks of v[0 .. n) ascending, 1 first, ties sharing their mean rank. */
static void ranks(const double *v, size_t n, double *rank)
{
	for (size_t i = 0; i < n; i++) {
		size_t less = 0, same = 0;
		for (size_t j = 0; j < n; j++)
			less += v[j] < v[i], same += v[j] == v[i];
		rank[i] = (double)less + (double)(same + 1) / 2.0;
	}
}

/* Spearman's rank correlation: Pearson's of the ranks (ties averaged);
 * NaN for fewer than 3 or a ranking of all ties. */
double report_spearman(const double *a, const double *b, size_t n)
{
	double *ra = malloc(2 * n * sizeof(*ra) + 1), *rb = ra + n, ma = 0, mb = 0;
	double sab = 0, saa = 0, sbb = 0;
	if (!ra || n < 3) {
		free(ra);
		return NAN;
	}
	ranks(a, n, ra);
	ranks(b, n, rb);
	for (size_t i = 0; i < n; i++)
		ma += ra[i] / n, mb += rb[i] / n;
	for (size_t i = 0; i < n; i++) {
		sab += (ra[i] - ma) * (rb[i] - mb);
		saa += (ra[i] - ma) * (ra[i] - ma);
		sbb += (rb[i] - mb) * (rb[i] - mb);
	}
	free(ra);
	return saa > 0 && sbb > 0 ? sab / sqrt(saa * sbb) : NAN;
}

/* The runs a ranking compares: ok, RANK_WIDTH wide, made by `method`,
 * with a binary SAH and a ray cost; one per builder (its first run: the
 * tree and its rays are the same at every thread count). */
static size_t rank_runs(const cJSON *const *runs, size_t n, const char *method,
                        const cJSON **out)
{
	size_t m = 0;
	for (size_t k = 0; k < n; k++) {
		const cJSON *r = runs[k];
		bool seen = false;
		if (!ok(r) || width_of(r) != RANK_WIDTH || strcmp(wide_method(r), method) != 0 ||
		    isnan(binary_sah(r)) || isnan(report_ray_cost(r)))
			continue;
		for (size_t j = 0; j < m && !seen; j++)
			seen = strcmp(report_str(out[j], "builder"), report_str(r, "builder")) == 0;
		if (!seen)
			out[m++] = r;
	}
	return m;
}

/* v: the m runs' three figures (binary SAH, ray cost, -Mrays/s), then
 * room for their ranks. */
static void rank_table(const struct out *o, const cJSON **r, size_t m, double *v)
{
	static const char *const heads[] = {"builder", "binary SAH", "rank", "8-wide ray cost",
	                                    "rank", "primary Mrays/s", "rank"};
	double *rank = v + 3 * m;
	char b[6][32];
	for (size_t f = 0; f < 3; f++)
		ranks(v + f * m, m, rank + f * m);
	table_begin(o, heads, 7);
	for (size_t k = 0; k < m; k++) {
		const char *cells[7] = {report_str(r[k], "builder")};
		for (size_t f = 0; f < 3; f++) {
			double x = v[f * m + k], at = rank[f * m + k];
			cells[1 + 2 * f] = fig(b[2 * f], 32, f == 2 ? -x : x, f == 2 ? 2 : 3);
			cells[2 + 2 * f] = fig(b[2 * f + 1], 32, at, at == floor(at) ? 0 : 1);
		}
		table_row(o, cells, 7);
	}
	table_end(o);
}

/* One collapse method's ranking: the table and the correlations. */
static void ranking(const struct out *o, const cJSON *const *runs, size_t n, const char *method)
{
	const cJSON **r = malloc((n + 1) * sizeof(*r));
	double *v = malloc((6 * n + 1) * sizeof(*v)); /* SAH, ray cost, -Mrays/s; ranks */
	size_t m = r && v ? rank_runs(runs, n, method, r) : 0;
	char title[96], line[400], b[2][32];
	if (m >= 2) {
		for (size_t k = 0; k < m; k++) {
			v[k] = binary_sah(r[k]);
			v[m + k] = report_ray_cost(r[k]);
			v[2 * m + k] = -report_num(r[k], "rays.primary.mrays_per_s");
		}
		snprintf(title, sizeof(title), "Does the collapse change the ranking? %d-wide, %s",
		         RANK_WIDTH, method);
		heading(o, title);
		rank_table(o, r, m, v);
		snprintf(line, sizeof(line), "Spearman rank correlation of the binary SAH's ranking "
		         "with the 8-wide ray cost's (nodes + triangles per primary ray): %s; with "
		         "primary Mrays/s: %s (%zu builders; 1 the same order, -1 reversed).",
		         fig(b[0], 32, report_spearman(v, v + m, m), 2),
		         fig(b[1], 32, report_spearman(v, v + 2 * m, m), 2), m);
		sb_printf(o->sb, o->html ? "<p>" : "\n");
		text(o, line);
		sb_printf(o->sb, o->html ? "</p>\n" : "\n");
	}
	free(r);
	free(v);
}

/* The wide runs on the front of build time (with the collapse) against
 * wide ray cost, at each machine and thread count. */
static void wide_front(const struct out *o, const struct report_index *ix,
                       const cJSON *const *runs, size_t n)
{
	struct front_point *p = malloc((n + 1) * sizeof(*p));
	long *by = malloc((n + 1) * sizeof(*by));
	bool any = false;
	for (size_t k = 0; p && by && k < n; k++) {
		bool use = ok(runs[k]) && width_of(runs[k]) > 2;
		p[k] = (struct front_point){use ? report_num(runs[k], "build_ms.median") : NAN,
		                            report_ray_cost(runs[k]),
		                            report_front_group(report_machine_number(ix, runs[k]),
		                                               report_num(runs[k], "threads"))};
	}
	if (p && by)
		report_front_points(p, n, by);
	for (size_t k = 0; p && by && k < n; k++) {
		char line[400];
		if (by[k] != FRONT_ON)
			continue;
		if (!any)
			sb_printf(o->sb, o->html ? "<p>Wide trees on the front of build time (the collapse "
			                           "included) against wide ray cost: "
			                         : "\nWide trees on the front of build time (the collapse "
			                           "included) against wide ray cost: ");
		snprintf(line, sizeof(line), "%s%s (%.0f-wide %s, %.0f thread%s: %.2f ms, %.1f)",
		         any ? "; " : "", report_str(runs[k], "builder"), width_of(runs[k]),
		         wide_method(runs[k]), report_num(runs[k], "threads"),
		         report_num(runs[k], "threads") == 1 ? "" : "s", p[k].time, p[k].figure);
		text(o, line);
		any = true;
	}
	if (any)
		sb_printf(o->sb, o->html ? ".</p>\n" : ".\n");
	free(p);
	free(by);
}

static void section(const struct out *o, const struct report_index *ix,
                    const cJSON *const *runs, size_t n)
{
	const char *methods[8];
	size_t mc = 0;
	for (size_t k = 0; k < n; k++) {
		const char *m = wide_method(runs[k]);
		bool seen = !*m;
		for (size_t j = 0; j < mc && !seen; j++)
			seen = strcmp(methods[j], m) == 0;
		if (!seen && mc < 8)
			methods[mc++] = m;
	}
	if (mc == 0)
		return;
	wide_table(o, runs, n);
	for (size_t j = 0; j < mc; j++)
		ranking(o, runs, n, methods[j]);
	wide_front(o, ix, runs, n);
}

void report_wide_md(struct strbuf *sb, const struct report_index *ix, const cJSON *const *runs,
                    size_t n)
{
	section(&(struct out){sb, false}, ix, runs, n);
}

void report_wide_html(struct strbuf *sb, const struct report_index *ix,
                      const cJSON *const *runs, size_t n)
{
	section(&(struct out){sb, true}, ix, runs, n);
}
