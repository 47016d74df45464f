/*
 * report.html: the results document as one page with inline CSS and SVG.
 * It is self-contained except for the PNGs it shows, which it names by
 * path relative to the output folder (images/...), next to the report.
 * Every string from the document is escaped: scene and builder names
 * come from configs and may hold anything.
 */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "output/report.h"

static const char css[] =
	"body{font-family:sans-serif;margin:2em;max-width:1400px;color:#222}"
	"table{border-collapse:collapse;margin:1em 0;font-size:13px}"
	"th,td{border:1px solid #ccc;padding:3px 7px;text-align:right}"
	"th{background:#f0f0f0}td.l,th.l{text-align:left}"
	".bad{color:#b00}.charts,.images{display:flex;flex-wrap:wrap;gap:1em}"
	"figure{margin:0}figcaption{font-size:12px;text-align:center}"
	"img{image-rendering:pixelated;border:1px solid #ccc}";

static void esc(struct strbuf *sb, const char *s)
{
	report_escape(sb, s);
}

/* A number cell, empty when the value is absent. */
static void num_cell(struct strbuf *sb, double v, const char *fmt)
{
	sb_printf(sb, "<td>");
	if (isfinite(v))
		sb_printf(sb, fmt, v);
	sb_printf(sb, "</td>");
}

static void run_row(struct strbuf *sb, const cJSON *runs, const cJSON *run)
{
	bool ok = strcmp(report_str(run, "status"), "ok") == 0;
	sb_printf(sb, "<tr><td class=\"l\">");
	esc(sb, report_str(run, "builder"));
	sb_printf(sb, "</td>");
	num_cell(sb, report_num(run, "threads"), "%.0f");
	sb_printf(sb, "<td class=\"l%s\">", ok ? "" : " bad");
	esc(sb, report_str(run, "status"));
	sb_printf(sb, "</td>");
	num_cell(sb, report_num(run, "build_ms.median"), "%.2f");
	num_cell(sb, report_num(run, "build_ms.min"), "%.2f");
	num_cell(sb, report_num(run, "build_ms.max"), "%.2f");
	num_cell(sb, report_num(run, "mtris_per_s"), "%.2f");
	num_cell(sb, report_speedup(runs, run), "%.2f");
	num_cell(sb, report_num(run, "tree.sah_cost"), "%.3f");
	num_cell(sb, report_num(run, "rays.primary.mrays_per_s"), "%.2f");
	num_cell(sb, report_num(run, "rays.primary.nodes_per_ray"), "%.1f");
	num_cell(sb, report_num(run, "rays.primary.tris_per_ray"), "%.1f");
	num_cell(sb, report_num(run, "rays.diffuse.mrays_per_s"), "%.2f");
	num_cell(sb, report_num(run, "rays.diffuse.nodes_per_ray"), "%.1f");
	sb_printf(sb, "<td class=\"l\">");
	esc(sb, report_str(run, "error"));
	sb_printf(sb, "</td></tr>\n");
}

static void table(struct strbuf *sb, const cJSON *runs, const char *scene)
{
	const cJSON *run;
	sb_printf(sb, "<table><tr><th class=\"l\">builder</th><th>threads</th>"
	              "<th class=\"l\">status</th><th>median ms</th><th>min ms</th><th>max ms</th>"
	              "<th>Mtris/s</th><th>speedup</th><th>SAH cost</th><th>primary Mrays/s</th>"
	              "<th>primary nodes/ray</th><th>primary tris/ray</th><th>diffuse Mrays/s</th>"
	              "<th>diffuse nodes/ray</th><th class=\"l\">error</th></tr>\n");
	cJSON_ArrayForEach(run, runs)
		if (strcmp(report_str(run, "scene"), scene) == 0)
			run_row(sb, runs, run);
	sb_printf(sb, "</table>\n");
}

/* The scene's runs with a build time, as chart points ("builder xT" labels). */
static size_t points(const cJSON *runs, const char *scene, struct svg_point *p, char (*labels)[96])
{
	size_t n = 0;
	const cJSON *run;
	cJSON_ArrayForEach(run, runs) {
		if (strcmp(report_str(run, "scene"), scene) != 0 ||
		    !isfinite(report_num(run, "build_ms.median")))
			continue;
		snprintf(labels[n], sizeof(labels[n]), "%s x%.0f", report_str(run, "builder"),
		         report_num(run, "threads"));
		p[n] = (struct svg_point){labels[n], report_str(run, "builder"),
		                          report_num(run, "build_ms.median"),
		                          report_num(run, "tree.sah_cost")};
		n++;
	}
	return n;
}

static void charts(struct strbuf *sb, const cJSON *runs, const char *scene)
{
	size_t total = (size_t)cJSON_GetArraySize(runs) + 1;
	struct svg_point *p = calloc(total, sizeof(*p)), *q = calloc(total, sizeof(*q));
	char (*labels)[96] = calloc(total, sizeof(*labels));
	if (!p || !q || !labels)
		goto out;
	size_t n = points(runs, scene, p, labels);
	if (n == 0)
		goto out;
	sb_printf(sb, "<div class=\"charts\">\n");
	for (size_t i = 0; i < n; i++)
		q[i] = (struct svg_point){p[i].label, p[i].group, 0, p[i].x};
	svg_bars(sb, "Build time (median)", "ms", q, n);
	svg_scatter(sb, "SAH cost vs. build time", "build time (ms)", "SAH cost", p, n);
	const cJSON *run;
	size_t m = 0;
	cJSON_ArrayForEach(run, runs) {
		double s = report_speedup(runs, run);
		if (strcmp(report_str(run, "scene"), scene) == 0 && isfinite(s))
			q[m++] = (struct svg_point){"", report_str(run, "builder"),
			                            report_num(run, "threads"), s};
	}
	svg_lines(sb, "Speedup over 1 thread", "threads", "speedup", q, m);
	sb_printf(sb, "</div>\n");
out:
	free(p);
	free(q);
	free(labels);
}

static void figure(struct strbuf *sb, const char *src, const char *caption)
{
	sb_printf(sb, "<figure><img src=\"");
	esc(sb, src);
	sb_printf(sb, "\" alt=\"");
	esc(sb, caption);
	sb_printf(sb, "\"><figcaption>");
	esc(sb, caption);
	sb_printf(sb, "</figcaption></figure>\n");
}

static void images(struct strbuf *sb, const cJSON *runs, const cJSON *scene)
{
	const char *name = report_str(scene, "name"), *legend = report_str(scene, "images.legend");
	const cJSON *run;
	if (!*report_str(scene, "images.shaded") && !*legend)
		return;
	sb_printf(sb, "<div class=\"images\">\n");
	if (*report_str(scene, "images.shaded"))
		figure(sb, report_str(scene, "images.shaded"), name);
	cJSON_ArrayForEach(run, runs)
		if (strcmp(report_str(run, "scene"), name) == 0 && *report_str(run, "heat_image"))
			figure(sb, report_str(run, "heat_image"), report_str(run, "builder"));
	sb_printf(sb, "</div>\n");
	if (*legend) {
		sb_printf(sb, "<p>Nodes visited per primary ray, one scale for every builder: "
		              "%.0f <img src=\"", report_num(scene, "images.heat_min"));
		esc(sb, legend);
		sb_printf(sb, "\" alt=\"colour scale\" width=\"256\" height=\"16\"> %.0f</p>\n",
		          report_num(scene, "images.heat_max"));
	}
}

static void scene_section(struct strbuf *sb, const cJSON *runs, const cJSON *scene)
{
	const char *name = report_str(scene, "name");
	sb_printf(sb, "<h2>");
	esc(sb, name);
	sb_printf(sb, "</h2>\n<p>");
	esc(sb, report_str(scene, "source"));
	sb_printf(sb, ", %.0f triangles", report_num(scene, "triangles"));
	if (*report_str(scene, "error")) {
		sb_printf(sb, ". <b class=\"bad\">Could not be loaded:</b> ");
		esc(sb, report_str(scene, "error"));
	}
	sb_printf(sb, "</p>\n");
	table(sb, runs, name);
	charts(sb, runs, name);
	images(sb, runs, scene);
}

char *report_html(const cJSON *doc)
{
	struct strbuf sb = {0};
	const cJSON *runs = cJSON_GetObjectItem(doc, "runs"), *scene;
	sb_printf(&sb, "<!DOCTYPE html>\n<html lang=\"en\"><head><meta charset=\"utf-8\">"
	               "<title>bvhlab report</title><style>%s</style></head><body>\n"
	               "<h1>bvhlab report</h1>\n<p>bvhlab ", css);
	esc(&sb, report_str(doc, "bvhlab_version"));
	sb_printf(&sb, ", ");
	esc(&sb, report_str(doc, "created"));
	sb_printf(&sb, ". Machine: ");
	esc(&sb, report_str(doc, "machine.cpu"));
	sb_printf(&sb, ", %.0f cores. Build times in ms over the timed repeats; speedup over the "
	               "same builder's 1-thread run; SAH cost with c_trav = c_isect = 1, "
	               "normalised by the root's area. Rays are traced with every hardware "
	               "thread for every run, so traversal numbers compare trees, not thread "
	               "counts.</p>\n", report_num(doc, "machine.cores"));
	cJSON_ArrayForEach(scene, cJSON_GetObjectItem(doc, "scenes"))
		scene_section(&sb, runs, scene);
	sb_printf(&sb, "</body></html>\n");
	return sb_take(&sb);
}
