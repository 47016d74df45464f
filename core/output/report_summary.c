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
 * plugin, or when neither ran the first builder that did (the summary says
 * so); on each scene its ok run with the fewest threads.
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

/* The first builder with an ok run, or NULL. */
static const char *first_ok_builder(const cJSON *runs)
{
	const cJSON *run;
	cJSON_ArrayForEach(run, runs)
		if (is_ok(run))
			return report_str(run, "builder");
	return NULL;
}

const char *report_reference(const cJSON *doc, const char **asked, bool *fallback)
{
	const cJSON *runs = cJSON_GetObjectItem(doc, "runs"), *run;
	const char *ref = report_str(doc, "config.report.reference");
	*asked = *ref ? ref : DEFAULT_REFERENCE;
	*fallback = false;
	cJSON_ArrayForEach(run, runs)
		if (is_ok(run) && strcmp(report_str(run, "builder"), *asked) == 0)
			return report_str(run, "builder");
	cJSON_ArrayForEach(run, runs)
		if (is_ok(run) && strcmp(report_str(run, "plugin"), *asked) == 0)
			return report_str(run, "builder");
	*fallback = true;
	return first_ok_builder(runs);
}

const cJSON *report_reference_run(const struct report_index *ix, const char *ref,
                                  const char *scene, double threads)
{
	size_t n;
	const cJSON *const *runs = report_scene_runs(ix, scene, &n), *best = NULL;
	for (size_t k = 0; ref && k < n; k++) {
		if (!is_ok(runs[k]) || strcmp(report_str(runs[k], "builder"), ref) != 0)
			continue;
		double t = report_num(runs[k], "threads");
		if (t == threads)
			return runs[k];
		if (!best || t < report_num(best, "threads"))
			best = runs[k];
	}
	return best;
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
	bool fallback;
	int n = 0;
	*rows = NULL;
	*ref = report_reference(doc, &asked, &fallback);
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

/* Whether the builder has a row with more than 1 thread. */
static bool has_parallel_row(const struct summary_row *rows, int n, const char *builder)
{
	for (int i = 0; i < n; i++)
		if (rows[i].threads > 1 && strcmp(rows[i].builder, builder) == 0)
			return true;
	return false;
}

static struct front_point row_point(const struct summary_row *r, double threads)
{
	return (struct front_point){r->ratio[0], r->ratio[1], (long)threads * 100000 + r->scenes};
}

/* The rows' points, then a stand-in at every other thread count for each
 * row of a builder that ran on 1 thread only (it is a choice there too);
 * map[k]: the row point k stands for. Returns the count. */
static size_t with_stand_ins(const struct summary_row *rows, int n, struct front_point *q,
                             int *map)
{
	size_t m = 0;
	for (int i = 0; i < n; i++, m++)
		q[m] = row_point(&rows[i], rows[i].threads), map[m] = i;
	for (int t = 0; t < n; t++) {
		bool first = rows[t].threads > 1;
		for (int j = 0; j < t && first; j++) /* each thread count once */
			first = rows[j].threads != rows[t].threads;
		for (int i = 0; first && i < n; i++)
			if (rows[i].threads == 1 && !has_parallel_row(rows, n, rows[i].builder))
				q[m] = row_point(&rows[i], rows[t].threads), map[m++] = i;
	}
	return m;
}

void report_summary_fronts(const struct summary_row *rows, int n, struct front_point *p,
                           long *by)
{
	size_t cap = (size_t)n * ((size_t)n + 1) + 1;
	struct front_point *q = calloc(cap, sizeof(*q));
	long *qb = calloc(cap, sizeof(*qb));
	int *map = calloc(cap, sizeof(*map));
	size_t m = q && qb && map ? with_stand_ins(rows, n, q, map) : 0;
	report_front_points(q, m, qb);
	for (int i = 0; i < n; i++) {
		p[i] = row_point(&rows[i], rows[i].threads);
		by[i] = (size_t)i >= m ? FRONT_NONE : qb[i] >= 0 ? map[qb[i]] : qb[i];
	}
	free(q);
	free(qb);
	free(map);
}

static const char intro[] =
	"Geometric mean over scenes of each figure relative to the reference builder "
	"**%s** on the same scene (its run with the fewest threads); below 1 is less "
	"build time, a cheaper tree (SAH, end-point overlap) or fewer nodes visited per "
	"ray. Scenes: how many had ok runs of both. Pareto: among the rows of the same "
	"thread count over as many scenes (a builder that ran on 1 thread only counts at "
	"every thread count), on the front of build time against SAH cost, or the fastest "
	"row on it that is at least as fast and as good.\n\n";

/* Where the configured reference did not run: which builder stands in. */
static void fallback_note(struct strbuf *sb, const cJSON *doc, const char *ref, bool html)
{
	const char *asked;
	bool fallback;
	report_reference(doc, &asked, &fallback);
	if (!fallback)
		return;
	sb_printf(sb, html ? "<p class=\"warn\">" : "");
	sb_printf(sb, "The reference builder asked for (report.reference: '");
	report_escape(sb, asked);
	sb_printf(sb, "') did not run, so the reference is the first builder that did: ");
	report_escape(sb, ref);
	sb_printf(sb, html ? ".</p>\n" : ".\n\n");
}

/* The row's Pareto verdict, in words. */
static const char *front_text(char *buf, size_t size, const struct summary_row *rows,
                              const struct front_point *p, const long *by, int i)
{
	report_front_text(buf, size, p, by[i], (size_t)i, by[i] >= 0 ? rows[by[i]].builder : "",
	                  "SAH");
	return buf;
}

struct summary {
	struct summary_row *rows;
	const char *ref;
	int n;
	struct front_point *p;
	long *by;
};

static bool summary_init(struct summary *s, const cJSON *doc)
{
	s->n = report_summary(doc, &s->rows, &s->ref);
	s->p = calloc((size_t)s->n + 1, sizeof(*s->p));
	s->by = calloc((size_t)s->n + 1, sizeof(*s->by));
	if (s->n > 0 && s->p && s->by)
		report_summary_fronts(s->rows, s->n, s->p, s->by);
	return s->n > 0 && s->p && s->by;
}

static void summary_finish(struct summary *s)
{
	free(s->rows);
	free(s->p);
	free(s->by);
}

void report_summary_md(struct strbuf *sb, const cJSON *doc)
{
	struct summary s;
	char buf[256];
	sb_printf(sb, "\n## Summary\n\n");
	if (!summary_init(&s, doc)) {
		sb_printf(sb, "No ok run, so no summary.\n");
		summary_finish(&s);
		return;
	}
	fallback_note(sb, doc, s.ref, false);
	sb_printf(sb, intro, s.ref);
	sb_printf(sb, "| builder | threads | scenes |");
	for (int m = 0; m < SUMMARY_METRICS; m++)
		sb_printf(sb, " %s |", metric_names[m]);
	sb_printf(sb, " Pareto (time × SAH) |\n|---|---:|---:|---:|---:|---:|---:|---:|---|\n");
	for (int i = 0; i < s.n; i++) {
		sb_printf(sb, "|");
		report_md_cell(sb, s.rows[i].builder);
		sb_printf(sb, " %.0f | %d |", s.rows[i].threads, s.rows[i].scenes);
		for (int m = 0; m < SUMMARY_METRICS; m++)
			sb_printf(sb, " %s |", ratio_text(buf, sizeof(buf), s.rows[i].ratio[m]));
		report_md_cell(sb, front_text(buf, sizeof(buf), s.rows, s.p, s.by, i));
		sb_printf(sb, "\n");
	}
	summary_finish(&s);
}

static void html_row(struct strbuf *sb, const struct summary *s, int i)
{
	char buf[256];
	sb_printf(sb, "<tr><td class=\"l\">");
	report_escape(sb, s->rows[i].builder);
	sb_printf(sb, "</td><td>%.0f</td><td>%d</td>", s->rows[i].threads, s->rows[i].scenes);
	for (int m = 0; m < SUMMARY_METRICS; m++) {
		double r = s->rows[i].ratio[m];
		sb_printf(sb, "<td%s>%s</td>",
		          isfinite(r) && r < 0.995 ? " class=\"good\""
		          : isfinite(r) && r > 1.005 ? " class=\"worse\"" : "",
		          ratio_text(buf, sizeof(buf), r));
	}
	sb_printf(sb, "<td class=\"l%s\">", s->by[i] == FRONT_ON ? " front" : "");
	report_escape(sb, front_text(buf, sizeof(buf), s->rows, s->p, s->by, i));
	sb_printf(sb, "</td></tr>\n");
}

void report_summary_html(struct strbuf *sb, const cJSON *doc)
{
	struct summary s;
	sb_printf(sb, "<h2 id=\"summary\">Summary</h2>\n");
	if (!summary_init(&s, doc)) {
		sb_printf(sb, "<p>No ok run, so no summary.</p>\n");
		summary_finish(&s);
		return;
	}
	fallback_note(sb, doc, s.ref, true);
	sb_printf(sb, "<p>Geometric mean over scenes of each figure relative to the reference "
	              "builder <b>");
	report_escape(sb, s.ref);
	sb_printf(sb, "</b> on the same scene (its run with the fewest threads); below 1 is less "
	              "build time, a cheaper tree (SAH, end-point overlap) or fewer nodes "
	              "visited per ray. Pareto: among the rows of the same thread count over "
	              "as many scenes (a builder that ran on 1 thread only counts at every "
	              "thread count), on the front of build time against SAH cost, or the "
	              "fastest row on it at least as fast and as good.</p>\n"
	              "<table class=\"summary\">"
	              "<tr><th class=\"l\">builder</th><th>threads</th><th>scenes</th>");
	for (int m = 0; m < SUMMARY_METRICS; m++)
		sb_printf(sb, "<th>%s</th>", metric_names[m]);
	sb_printf(sb, "<th class=\"l\">Pareto (time × SAH)</th></tr>\n");
	for (int i = 0; i < s.n; i++)
		html_row(sb, &s, i);
	sb_printf(sb, "</table>\n");
	summary_finish(&s);
}
