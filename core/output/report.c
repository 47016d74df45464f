/*
 * Renderings of a results document: results.csv (one row per run) and
 * report.md (one table per scene). Both read only the document (through
 * report_doc.h), so a saved results.json can be rendered again later.
 */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include <cJSON.h>

#include "output/report.h"
#include "util/util.h"

/* Formats a number at path with fmt, or "" when absent. */
static const char *num(char *buf, size_t size, const cJSON *o, const char *path, const char *fmt)
{
	const cJSON *v = report_at(o, path);
	if (!cJSON_IsNumber(v))
		return "";
	snprintf(buf, size, fmt, v->valuedouble);
	return buf;
}

static const char *const csv_numbers[][2] = {
	{"threads", "%.0f"},
	{"build_ms.median", "%.4f"},
	{"build_ms.min", "%.4f"},
	{"build_ms.max", "%.4f"},
	{"build_ms.cold", "%.4f"},
	{"mtris_per_s", "%.4f"},
	{"tree.nodes", "%.0f"},
	{"tree.leaves", "%.0f"},
	{"tree.max_depth", "%.0f"},
	{"tree.avg_leaf_size", "%.4f"},
	{"tree.sah_cost", "%.6f"},
	{"tree.refs", "%.0f"},
	{"tree.dup_ratio", "%.4f"},
	{"tree.memory_bytes", "%.0f"},
	{"validation.rays_checked", "%.0f"},
	{"validation.mismatches", "%.0f"},
	{"rays.primary.mrays_per_s", "%.4f"},
	{"rays.primary.nodes_per_ray", "%.4f"},
	{"rays.primary.tris_per_ray", "%.4f"},
	{"rays.diffuse.mrays_per_s", "%.4f"},
	{"rays.diffuse.nodes_per_ray", "%.4f"},
	{"rays.diffuse.tris_per_ray", "%.4f"},
	{"tree.epo", "%.6f"},
	{"memory.peak_bytes", "%.0f"},
	{"memory.peak_rss_bytes", "%.0f"},
	{"memory.output_bytes", "%.0f"},
	{"rays.threads", "%.0f"},
	{"rays.primary.mrays_min", "%.4f"},
	{"rays.primary.mrays_max", "%.4f"},
	{"rays.primary.wall_mrays_per_s", "%.4f"},
	{"rays.primary.repeats", "%.0f"},
	{"rays.diffuse.mrays_min", "%.4f"},
	{"rays.diffuse.mrays_max", "%.4f"},
	{"rays.wide.primary.mrays_per_s", "%.4f"},
	{"rays.wide.diffuse.mrays_per_s", "%.4f"},
	{"rays.stack.primary.mrays_per_s", "%.4f"},
	{"rays.stack.diffuse.mrays_per_s", "%.4f"},
	{"rays.stackless.primary.mrays_per_s", "%.4f"},
	{"rays.stackless.primary.nodes_per_ray", "%.4f"},
	{"rays.stackless.diffuse.mrays_per_s", "%.4f"},
	{"rays.stackless.diffuse.nodes_per_ray", "%.4f"},
	{"rays.traversal_disagreements", "%.0f"},
	{"rays.device_stack.primary.mrays_per_s", "%.4f"},
	{"rays.device_stack.primary.wall_mrays_per_s", "%.4f"},
	{"rays.device_stack.diffuse.mrays_per_s", "%.4f"},
	{"rays.device_stack.diffuse.wall_mrays_per_s", "%.4f"},
	{"rays.device_stackless.primary.mrays_per_s", "%.4f"},
	{"rays.device_stackless.primary.wall_mrays_per_s", "%.4f"},
	{"rays.device_stackless.diffuse.mrays_per_s", "%.4f"},
	{"rays.device_stackless.diffuse.wall_mrays_per_s", "%.4f"},
	{"rays.device_wide8.primary.mrays_per_s", "%.4f"},
	{"rays.device_wide8.primary.wall_mrays_per_s", "%.4f"},
	{"rays.device_wide8.primary.nodes_per_ray", "%.4f"},
	{"rays.device_wide8.diffuse.mrays_per_s", "%.4f"},
	{"rays.device_wide8.diffuse.wall_mrays_per_s", "%.4f"},
	{"load_before", "%.2f"},
	{"load_after", "%.2f"},
	{"device.compute_units", "%.0f"},
	{"memory.runtime_bytes", "%.0f"},
	{"tree.width", "%.0f"},
	{"tree.bytes_per_triangle", "%.3f"},
	{"tree.packed_bytes_per_triangle", "%.3f"},
	{"tree.cwbvh_bytes_per_triangle", "%.3f"},
	{"rays.shadow.mrays_per_s", "%.4f"},
	{"rays.shadow.nodes_per_ray", "%.4f"},
	{"rays.shadow.tris_per_ray", "%.4f"},
	{"rays.ao.mrays_per_s", "%.4f"},
	{"rays.ao.nodes_per_ray", "%.4f"},
	{"rays.ao.tris_per_ray", "%.4f"},
	{"rays.stack.shadow.mrays_per_s", "%.4f"},
	{"rays.stack.ao.mrays_per_s", "%.4f"},
	{"rays.stackless.shadow.mrays_per_s", "%.4f"},
	{"rays.stackless.ao.mrays_per_s", "%.4f"},
	{"rays.wide.shadow.mrays_per_s", "%.4f"},
	{"rays.wide.ao.mrays_per_s", "%.4f"},
	{"rays.wide4.primary.mrays_per_s", "%.4f"},
	{"rays.wide4.diffuse.mrays_per_s", "%.4f"},
	{"rays.wide8.primary.mrays_per_s", "%.4f"},
	{"rays.wide8.diffuse.mrays_per_s", "%.4f"},
	{"rays.wide8.shadow.mrays_per_s", "%.4f"},
	{"rays.wide8.ao.mrays_per_s", "%.4f"},
	{"two_level.bottom.build_ms", "%.4f"},
	{"two_level.top.build_ms", "%.4f"},
	{"two_level.build_ms", "%.4f"},
	{"two_level.bottom.nodes", "%.0f"},
	{"two_level.top.nodes", "%.0f"},
	{"two_level.bottom.sah_cost", "%.4f"},
	{"two_level.top.sah_cost", "%.4f"},
	{"two_level.sah_cost", "%.4f"},
	{"memory.scene_bytes", "%.0f"},
	{"memory.build_bytes_per_triangle", "%.2f"},
	{"memory.with_scene_bytes_per_triangle", "%.2f"},
	{"memory.child_bytes_per_triangle", "%.2f"},
	{"memory.scene_bytes_per_triangle", "%.2f"},
	{"memory.run_bytes_per_triangle", "%.2f"},
};

/* build_phases as one field, "upload=1.2345;device=3.4567": the phases vary
 * by builder, so they do not get a column each. */
static void csv_phases(struct strbuf *sb, const cJSON *phases)
{
	struct strbuf f = {0};
	const cJSON *p;
	cJSON_ArrayForEach(p, phases)
		if (cJSON_IsNumber(p) && p->string)
			sb_printf(&f, "%s%s=%.4f", f.len ? ";" : "", p->string, p->valuedouble);
	char *text = sb_take(&f);
	report_csv_field(sb, text ? text : "", false);
	free(text);
}

static void csv_row(struct strbuf *sb, const cJSON *run)
{
	char buf[64];
	report_csv_field(sb, report_str(run, "scene"), false);
	report_csv_field(sb, report_str(run, "builder"), false);
	report_csv_field(sb, report_str(run, "plugin"), false);
	report_csv_field(sb, report_str(run, "status"), false);
	for (size_t k = 0; k < sizeof(csv_numbers) / sizeof(csv_numbers[0]); k++)
		report_csv_field(sb, num(buf, sizeof(buf), run, csv_numbers[k][0], csv_numbers[k][1]), false);
	const cJSON *trav = report_at(run, "rays.traversal");
	report_csv_field(sb, cJSON_IsString(trav) ? trav->valuestring : "", false);
	const cJSON *valid = report_at(run, "validation.valid");
	report_csv_field(sb, cJSON_IsBool(valid) ? (cJSON_IsTrue(valid) ? "true" : "false") : "", false);
	report_csv_field(sb, report_str(run, "device.name"), false);
	report_csv_field(sb, report_str(run, "device.kind"), false);
	csv_phases(sb, cJSON_GetObjectItemCaseSensitive(run, "build_phases"));
	report_csv_field(sb, report_str(run, "error"), true);
}

char *report_csv(const cJSON *doc)
{
	struct strbuf sb = {0};
	sb_printf(&sb, "scene,builder,plugin,status");
	for (size_t k = 0; k < sizeof(csv_numbers) / sizeof(csv_numbers[0]); k++)
		sb_printf(&sb, ",%s", csv_numbers[k][0]);
	sb_printf(&sb, ",rays.traversal,validation.valid,device.name,device.kind,build_phases,"
	          "error\n");
	const cJSON *run;
	cJSON_ArrayForEach(run, cJSON_GetObjectItem(doc, "runs"))
		csv_row(&sb, run);
	return sb_take(&sb);
}

/* The Markdown run table's number columns (key, format), before the
 * speedup and after it. */
static const char *const md_times[][2] = {
	{"build_ms.median", "%.2f"}, {"build_ms.min", "%.2f"}, {"build_ms.max", "%.2f"},
	{"build_ms.cold", "%.2f"}, {"mtris_per_s", "%.2f"},
};
static const char *const md_figures[][2] = {
	{"tree.sah_cost", "%.3f"}, {"tree.epo", "%.3f"}, {"memory.peak_bytes", "%.0f"},
	{"rays.primary.mrays_per_s", "%.2f"}, {"rays.primary.nodes_per_ray", "%.1f"},
	{"rays.diffuse.mrays_per_s", "%.2f"}, {"rays.diffuse.nodes_per_ray", "%.1f"},
	{"tree.nodes", "%.0f"}, {"tree.max_depth", "%.0f"}, {"tree.avg_leaf_size", "%.2f"},
	{"tree.refs", "%.0f"}, {"tree.dup_ratio", "%.3f"},
};

static void md_numbers(struct strbuf *sb, const cJSON *run, const char *const (*cols)[2],
                       size_t count)
{
	char buf[64];
	for (size_t k = 0; k < count; k++)
		report_md_cell(sb, num(buf, sizeof(buf), run, cols[k][0], cols[k][1]));
}

static void md_run_row(struct strbuf *sb, const struct report_index *ix, const cJSON *run,
                       bool phases)
{
	char buf[400];
	sb_printf(sb, "|");
	report_md_cell(sb, report_str(run, "builder"));
	report_md_cell(sb, report_on_device(run) ? "device" /* its host thread says nothing */
	                                         : num(buf, sizeof(buf), run, "threads", "%.0f"));
	report_md_cell(sb, report_str(run, "status"));
	md_numbers(sb, run, md_times, sizeof(md_times) / sizeof(md_times[0]));
	double speedup = report_speedup(ix, run);
	snprintf(buf, sizeof(buf), "%.2f", speedup);
	report_md_cell(sb, isnan(speedup) ? "" : buf);
	md_numbers(sb, run, md_figures, sizeof(md_figures) / sizeof(md_figures[0]));
	report_md_cell(sb, report_run_marks(buf, sizeof(buf), ix, run));
	if (phases)
		report_md_cell(sb, report_phases(buf, sizeof(buf), run));
	report_md_cell(sb, report_str(run, "error"));
	sb_printf(sb, "\n");
}

/* "a 0 to 35, b 0 to 45": each heat map's own scale. */
static void md_own_scales(struct strbuf *sb, const cJSON *scene, const cJSON *const *runs,
                          size_t n)
{
	const char *sep = "";
	for (size_t k = 0; k < n; k++) {
		double lo, hi;
		if (!*report_str(runs[k], "heat_image") || !report_heat_scale(scene, runs[k], &lo, &hi))
			continue;
		sb_printf(sb, "%s", sep);
		report_md_text(sb, report_str(runs[k], "builder"));
		sb_printf(sb, " x%.0f %.0f to %.0f", report_num(runs[k], "threads"), lo, hi);
		sep = ", ";
	}
}

/* The scene's images, when the run drew them (paths relative to the
 * report). Heat maps drawn on different scales (a merged sweep's parts)
 * each get theirs: one stated scale would misread the others. */
static void md_images(struct strbuf *sb, const cJSON *scene, const cJSON *const *runs, size_t n)
{
	const char *shaded = report_str(scene, "images.shaded");
	const char *legend = report_str(scene, "images.legend");
	const char *kind = strcmp(report_str(scene, "images.heat_scale"), "log") == 0 ? "log"
	                                                                              : "linear";
	if (*shaded) {
		sb_printf(sb, "\n![");
		report_md_text(sb, report_str(scene, "name"));
		sb_printf(sb, "](%s)\n", shaded);
	}
	if (report_heat_scales_differ(scene, runs, n)) {
		sb_printf(sb, "\nHeat maps (nodes visited per primary ray, %s scale) per builder in "
		              "report.html, drawn on different scales, each its own: ", kind);
		md_own_scales(sb, scene, runs, n);
		sb_printf(sb, ".\n");
	} else if (*legend) {
		sb_printf(sb, "\nHeat maps (nodes visited per primary ray, %.0f to %.0f, %s scale): "
		              "![scale](%s) and per builder in report.html.\n",
		          report_num(scene, "images.heat_min"), report_num(scene, "images.heat_max"),
		          kind, legend);
	}
}

static void md_scene(struct strbuf *sb, const struct report_index *ix, const char *ref,
                     const cJSON *scene)
{
	const char *name = report_str(scene, "name");
	char buf[64];
	sb_printf(sb, "\n## ");
	report_md_text(sb, name);
	sb_printf(sb, "\n\n");
	report_md_text(sb, report_str(scene, "source"));
	sb_printf(sb, ", %s triangles", num(buf, sizeof(buf), scene, "triangles", "%.0f"));
	report_scene_instances(sb, scene);
	if (*report_str(scene, "error")) {
		sb_printf(sb, ". **Could not be loaded:** ");
		report_md_text(sb, report_str(scene, "error"));
	}
	sb_printf(sb, "\n\n| builder | threads | status | median ms | min ms | max ms | cold ms "
	              "| Mtris/s | speedup | SAH cost | EPO | peak bytes | primary Mrays/s (best tile) "
	              "| primary nodes/ray | diffuse Mrays/s (best tile) | diffuse nodes/ray | nodes "
	              "| depth | avg leaf | refs | refs/tri | marks |");
	size_t n;
	const cJSON *const *runs = report_scene_runs(ix, name, &n);
	bool phases = report_any_phases(runs, n);
	sb_printf(sb, "%s error |\n|---|---:|---|---:|---:|---:|---:|---:|---:|---:|---:|---:|---:"
	              "|---:|---:|---:|---:|---:|---:|---:|---:|---|%s---|\n",
	          phases ? " build phases ms |" : "", phases ? "---|" : "");
	for (size_t k = 0; k < n; k++)
		md_run_row(sb, ix, runs[k], phases);
	report_kinds(sb, runs, n, false);
	report_two_level_md(sb, runs, n);
	report_memory_md(sb, runs, n);
	report_front_md(sb, ix, runs, n);
	report_budget_md(sb, ix, name);
	report_breakeven_md(sb, ix, ref, runs, n);
	report_wide_md(sb, ix, runs, n);
	md_images(sb, scene, runs, n);
	report_frames_md(sb, ix, scene); /* an animated scene's frames */
}

char *report_markdown(const cJSON *doc)
{
	struct strbuf sb = {0};
	const cJSON *runs = cJSON_GetObjectItem(doc, "runs");
	int total = cJSON_GetArraySize(runs), ok = 0;
	const cJSON *run, *scene;
	cJSON_ArrayForEach(run, runs)
		ok += strcmp(report_str(run, "status"), "ok") == 0;
	sb_printf(&sb, "# bvhlab report\n\n");
	report_byline(&sb, doc, report_md_text);
	sb_printf(&sb, ", %s cores, %s available "
	               "to this process.\n\n%d runs, %d ok. Times are build times in ms over "
	               "the timed repeats; SAH cost with c_trav = c_isect = 1, normalised by "
	               "the root's surface area; EPO: end-point overlap, sampled. Peak bytes: "
	               "what the builds added to the process's resident set at its peak. "
	               "Speedup: over the same builder's 1-thread run. Rays (primary from the "
	               "camera, diffuse bounces from their hits) are traced with the same "
	               "threads for every run, whatever its build thread count, so traversal "
	               "numbers compare trees; Mrays/s: rays per CPU second of the tracing "
	               "threads times their number, each tile of rays at its best of the "
	               "repeated passes (best tile; spread over rays.rounds rounds taken in turn "
	               "by the scene's trees), by the run's rays.traversal (default wide: the tree "
	               "collapsed into 4-child nodes); nodes and triangles per ray are the "
	               "binary tree's, counted by the stack traversal, whichever is timed. "
	               "Marks: noisy where the build repeats spread more than 5 %% or a run "
	               "of the same tree traced more than 5 %% faster or slower; busy where "
	               "other processes kept more CPUs busy than the run left free.\n",
	          num((char[32]){0}, 32, doc, "machine.cores", "%.0f"),
	          num((char[32]){0}, 32, doc, "machine.threads_available", "%.0f"), total, ok);
	struct report_index ix;
	if (report_index_init(&ix, doc) < 0)
		sb.failed = true;
	const char *asked, *ref = report_reference(doc, &asked, &(bool){false});
	report_load_warning(&sb, doc, false);
	if (*report_str(doc, "report_note")) /* bvhlab report --scene/--threads */
		sb_printf(&sb, "\n**%s**\n", report_str(doc, "report_note"));
	report_summary_md(&sb, &ix);
	report_machines_md(&sb, doc);
	report_thesis(&sb, doc, &ix);
	report_scale_md(&sb, &ix);
	cJSON_ArrayForEach(scene, cJSON_GetObjectItem(doc, "scenes"))
		md_scene(&sb, &ix, ref, scene);
	report_index_finish(&ix);
	return sb_take(&sb);
}
