/*
 * The summary at the top of report.md and report.html: "which builder?"
 * across scenes. One row per builder and thread count, each figure the
 * geometric mean over scenes of the run's value divided by the reference
 * builder's on the same scene (below 1: less time, a cheaper tree, fewer
 * nodes per ray). A geometric mean of ratios does not depend on which
 * builder is the reference, and a scene where everything is slow counts
 * no more than one where everything is fast.
 *
 * The reference is the config's "report": {"reference"} (default
 * "sah_seq"): a builder name, or failing that the first builder of that
 * plugin; on each scene its ok run with the fewest threads.
 */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "output/report.h"
#include "output/results.h"

#define DEFAULT_REFERENCE "sah_seq"

/* The figures the summary compares, as dotted paths in a run. */
static const char *const metric_paths[SUMMARY_METRICS] = {
	"build_ms.median", "tree.sah_cost", "tree.epo", "rays.primary.nodes_per_ray",
	"rays.diffuse.nodes_per_ray",
};
static const char *const metric_names[SUMMARY_METRICS] = {
	"build time", "SAH cost", "EPO", "primary nodes/ray", "diffuse nodes/ray",
};

static bool is_ok(const cJSON *run)
{
	return strcmp(report_str(run, "status"), "ok") == 0;
}

/* The builder label the reference names: a builder, else a plugin's first. */
static const char *reference_builder(const cJSON *doc, const char **asked)
{
	const cJSON *runs = cJSON_GetObjectItem(doc, "runs"), *run;
	const char *ref = report_str(doc, "config.report.reference");
	*asked = *ref ? ref : DEFAULT_REFERENCE;
	cJSON_ArrayForEach(run, runs)
		if (strcmp(report_str(run, "builder"), *asked) == 0)
			return *asked;
	cJSON_ArrayForEach(run, runs)
		if (strcmp(report_str(run, "plugin"), *asked) == 0)
			return report_str(run, "builder");
	return NULL;
}

/* The reference's ok run on a scene with the fewest threads, or NULL. */
static const cJSON *reference_run(const cJSON *runs, const char *ref, const char *scene)
{
	const cJSON *run, *best = NULL;
	cJSON_ArrayForEach(run, runs) {
		if (!is_ok(run) || strcmp(report_str(run, "builder"), ref) != 0 ||
		    strcmp(report_str(run, "scene"), scene) != 0)
			continue;
		if (!best || report_num(run, "threads") < report_num(best, "threads"))
			best = run;
	}
	return best;
}

/* Whether an earlier run already has this builder and thread count. */
static bool seen_before(const cJSON *runs, const cJSON *upto)
{
	const cJSON *run;
	cJSON_ArrayForEach(run, runs) {
		if (run == upto)
			return false;
		if (strcmp(report_str(run, "builder"), report_str(upto, "builder")) == 0 &&
		    report_num(run, "threads") == report_num(upto, "threads"))
			return true;
	}
	return false;
}

/* Geometric means over scenes for the builder and thread count of `first`. */
static void summarise(const cJSON *runs, const char *ref, const cJSON *first,
                      struct summary_row *row)
{
	double logs[SUMMARY_METRICS] = {0};
	int counts[SUMMARY_METRICS] = {0};
	const cJSON *run;
	memset(row, 0, sizeof(*row));
	row->builder = report_str(first, "builder");
	row->threads = report_num(first, "threads");
	cJSON_ArrayForEach(run, runs) {
		if (!is_ok(run) || strcmp(report_str(run, "builder"), row->builder) != 0 ||
		    report_num(run, "threads") != row->threads)
			continue;
		const cJSON *base = reference_run(runs, ref, report_str(run, "scene"));
		row->scenes += base != NULL;
		for (int m = 0; base && m < SUMMARY_METRICS; m++) {
			double r = report_num(run, metric_paths[m]) / report_num(base, metric_paths[m]);
			if (isfinite(r) && r > 0) {
				logs[m] += log(r);
				counts[m]++;
			}
		}
	}
	for (int m = 0; m < SUMMARY_METRICS; m++)
		row->ratio[m] = counts[m] ? exp(logs[m] / counts[m]) : NAN;
}

int report_summary(const cJSON *doc, struct summary_row **rows, const char **ref)
{
	const cJSON *runs = cJSON_GetObjectItem(doc, "runs"), *run;
	const char *asked;
	int n = 0;
	*rows = NULL;
	*ref = reference_builder(doc, &asked);
	if (!*ref)
		return 0;
	*rows = calloc((size_t)cJSON_GetArraySize(runs) + 1, sizeof(**rows));
	if (!*rows)
		return 0;
	cJSON_ArrayForEach(run, runs)
		if (!seen_before(runs, run))
			summarise(runs, *ref, run, &(*rows)[n++]);
	return n;
}

const char *report_summary_metric(int m)
{
	return metric_names[m];
}

/* "0.52x", or "n/a" when no scene had both values. */
static const char *ratio_text(char *buf, size_t size, double r)
{
	if (!isfinite(r))
		return "n/a";
	snprintf(buf, size, "%.2f×", r);
	return buf;
}

static const char intro[] =
	"Geometric mean over scenes of each figure relative to the reference builder "
	"**%s** on the same scene (its run with the fewest threads); below 1 is less "
	"build time, a cheaper tree (SAH, end-point overlap) or fewer nodes visited per "
	"ray. Scenes: how many had ok runs of both.\n\n";

void report_summary_md(struct strbuf *sb, const cJSON *doc)
{
	struct summary_row *rows;
	const char *ref;
	char buf[32];
	int n = report_summary(doc, &rows, &ref);
	sb_printf(sb, "\n## Summary\n\n");
	if (n == 0) {
		sb_printf(sb, "No run of the reference builder '%s', so no summary.\n",
		          *report_str(doc, "config.report.reference")
		                  ? report_str(doc, "config.report.reference")
		                  : DEFAULT_REFERENCE);
		free(rows);
		return;
	}
	sb_printf(sb, intro, ref);
	sb_printf(sb, "| builder | threads | scenes |");
	for (int m = 0; m < SUMMARY_METRICS; m++)
		sb_printf(sb, " %s |", metric_names[m]);
	sb_printf(sb, "\n|---|---:|---:|---:|---:|---:|---:|---:|\n");
	for (int i = 0; i < n; i++) {
		sb_printf(sb, "| %s | %.0f | %d |", rows[i].builder, rows[i].threads, rows[i].scenes);
		for (int m = 0; m < SUMMARY_METRICS; m++)
			sb_printf(sb, " %s |", ratio_text(buf, sizeof(buf), rows[i].ratio[m]));
		sb_printf(sb, "\n");
	}
	free(rows);
}

void report_summary_html(struct strbuf *sb, const cJSON *doc)
{
	struct summary_row *rows;
	const char *ref;
	char buf[32];
	int n = report_summary(doc, &rows, &ref);
	sb_printf(sb, "<h2 id=\"summary\">Summary</h2>\n");
	if (n == 0) {
		sb_printf(sb, "<p>No run of the reference builder, so no summary.</p>\n");
		free(rows);
		return;
	}
	sb_printf(sb, "<p>Geometric mean over scenes of each figure relative to the reference "
	              "builder <b>");
	report_escape(sb, ref);
	sb_printf(sb, "</b> on the same scene (its run with the fewest threads); below 1 is less "
	              "build time, a cheaper tree (SAH, end-point overlap) or fewer nodes "
	              "visited per ray.</p>\n<table class=\"summary\"><tr><th class=\"l\">builder"
	              "</th><th>threads</th><th>scenes</th>");
	for (int m = 0; m < SUMMARY_METRICS; m++)
		sb_printf(sb, "<th>%s</th>", metric_names[m]);
	sb_printf(sb, "</tr>\n");
	for (int i = 0; i < n; i++) {
		sb_printf(sb, "<tr><td class=\"l\">");
		report_escape(sb, rows[i].builder);
		sb_printf(sb, "</td><td>%.0f</td><td>%d</td>", rows[i].threads, rows[i].scenes);
		for (int m = 0; m < SUMMARY_METRICS; m++) {
			double r = rows[i].ratio[m];
			sb_printf(sb, "<td%s>%s</td>",
			          isfinite(r) && r < 0.995 ? " class=\"good\""
			          : isfinite(r) && r > 1.005 ? " class=\"worse\"" : "",
			          ratio_text(buf, sizeof(buf), r));
		}
		sb_printf(sb, "</tr>\n");
	}
	sb_printf(sb, "</table>\n");
	free(rows);
}
