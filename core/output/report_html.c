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
	"body{font-family:sans-serif;margin:2em;color:#222}p{max-width:1400px}"
	"table{border-collapse:collapse;margin:1em 0;font-size:13px}"
	"th,td{border:1px solid #ccc;padding:3px 7px;text-align:right}"
	"th{background:#f0f0f0}td.l,th.l{text-align:left}"
	".bad{color:#b00}.charts,.images{display:flex;flex-wrap:wrap;gap:1em}"
	"figure{margin:0}figcaption{font-size:12px;text-align:center}"
	"img{image-rendering:pixelated;border:1px solid #ccc}"
	"table.summary td.good{background:#e3f4e3}table.summary td.worse{background:#fbe7e7}"
	"td.front{background:#e3f4e3;font-weight:bold}.warn{color:#8a4b00}"
	"td.warn{background:#fff4dc}td.err{max-width:40em}"
	"h3{margin-bottom:0.2em}";

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
static const char *const other_traversals[] = {"wide", "stack", "stackless", "device_stack",
                                                 "device_stackless", "wide4", "wide8",
                                                 "device_wide8"};
#define OTHERS (sizeof(other_traversals) / sizeof(other_traversals[0]))

/* Whether a traversal counts its own nodes (the others count the binary
 * tree's, as the stack traversal walks it): stackless, and device_wide8
 * its compressed nodes. */
static bool counts_own_nodes(const char *name)
{
	return strstr(name, "stackless") || strcmp(name, "device_wide8") == 0;
}

static double other_num(const cJSON *run, const char *traversal, const char *what)
{
	char key[96];
	snprintf(key, sizeof(key), "rays.%s.%s", traversal, what);
	return report_num(run, key);
}

/* "≈ noisy" and "⚠ busy", short beside the status; why in the tooltip
 * (and in report.md). */
static void marks_cell(struct strbuf *sb, const struct report_index *ix, const cJSON *run)
{
	char noise[160], load[160];
	bool noisy = report_noise(ix, run, noise, sizeof(noise));
	bool busy = report_busy(ix->doc, run, load, sizeof(load));
	sb_printf(sb, "<td class=\"l%s\" title=\"", noisy || busy ? " warn" : "");
	esc(sb, noise);
	sb_printf(sb, "%s%s\">%s%s%s</td>", noisy && busy ? "; " : "", load, noisy ? "≈ noisy" : "",
	          noisy && busy ? " " : "", busy ? "⚠ busy" : "");
}

/* The builder's phases of the median build, each with its share of it. */
static void phases_cell(struct strbuf *sb, const cJSON *run)
{
	char buf[512];
	double median = report_num(run, "build_ms.median"), sum = 0;
	const cJSON *p;
	cJSON_ArrayForEach(p, cJSON_GetObjectItemCaseSensitive(run, "build_phases"))
		sum += cJSON_IsNumber(p) ? p->valuedouble : 0;
	sb_printf(sb, "<td class=\"l\"");
	if (median > 0 && sum > 0)
		sb_printf(sb, " title=\"the phases add up to %.0f %% of the median build\"",
		          100 * sum / median);
	sb_printf(sb, ">");
	esc(sb, report_phases(buf, sizeof(buf), run));
	sb_printf(sb, "</td>");
}

/* The cells that start every row of a scene's tables. */
static void name_cells(struct strbuf *sb, const cJSON *run)
{
	sb_printf(sb, "<tr><td class=\"l\">");
	esc(sb, report_str(run, "builder"));
	sb_printf(sb, "</td>");
	if (report_on_device(run))
		sb_printf(sb, "<td>device</td>"); /* its one host thread says nothing */
	else
		num_cell(sb, report_num(run, "threads"), "%.0f");
}

static void error_cell(struct strbuf *sb, const cJSON *run)
{
	sb_printf(sb, "<td class=\"l err\">");
	esc(sb, report_str(run, "error"));
	if (*report_str(run, "rays.error")) { /* a traversal's device missing, say */
		sb_printf(sb, "%srays: ", *report_str(run, "error") ? "; " : "");
		esc(sb, report_str(run, "rays.error"));
	}
	sb_printf(sb, "</td>");
}

/* The run's build: status, marks, times, memory, error. */
static void build_row(struct strbuf *sb, const struct report_index *ix, const cJSON *run,
                      bool phases)
{
	bool ok = strcmp(report_str(run, "status"), "ok") == 0;
	name_cells(sb, run);
	sb_printf(sb, "<td class=\"l%s\">", ok ? "" : " bad");
	esc(sb, report_str(run, "status"));
	sb_printf(sb, "</td>");
	marks_cell(sb, ix, run);
	num_cell(sb, report_num(run, "build_ms.median"), "%.2f");
	num_cell(sb, report_num(run, "build_ms.min"), "%.2f");
	num_cell(sb, report_num(run, "build_ms.max"), "%.2f");
	num_cell(sb, report_num(run, "build_ms.cold"), "%.2f");
	if (phases)
		phases_cell(sb, run);
	num_cell(sb, report_num(run, "mtris_per_s"), "%.2f");
	num_cell(sb, report_speedup(ix, run), "%.2f");
	num_cell(sb, report_num(run, "memory.peak_bytes") / 1048576.0, "%.1f");
	error_cell(sb, run);
	sb_printf(sb, "</tr>\n");
}

/* The run's tree and its rays by the main traversal. */
static void tree_row(struct strbuf *sb, const cJSON *run)
{
	name_cells(sb, run);
	num_cell(sb, report_num(run, "tree.sah_cost"), "%.3f");
	num_cell(sb, report_num(run, "tree.epo"), "%.3f");
	num_cell(sb, report_num(run, "rays.primary.mrays_per_s"), "%.2f");
	range_cell(sb, run, "rays.primary");
	num_cell(sb, report_num(run, "rays.primary.nodes_per_ray"), "%.1f");
	num_cell(sb, report_num(run, "rays.primary.tris_per_ray"), "%.1f");
	num_cell(sb, report_num(run, "rays.diffuse.mrays_per_s"), "%.2f");
	num_cell(sb, report_num(run, "rays.diffuse.nodes_per_ray"), "%.1f");
	num_cell(sb, report_num(run, "tree.nodes"), "%.0f");
	num_cell(sb, report_num(run, "tree.refs"), "%.0f");
	num_cell(sb, report_num(run, "tree.dup_ratio"), "%.3f");
	sb_printf(sb, "</tr>\n");
}

/* The run's rays by the other traversals it was traced with. */
static void others_row(struct strbuf *sb, const cJSON *run, const bool *others)
{
	name_cells(sb, run);
	for (size_t t = 0; t < OTHERS; t++) {
		if (!others[t])
			continue;
		num_cell(sb, other_num(run, other_traversals[t], "primary.mrays_per_s"), "%.2f");
		num_cell(sb, other_num(run, other_traversals[t], "diffuse.mrays_per_s"), "%.2f");
		if (counts_own_nodes(other_traversals[t]))
			num_cell(sb, other_num(run, other_traversals[t], "primary.nodes_per_ray"),
			         "%.1f");
	}
	num_cell(sb, report_num(run, "rays.traversal_disagreements"), "%.0f");
	sb_printf(sb, "</tr>\n");
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

static const char name_heads[] = "<tr><th class=\"l\">builder</th><th>threads</th>";

static void build_table(struct strbuf *sb, const struct report_index *ix,
                        const cJSON *const *runs, size_t n)
{
	bool phases = report_any_phases(runs, n);
	sb_printf(sb, "<table class=\"runs build\">%s<th class=\"l\">status</th><th class=\"l\" "
	              "title=\"≈ noisy: build repeats spread over 5 %%, or the same tree traced over "
	              "5 %% faster or slower elsewhere; ⚠ busy: the load exceeded the cores the run "
	              "left free (hover a mark for its figures)\">marks</th><th>median ms</th>"
	              "<th>min ms</th><th>max ms</th><th>cold ms</th>%s<th>Mtris/s</th>"
	              "<th>speedup</th><th>peak MiB</th><th class=\"l\">error</th></tr>\n",
	          name_heads,
	          phases ? "<th class=\"l\" title=\"the builder's own timing of the phases of a "
	                   "build (median over the timed repeats), inside the whole call that "
	                   "median ms times\">build phases ms</th>" : "");
	for (size_t k = 0; k < n; k++)
		build_row(sb, ix, runs[k], phases);
	sb_printf(sb, "</table>\n");
}

static void tree_table(struct strbuf *sb, const cJSON *const *runs, size_t n)
{
	sb_printf(sb, "<table class=\"runs tree\">%s<th>SAH cost</th><th>EPO</th><th title=\"each "
	              "tile of rays at its best pass: the figure runs compare by\">primary Mrays/s "
	              "(best tile)</th><th title=\"whole passes, slowest to fastest: the best-tile "
	              "figure can lie above them, as no single pass had every tile at its best\">"
	              "per pass min–max</th><th>primary nodes/ray</th><th>primary tris/ray</th>"
	              "<th>diffuse Mrays/s (best tile)</th><th>diffuse nodes/ray</th><th>nodes</th>"
	              "<th>refs</th><th>refs/tri</th></tr>\n", name_heads);
	for (size_t k = 0; k < n; k++)
		tree_row(sb, runs[k]);
	sb_printf(sb, "</table>\n");
}

static void others_table(struct strbuf *sb, const cJSON *const *runs, size_t n,
                         const bool *others)
{
	sb_printf(sb, "<table class=\"runs others\">%s", name_heads);
	for (size_t t = 0; t < OTHERS; t++) {
		const char *name = other_traversals[t];
		if (!others[t])
			continue;
		sb_printf(sb, "<th>%s primary Mrays/s</th><th>%s diffuse Mrays/s</th>", name, name);
		if (counts_own_nodes(name))
			sb_printf(sb, "<th>%s primary nodes/ray</th>", name);
	}
	sb_printf(sb, "<th>hits differing</th></tr>\n");
	for (size_t k = 0; k < n; k++)
		others_row(sb, runs[k], others);
	sb_printf(sb, "</table>\n");
}

/* The scene's runs in tables narrow enough for a 1400 px window: the
 * builds, then the trees and their rays, then any other traversals. */
static void table(struct strbuf *sb, const struct report_index *ix, const char *scene)
{
	size_t n;
	bool others[OTHERS];
	const cJSON *const *runs = report_scene_runs(ix, scene, &n);
	build_table(sb, ix, runs, n);
	tree_table(sb, runs, n);
	if (find_others(runs, n, others))
		others_table(sb, runs, n, others);
}

/* " on M2" when the runs come from several machines, else "". */
static const char *machine_text(char *buf, size_t size, const struct report_index *ix,
                                long machine)
{
	buf[0] = '\0';
	if (ix->machine_count > 1)
		snprintf(buf, size, " on M%ld", machine + 1);
	return buf;
}

/* A point's texts: its label and its run's marks. */
struct point_text {
	char label[96], mark[256];
};

/* A chart point of a run: its builder's colour, its library's shape,
 * "builder x2" as its label, and the run's marks (every chart of a scene
 * shows a time). */
static struct svg_point run_point(const struct report_index *ix, const cJSON *run,
                                  struct point_text *t, double x, double y)
{
	char on[32];
	const char *builder = report_str(run, "builder");
	snprintf(t->label, sizeof(t->label), "%s x%.0f%s", builder, report_num(run, "threads"),
	         machine_text(on, sizeof(on), ix, report_machine_number(ix, run)));
	report_run_marks(t->mark, sizeof(t->mark), ix, run);
	struct svg_point p = {.label = t->label, .group = builder, .x = x, .y = y,
	                      .shape = svg_plugin_shape(report_str(run, "plugin")),
	                      .mark = t->mark};
	svg_colour(report_builder_number(ix, builder), p.colour, sizeof(p.colour));
	return p;
}

/* One view's Pareto charts, one per machine and thread count: build time
 * against the figure, the front joined by a line. The verdicts are
 * computed once for every thread count (a 1-thread-only builder is on
 * each). */
static void front_charts(struct strbuf *sb, const struct report_index *ix,
                         const struct front_entry *e, size_t n, const double *threads,
                         size_t nt, int view, struct svg_point *p, struct point_text *texts)
{
	struct front_point *fp = calloc(n + 1, sizeof(*fp));
	long *by = calloc(n + 1, sizeof(*by));
	if (fp && by)
		report_entries_front(e, n, view, fp, by);
	for (size_t g = 0; fp && by && g < nt * ix->machine_count; g++) {
		size_t m = 0, t = g % nt;
		long machine = (long)(g / nt);
		for (size_t k = 0; k < n; k++) {
			if (by[k] == FRONT_NONE || e[k].threads != threads[t] || e[k].machine != machine)
				continue;
			p[m] = run_point(ix, e[k].run, &texts[m], fp[k].time, fp[k].figure);
			p[m++].front = by[k] == FRONT_ON;
		}
		char title[128], on[32];
		snprintf(title, sizeof(title), "%s vs. build time, %.0f thread%s%s",
		         report_front_view_name(view), threads[t], threads[t] == 1 ? "" : "s",
		         machine_text(on, sizeof(on), ix, machine));
		if (m > 0)
			svg_scatter(sb, title, "build time (ms)", report_front_view_name(view), p, m);
	}
	free(fp);
	free(by);
}

static void bars_and_speedups(struct strbuf *sb, const struct report_index *ix,
                              const cJSON *const *runs, size_t count, struct svg_point *q,
                              struct point_text *texts)
{
	size_t n = 0, m = 0;
	for (size_t k = 0; k < count; k++)
		if (isfinite(report_num(runs[k], "build_ms.median"))) {
			q[n] = run_point(ix, runs[k], &texts[n], 0, report_num(runs[k], "build_ms.median"));
			n++;
		}
	if (n > 0)
		svg_bars(sb, "Build time (median)", "ms", q, n);
	for (long machine = 0; machine < (long)ix->machine_count; machine++, m = 0) {
		char title[64], on[32];
		for (size_t k = 0; k < count; k++) {
			double s = report_speedup(ix, runs[k]);
			if (isfinite(s) && report_machine_number(ix, runs[k]) == machine) {
				q[m] = run_point(ix, runs[k], &texts[m], report_num(runs[k], "threads"), s);
				m++;
			}
		}
		snprintf(title, sizeof(title), "Speedup over 1 thread%s",
		         machine_text(on, sizeof(on), ix, machine));
		if (m > 0) /* one chart per machine: a line joins one machine's runs */
			svg_lines(sb, title, "threads", "speedup", q, m);
	}
}

static void charts(struct strbuf *sb, const struct report_index *ix, const char *scene)
{
	size_t count, nt, ne = 0;
	double threads[16];
	const cJSON *const *runs = report_scene_runs(ix, scene, &count);
	struct front_entry *e = report_front_entries(ix, runs, count, &ne);
	struct svg_point *p = calloc(ne + count + 1, sizeof(*p));
	struct point_text *texts = calloc(ne + count + 1, sizeof(*texts));
	if (!e || !p || !texts || count == 0)
		goto out;
	sb_printf(sb, "<div class=\"charts\">\n");
	bars_and_speedups(sb, ix, runs, count, p, texts);
	nt = report_thread_counts(runs, count, threads, 16);
	for (int view = 0; view < 2; view++)
		front_charts(sb, ix, e, ne, threads, nt, view, p, texts);
	sb_printf(sb, "</div>\n");
out:
	free(e);
	free(p);
	free(texts);
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

/* The colour bar under the heat maps; a log scale names its middle value
 * (older results drew them on a linear one). */
static void heat_legend(struct strbuf *sb, const cJSON *scene, const char *legend)
{
	double lo = report_num(scene, "images.heat_min"), hi = report_num(scene, "images.heat_max");
	bool log_scale = strcmp(report_str(scene, "images.heat_scale"), "log") == 0;
	sb_printf(sb, "<p>Nodes visited per primary ray, one %s scale for every builder: %.0f "
	              "<img src=\"", log_scale ? "log" : "linear", lo);
	esc(sb, legend);
	sb_printf(sb, "\" alt=\"colour scale\" width=\"256\" height=\"16\"> %.0f", hi);
	if (log_scale)
		sb_printf(sb, " (the middle of the bar: %.0f)", lo + sqrt(1 + hi - lo) - 1);
	sb_printf(sb, "</p>\n");
}

/* A heat map drawn on a scale of its own: "b x2, 0–45" under it. */
static void own_scale_figure(struct strbuf *sb, const cJSON *scene, const cJSON *run)
{
	char caption[256];
	double lo, hi;
	if (report_heat_scale(scene, run, &lo, &hi))
		snprintf(caption, sizeof(caption), "%s x%.0f, %.0f–%.0f", report_str(run, "builder"),
		         report_num(run, "threads"), lo, hi);
	else
		snprintf(caption, sizeof(caption), "%s x%.0f, scale unknown",
		         report_str(run, "builder"), report_num(run, "threads"));
	figure(sb, report_str(run, "heat_image"), caption);
}

static void images(struct strbuf *sb, const struct report_index *ix, const cJSON *scene)
{
	const char *name = report_str(scene, "name"), *legend = report_str(scene, "images.legend");
	size_t n;
	const cJSON *const *runs = report_scene_runs(ix, name, &n);
	bool own = report_heat_scales_differ(scene, runs, n);
	if (!*report_str(scene, "images.shaded") && !*legend && !own)
		return;
	sb_printf(sb, "<div class=\"images\">\n");
	if (*report_str(scene, "images.shaded"))
		figure(sb, report_str(scene, "images.shaded"), name);
	for (size_t k = 0; k < n; k++)
		if (*report_str(runs[k], "heat_image") && own)
			own_scale_figure(sb, scene, runs[k]);
		else if (*report_str(runs[k], "heat_image"))
			figure(sb, report_str(runs[k], "heat_image"), report_str(runs[k], "builder"));
	sb_printf(sb, "</div>\n");
	if (own)
		sb_printf(sb, "<p class=\"warn\">Nodes visited per primary ray, %s scale; the maps "
		              "were drawn on different scales (the parts of a merged sweep), each "
		              "named under its map: compare colours only between maps of one "
		              "scale.</p>\n",
		          strcmp(report_str(scene, "images.heat_scale"), "log") == 0 ? "log"
		                                                                   : "linear");
	else if (*legend)
		heat_legend(sb, scene, legend);
}

static void scene_section(struct strbuf *sb, const struct report_index *ix, const char *ref,
                          const cJSON *scene)
{
	const char *name = report_str(scene, "name");
	sb_printf(sb, "<h2>");
	esc(sb, name);
	sb_printf(sb, "</h2>\n<p>");
	esc(sb, report_str(scene, "source"));
	sb_printf(sb, ", %.0f triangles", report_num(scene, "triangles"));
	report_scene_instances(sb, scene);
	if (*report_str(scene, "error")) {
		sb_printf(sb, ". <b class=\"bad\">Could not be loaded:</b> ");
		esc(sb, report_str(scene, "error"));
	}
	sb_printf(sb, "</p>\n");
	table(sb, ix, name);
	charts(sb, ix, name);
	size_t n;
	const cJSON *const *runs = report_scene_runs(ix, name, &n);
	report_kinds(sb, runs, n, true);
	report_two_level_html(sb, runs, n);
	report_memory_html(sb, runs, n);
	report_front_html(sb, ix, runs, n);
	report_budget_html(sb, ix, name);
	report_breakeven_html(sb, ix, ref, runs, n);
	report_wide_html(sb, ix, runs, n);
	images(sb, ix, scene);
	report_frames_html(sb, ix, scene); /* an animated scene's frames */
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
	               "<h1>bvhlab report</h1>\n<p>", css);
	report_byline(&sb, doc, report_escape);
	sb_printf(&sb, ", %.0f cores. Build times in ms over the timed repeats; speedup over the "
	               "same builder's 1-thread run; SAH cost with c_trav = c_isect = 1, "
	               "normalised by the root's area; EPO: end-point overlap, sampled; peak "
	               "MiB: what the builds added to the process's resident set at its peak. "
	               "Rays are traced with the same threads for every run, so traversal "
	               "numbers compare trees, not thread counts; Mrays/s: rays per CPU "
	               "second of the tracing threads times their number, each tile of rays "
	               "at its best of the repeated passes (best tile; spread over rounds taken "
	               "in turn by the scene's trees; per pass min–max: whole passes, which the "
	               "best-tile figure can exceed), by the "
	               "run's traversal (default wide: the tree collapsed into 4-child "
	               "nodes); nodes and triangles per ray are the binary tree's, counted "
	               "by the stack traversal, whichever is timed. Marks: ≈ noisy where the "
	               "build repeats spread more than 5 %% or a run of the same tree traced "
	               "more than 5 %% faster or slower; ⚠ busy where other processes "
	               "kept more CPUs busy than the run left free.</p>\n",
	          report_num(doc, "machine.cores"));
	const char *asked, *ref = report_reference(doc, &asked, &(bool){false});
	report_load_warning(&sb, doc, true);
	if (*report_str(doc, "report_note")) { /* bvhlab report --scene/--threads */
		sb_printf(&sb, "<p class=\"warn\">");
		esc(&sb, report_str(doc, "report_note"));
		sb_printf(&sb, "</p>\n");
	}
	report_summary_html(&sb, &ix);
	report_machines_html(&sb, doc);
	report_scale_html(&sb, &ix);
	cJSON_ArrayForEach(scene, cJSON_GetObjectItem(doc, "scenes"))
		scene_section(&sb, &ix, ref, scene);
	report_index_finish(&ix);
	sb_printf(&sb, "</body></html>\n");
	return sb_take(&sb);
}
