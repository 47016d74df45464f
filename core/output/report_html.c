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
	"img{image-rendering:pixelated;border:1px solid #ccc}"
	"table.summary td.good{background:#e3f4e3}table.summary td.worse{background:#fbe7e7}";

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

/* "min–max" of a ray kind's throughput over the passes. */
static void range_cell(struct strbuf *sb, const cJSON *run, const char *kind)
{
	char lo[64], hi[64];
	snprintf(lo, sizeof(lo), "%s.mrays_min", kind);
	snprintf(hi, sizeof(hi), "%s.mrays_max", kind);
	double a = report_num(run, lo), b = report_num(run, hi);
	sb_printf(sb, "<td>");
	if (isfinite(a) && isfinite(b))
		sb_printf(sb, "%.2f–%.2f", a, b);
	sb_printf(sb, "</td>");
}

/* Traversals a scene's table may show beside the main one, by name. */
static const char *const other_traversals[] = {"wide", "stack", "stackless", "cl_stack",
                                                 "cl_stackless"};
#define OTHERS (sizeof(other_traversals) / sizeof(other_traversals[0]))

static double other_num(const cJSON *run, const char *traversal, const char *what)
{
	char key[96];
	snprintf(key, sizeof(key), "rays.%s.%s", traversal, what);
	return report_num(run, key);
}

static void run_row(struct strbuf *sb, const struct report_index *ix, const cJSON *run,
                    const bool *others, bool any_other)
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
	num_cell(sb, report_num(run, "build_ms.cold"), "%.2f");
	num_cell(sb, report_num(run, "mtris_per_s"), "%.2f");
	num_cell(sb, report_speedup(ix, run), "%.2f");
	num_cell(sb, report_num(run, "tree.sah_cost"), "%.3f");
	num_cell(sb, report_num(run, "tree.epo"), "%.3f");
	num_cell(sb, report_num(run, "memory.peak_bytes") / 1048576.0, "%.1f");
	num_cell(sb, report_num(run, "rays.primary.mrays_per_s"), "%.2f");
	range_cell(sb, run, "rays.primary");
	num_cell(sb, report_num(run, "rays.primary.nodes_per_ray"), "%.1f");
	num_cell(sb, report_num(run, "rays.primary.tris_per_ray"), "%.1f");
	num_cell(sb, report_num(run, "rays.diffuse.mrays_per_s"), "%.2f");
	num_cell(sb, report_num(run, "rays.diffuse.nodes_per_ray"), "%.1f");
	num_cell(sb, report_num(run, "tree.refs"), "%.0f");
	num_cell(sb, report_num(run, "tree.dup_ratio"), "%.3f");
	for (size_t t = 0; t < OTHERS; t++) {
		if (!others[t])
			continue;
		num_cell(sb, other_num(run, other_traversals[t], "primary.mrays_per_s"), "%.2f");
		num_cell(sb, other_num(run, other_traversals[t], "diffuse.mrays_per_s"), "%.2f");
		if (strstr(other_traversals[t], "stackless")) /* it counts its own nodes */
			num_cell(sb, other_num(run, other_traversals[t], "primary.nodes_per_ray"),
			         "%.1f");
	}
	if (any_other)
		num_cell(sb, report_num(run, "rays.traversal_disagreements"), "%.0f");
	sb_printf(sb, "<td class=\"l\">");
	esc(sb, report_str(run, "error"));
	if (*report_str(run, "rays.error")) { /* a traversal's device missing, say */
		sb_printf(sb, "%srays: ", *report_str(run, "error") ? "; " : "");
		esc(sb, report_str(run, "rays.error"));
	}
	sb_printf(sb, "</td></tr>\n");
}

/* Which other traversals some run of the scene was also traced with;
 * whether any. */
static bool find_others(const cJSON *const *runs, size_t n, bool *others)
{
	bool any = false;
	for (size_t t = 0; t < OTHERS; t++) {
		char key[64];
		snprintf(key, sizeof(key), "rays.%s", other_traversals[t]);
		others[t] = false;
		for (size_t k = 0; k < n && !others[t]; k++)
			others[t] = report_at(runs[k], key) != NULL;
		any |= others[t];
	}
	return any;
}

static void table(struct strbuf *sb, const struct report_index *ix, const char *scene)
{
	size_t n;
	bool others[OTHERS];
	const cJSON *const *runs = report_scene_runs(ix, scene, &n);
	bool any_other = find_others(runs, n, others);
	sb_printf(sb, "<table><tr><th class=\"l\">builder</th><th>threads</th>"
	              "<th class=\"l\">status</th><th>median ms</th><th>min ms</th><th>max ms</th>"
	              "<th>cold ms</th>"
	              "<th>Mtris/s</th><th>speedup</th><th>SAH cost</th><th>EPO</th>"
	              "<th>peak MiB</th><th>primary Mrays/s</th><th>min–max</th>"
	              "<th>primary nodes/ray</th><th>primary tris/ray</th><th>diffuse Mrays/s</th>"
	              "<th>diffuse nodes/ray</th><th>refs</th><th>refs/tri</th>");
	for (size_t t = 0; t < OTHERS; t++) {
		const char *name = other_traversals[t];
		if (!others[t])
			continue;
		sb_printf(sb, "<th>%s primary Mrays/s</th><th>%s diffuse Mrays/s</th>", name, name);
		if (strstr(name, "stackless"))
			sb_printf(sb, "<th>%s primary nodes/ray</th>", name);
	}
	if (any_other)
		sb_printf(sb, "<th>hits differing</th>");
	sb_printf(sb, "<th class=\"l\">error</th></tr>\n");
	for (size_t k = 0; k < n; k++)
		run_row(sb, ix, runs[k], others, any_other);
	sb_printf(sb, "</table>\n");
}

/* The scene's runs with a build time, as chart points ("builder xT" labels). */
static size_t points(const cJSON *const *runs, size_t count, struct svg_point *p,
                     char (*labels)[96])
{
	size_t n = 0;
	for (size_t k = 0; k < count; k++) {
		const cJSON *run = runs[k];
		if (!isfinite(report_num(run, "build_ms.median")))
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

static void charts(struct strbuf *sb, const struct report_index *ix, const char *scene)
{
	size_t count;
	const cJSON *const *runs = report_scene_runs(ix, scene, &count);
	size_t total = count + 1;
	struct svg_point *p = calloc(total, sizeof(*p)), *q = calloc(total, sizeof(*q));
	char (*labels)[96] = calloc(total, sizeof(*labels));
	if (!p || !q || !labels)
		goto out;
	size_t n = points(runs, count, p, labels);
	if (n == 0)
		goto out;
	sb_printf(sb, "<div class=\"charts\">\n");
	for (size_t i = 0; i < n; i++)
		q[i] = (struct svg_point){p[i].label, p[i].group, 0, p[i].x};
	svg_bars(sb, "Build time (median)", "ms", q, n);
	svg_scatter(sb, "SAH cost vs. build time", "build time (ms)", "SAH cost", p, n);
	size_t m = 0;
	for (size_t k = 0; k < count; k++) {
		double s = report_speedup(ix, runs[k]);
		if (isfinite(s))
			q[m++] = (struct svg_point){"", report_str(runs[k], "builder"),
			                            report_num(runs[k], "threads"), s};
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

static void images(struct strbuf *sb, const struct report_index *ix, const cJSON *scene)
{
	const char *name = report_str(scene, "name"), *legend = report_str(scene, "images.legend");
	size_t n;
	const cJSON *const *runs = report_scene_runs(ix, name, &n);
	if (!*report_str(scene, "images.shaded") && !*legend)
		return;
	sb_printf(sb, "<div class=\"images\">\n");
	if (*report_str(scene, "images.shaded"))
		figure(sb, report_str(scene, "images.shaded"), name);
	for (size_t k = 0; k < n; k++)
		if (*report_str(runs[k], "heat_image"))
			figure(sb, report_str(runs[k], "heat_image"), report_str(runs[k], "builder"));
	sb_printf(sb, "</div>\n");
	if (*legend) {
		sb_printf(sb, "<p>Nodes visited per primary ray, one scale for every builder: "
		              "%.0f <img src=\"", report_num(scene, "images.heat_min"));
		esc(sb, legend);
		sb_printf(sb, "\" alt=\"colour scale\" width=\"256\" height=\"16\"> %.0f</p>\n",
		          report_num(scene, "images.heat_max"));
	}
}

static void scene_section(struct strbuf *sb, const struct report_index *ix, const cJSON *scene)
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
	table(sb, ix, name);
	charts(sb, ix, name);
	images(sb, ix, scene);
}

char *report_html(const cJSON *doc)
{
	struct strbuf sb = {0};
	const cJSON *scene;
	struct report_index ix;
	if (report_index_init(&ix, doc) < 0)
		sb.failed = true;
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
	               "normalised by the root's area; EPO: end-point overlap, sampled; peak "
	               "MiB: what the builds added to the process's resident set at its peak. "
	               "Rays are traced with the same threads for every run, so traversal "
	               "numbers compare trees, not thread counts; Mrays/s: rays per CPU "
	               "second of the tracing threads times their number, each tile of rays "
	               "at its best of the repeated passes (spread over rounds taken in turn "
	               "by the scene's trees; min–max: whole passes), by the "
	               "run's traversal (default wide: the tree collapsed into 4-child "
	               "nodes); nodes and triangles per ray are the binary tree's, counted "
	               "by the stack traversal, whichever is timed.</p>\n",
	          report_num(doc, "machine.cores"));
	report_summary_html(&sb, doc);
	report_machines_html(&sb, doc);
	cJSON_ArrayForEach(scene, cJSON_GetObjectItem(doc, "scenes"))
		scene_section(&sb, &ix, scene);
	report_index_finish(&ix);
	sb_printf(&sb, "</body></html>\n");
	return sb_take(&sb);
}
