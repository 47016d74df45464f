/*
 * "Cost per triangle against N" (report.md and report.html): how a
 * builder's build time and peak memory per triangle change with the
 * scene's size, where a sweep holds one mesh at several sizes (a scene
 * source subdivided 0, 1, 2, ... times, bench/scale.json). A series is one
 * builder, thread count and source; the section appears only when some
 * series has SCALE_MIN_SIZES sizes, so sweeps of unrelated scenes do not
 * get it. In HTML, per builder, ns per triangle (warm: the median build;
 * cold: the first, on fresh pages) and build + scene bytes per triangle
 * over triangles, the axis logarithmic.
 */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "output/report.h"

#define SCALE_MIN_SIZES 3

/* One ok run as a point of its series. */
struct scale_point {
	const cJSON *run;
	const char *source; /* the scene's source: the series' mesh */
	long builder;       /* report_builder_number */
	double threads, triangles, warm_ns, cold_ns, bytes;
};

static int by_series(const void *a, const void *b)
{
	const struct scale_point *p = a, *q = b;
	if (p->builder != q->builder)
		return p->builder < q->builder ? -1 : 1;
	int c = strcmp(p->source, q->source);
	if (c)
		return c;
	if (p->threads != q->threads)
		return p->threads < q->threads ? -1 : 1;
	return (p->triangles > q->triangles) - (p->triangles < q->triangles);
}

static bool same_series(const struct scale_point *p, const struct scale_point *q)
{
	return p->builder == q->builder && p->threads == q->threads &&
	       !strcmp(p->source, q->source);
}

static const cJSON *scene_of(const cJSON *doc, const char *name)
{
	const cJSON *s;
	cJSON_ArrayForEach(s, cJSON_GetObjectItem(doc, "scenes"))
		if (!strcmp(report_str(s, "name"), name))
			return s;
	return NULL;
}

/* The document's ok CPU runs with a build time, sorted by series (malloc'd). */
static struct scale_point *collect(const struct report_index *ix, size_t *count)
{
	const cJSON *runs = cJSON_GetObjectItem(ix->doc, "runs"), *run;
	struct scale_point *p = calloc((size_t)cJSON_GetArraySize(runs) + 1, sizeof(*p));
	size_t n = 0;
	cJSON_ArrayForEach(run, runs) {
		const cJSON *scene = scene_of(ix->doc, report_str(run, "scene"));
		double tris = report_num(scene, "triangles"), ms = report_num(run, "build_ms.median");
		if (!p || !scene || strcmp(report_str(run, "status"), "ok") || !(tris > 0) ||
		    !isfinite(ms) || report_on_device(run))
			continue;
		p[n++] = (struct scale_point){
			.run = run, .source = report_str(scene, "source"),
			.builder = report_builder_number(ix, report_str(run, "builder")),
			.threads = report_num(run, "threads"), .triangles = tris,
			.warm_ns = ms * 1e6 / tris,
			.cold_ns = report_num(run, "build_ms.cold") * 1e6 / tris,
			.bytes = report_num(run, "memory.with_scene_bytes_per_triangle")};
	}
	if (p)
		qsort(p, n, sizeof(*p), by_series);
	*count = n;
	return p;
}

/* Whether some series has SCALE_MIN_SIZES distinct sizes. */
static bool any_scaling(const struct scale_point *p, size_t n)
{
	for (size_t a = 0, b; a < n; a = b) {
		size_t sizes = 1;
		for (b = a + 1; b < n && same_series(&p[a], &p[b]); b++)
			sizes += p[b].triangles != p[b - 1].triangles;
		if (sizes >= SCALE_MIN_SIZES)
			return true;
	}
	return false;
}

/* collect's points where some series scales (malloc'd), else NULL. */
static struct scale_point *scaling_points(const struct report_index *ix, size_t *n)
{
	struct scale_point *p = collect(ix, n);
	if (p && any_scaling(p, *n))
		return p;
	free(p);
	return NULL;
}

/* The series' point nearest a million triangles (log distance): what the
 * others' ns per triangle are held against. */
static size_t million(const struct scale_point *p, size_t a, size_t b)
{
	size_t best = a;
	for (size_t k = a; k < b; k++)
		if (fabs(log(p[k].triangles / 1e6)) < fabs(log(p[best].triangles / 1e6)))
			best = k;
	return best;
}

static void md_cell_num(struct strbuf *sb, double v, const char *fmt)
{
	char buf[64];
	snprintf(buf, sizeof(buf), fmt, v);
	report_md_cell(sb, isfinite(v) ? buf : "");
}

static const char intro[] =
	"Build time and peak memory per triangle as the scene grows, for each "
	"builder, thread count and mesh: warm is the median build, cold the first "
	"(fresh pages); bytes are the builds' peak with the scene's own arrays; "
	"vs. 1M is warm ns per triangle over that of the same series' size "
	"nearest a million triangles.";

void report_scale_md(struct strbuf *sb, const struct report_index *ix)
{
	size_t n;
	struct scale_point *p = scaling_points(ix, &n);
	if (!p)
		return;
	sb_printf(sb, "\n## Cost per triangle against N\n\n%s\n\n| builder | threads | mesh "
	              "| triangles | warm ns/tri | cold ns/tri | cold/warm | B/tri | vs. 1M |\n"
	              "|---|---:|---|---:|---:|---:|---:|---:|---:|\n", intro);
	for (size_t a = 0, b; a < n; a = b) {
		for (b = a + 1; b < n && same_series(&p[a], &p[b]); b++)
			;
		double ref = p[million(p, a, b)].warm_ns;
		for (size_t k = a; k < b; k++) {
			sb_printf(sb, "|");
			report_md_cell(sb, report_str(p[k].run, "builder"));
			md_cell_num(sb, p[k].threads, "%.0f");
			report_md_cell(sb, p[k].source);
			md_cell_num(sb, p[k].triangles, "%.0f");
			md_cell_num(sb, p[k].warm_ns, "%.1f");
			md_cell_num(sb, p[k].cold_ns, "%.1f");
			md_cell_num(sb, p[k].cold_ns / p[k].warm_ns, "%.2f");
			md_cell_num(sb, p[k].bytes, "%.1f");
			md_cell_num(sb, p[k].warm_ns / ref, "%.2f");
			sb_printf(sb, "\n");
		}
	}
	free(p);
}

/* A line's name: "igea.ply, 2 threads, cold". */
static const char *series_name(char *buf, size_t size, const struct scale_point *p,
                               const char *what)
{
	const char *slash = strrchr(p->source, '/');
	snprintf(buf, size, "%s, %.0f thread%s%s%s", slash ? slash + 1 : p->source, p->threads,
	         p->threads == 1 ? "" : "s", *what ? ", " : "", what);
	return buf;
}

/* The builder's points [a, b) as lines of one figure (0: warm and cold ns
 * per triangle, 1: bytes per triangle), colours by line. */
static size_t builder_lines(const struct scale_point *p, size_t a, size_t b, int figure,
                            struct svg_point *q, char (*names)[160])
{
	size_t m = 0;
	long line = 0;
	for (int cold = 0; cold < (figure == 0 ? 2 : 1); cold++)
		for (size_t k = a; k < b; k++) {
			double y = figure ? p[k].bytes : cold ? p[k].cold_ns : p[k].warm_ns;
			if (k == a || !same_series(&p[k], &p[k - 1]))
				line++;
			if (!isfinite(y))
				continue;
			series_name(names[m], sizeof(names[m]), &p[k],
			            figure ? "" : cold ? "cold" : "warm");
			q[m] = (struct svg_point){.label = names[m], .group = names[m],
			                          .x = p[k].triangles, .y = y};
			svg_colour(line, q[m].colour, sizeof(q[m].colour));
			m++;
		}
	return m;
}

static void builder_charts(struct strbuf *sb, const struct scale_point *p, size_t a, size_t b)
{
	struct svg_point *q = calloc(2 * (b - a) + 1, sizeof(*q));
	char (*names)[160] = calloc(2 * (b - a) + 1, sizeof(*names));
	char title[200];
	const char *builder = report_str(p[a].run, "builder");
	for (int figure = 0; q && names && figure < 2; figure++) {
		size_t m = builder_lines(p, a, b, figure, q, names);
		snprintf(title, sizeof(title), "%s: %s", builder,
		         figure ? "build + scene bytes per triangle" : "ns per triangle");
		if (m > 0)
			svg_lines(sb, title, "triangles", figure ? "bytes per triangle" : "ns per triangle",
			          q, m);
	}
	free(q);
	free(names);
}

void report_scale_html(struct strbuf *sb, const struct report_index *ix)
{
	size_t n;
	struct scale_point *p = scaling_points(ix, &n);
	if (!p)
		return;
	sb_printf(sb, "<h2>Cost per triangle against N</h2>\n<p>%s Figures: report.md's table "
	              "of the same name.</p>\n<div class=\"charts\">\n", intro);
	for (size_t a = 0, b; a < n; a = b) {
		for (b = a + 1; b < n && p[b].builder == p[a].builder; b++)
			;
		builder_charts(sb, p, a, b);
	}
	sb_printf(sb, "</div>\n");
	free(p);
}
