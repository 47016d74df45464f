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
                                  const char *scene, long machine, double threads)
{
	size_t n;
	const cJSON *const *runs = report_scene_runs(ix, scene, &n), *best = NULL;
	for (size_t k = 0; ref && k < n; k++) {
		if (!is_ok(runs[k]) || strcmp(report_str(runs[k], "builder"), ref) != 0 ||
		    (machine >= 0 && report_machine_number(ix, runs[k]) != machine))
			continue;
		double t = report_num(runs[k], "threads");
		if (t == threads)
			return runs[k];
		if (!best || t < report_num(best, "threads"))
			best = runs[k];
	}
	return best;
}

/* Whether an earlier run already has this builder, thread count and machine. */
static bool seen_before(const struct report_index *ix, const cJSON *runs, const cJSON *upto)
{
	const cJSON *run;
	cJSON_ArrayForEach(run, runs) {
		if (run == upto)
			return false;
		if (strcmp(report_str(run, "builder"), report_str(upto, "builder")) == 0 &&
		    report_num(run, "threads") == report_num(upto, "threads") &&
		    report_machine_number(ix, run) == report_machine_number(ix, upto))
			return true;
	}
	return false;
}

/* Geometric means over scenes for the builder, thread count and machine of
 * `first`, each run against the reference's on its scene and machine: a
 * ratio of two machines' times would measure the machines. */
static void summarise(const struct report_index *ix, const char *ref, const cJSON *first,
                      struct summary_row *row)
{
	double logs[SUMMARY_METRICS] = {0};
	int counts[SUMMARY_METRICS] = {0};
	const cJSON *run;
	memset(row, 0, sizeof(*row));
	row->builder = report_str(first, "builder");
	row->threads = report_num(first, "threads");
	row->machine = report_machine_number(ix, first);
	cJSON_ArrayForEach(run, cJSON_GetObjectItem(ix->doc, "runs")) {
		if (!is_ok(run) || strcmp(report_str(run, "builder"), row->builder) != 0 ||
		    report_num(run, "threads") != row->threads ||
		    report_machine_number(ix, run) != row->machine)
			continue;
		const cJSON *base = report_reference_run(ix, ref, report_str(run, "scene"),
		                                         row->machine, NAN);
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

int report_summary(const struct report_index *ix, struct summary_row **rows, const char **ref)
{
	const cJSON *runs = cJSON_GetObjectItem(ix->doc, "runs"), *run;
	const char *asked;
	bool fallback;
	int n = 0;
	*rows = NULL;
	*ref = report_reference(ix->doc, &asked, &fallback);
	if (!*ref)
		return 0;
	*rows = calloc((size_t)cJSON_GetArraySize(runs) + 1, sizeof(**rows));
	if (!*rows)
		return 0;
	cJSON_ArrayForEach(run, runs)
		if (!seen_before(ix, runs, run))
			summarise(ix, *ref, run, &(*rows)[n++]);
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

/* Whether the row's builder has a row with more than 1 thread on its machine. */
static bool has_parallel_row(const struct summary_row *rows, int n, const struct summary_row *r)
{
	for (int i = 0; i < n; i++)
		if (rows[i].threads > 1 && rows[i].machine == r->machine &&
		    strcmp(rows[i].builder, r->builder) == 0)
			return true;
	return false;
}

/* Rows compete within one machine, thread count and scene count. */
static struct front_point row_point(const struct summary_row *r, double threads)
{
	long group = report_front_group(r->machine, threads) * 100000 + r->scenes;
	return (struct front_point){r->ratio[0], r->ratio[1], group};
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
		for (int j = 0; j < t && first; j++) /* each thread count and machine once */
			first = rows[j].threads != rows[t].threads || rows[j].machine != rows[t].machine;
		for (int i = 0; first && i < n; i++)
			if (rows[i].threads == 1 && rows[i].machine == rows[t].machine &&
			    !has_parallel_row(rows, n, &rows[i]))
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

static const char machines_note[] =
	"The runs come from %zu machines (see Machines): a row holds one machine's runs, "
	"each set against the reference's run on the same scene and machine, never "
	"another machine's; n/a where the reference did not run on that machine.";

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
	bool machines; /* runs from several machines: a machine column */
};

static bool summary_init(struct summary *s, const struct report_index *ix)
{
	s->machines = ix->machine_count > 1;
	s->n = report_summary(ix, &s->rows, &s->ref);
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

void report_summary_md(struct strbuf *sb, const struct report_index *ix)
{
	struct summary s;
	char buf[256];
	sb_printf(sb, "\n## Summary\n\n");
	if (!summary_init(&s, ix)) {
		sb_printf(sb, "No ok run, so no summary.\n");
		summary_finish(&s);
		return;
	}
	fallback_note(sb, ix->doc, s.ref, false);
	struct strbuf ref = {0};
	report_md_text(&ref, s.ref);
	char *ref_text = sb_take(&ref);
	sb_printf(sb, intro, ref_text ? ref_text : "");
	free(ref_text);
	if (s.machines) {
		sb_printf(sb, machines_note, ix->machine_count);
		sb_printf(sb, "\n\n");
	}
	sb_printf(sb, "| builder | threads |%s scenes |", s.machines ? " machine |" : "");
	for (int m = 0; m < SUMMARY_METRICS; m++)
		sb_printf(sb, " %s |", metric_names[m]);
	sb_printf(sb, " Pareto (time × SAH) |\n|---|---:|%s---:|---:|---:|---:|---:|---:|---|\n",
	          s.machines ? "---|" : "");
	for (int i = 0; i < s.n; i++) {
		sb_printf(sb, "|");
		report_md_cell(sb, s.rows[i].builder);
		sb_printf(sb, " %.0f |", s.rows[i].threads);
		if (s.machines)
			sb_printf(sb, " M%ld |", s.rows[i].machine + 1);
		sb_printf(sb, " %d |", s.rows[i].scenes);
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
	sb_printf(sb, "</td><td>%.0f</td>", s->rows[i].threads);
	if (s->machines)
		sb_printf(sb, "<td>M%ld</td>", s->rows[i].machine + 1);
	sb_printf(sb, "<td>%d</td>", s->rows[i].scenes);
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

void report_summary_html(struct strbuf *sb, const struct report_index *ix)
{
	struct summary s;
	sb_printf(sb, "<h2 id=\"summary\">Summary</h2>\n");
	if (!summary_init(&s, ix)) {
		sb_printf(sb, "<p>No ok run, so no summary.</p>\n");
		summary_finish(&s);
		return;
	}
	fallback_note(sb, ix->doc, s.ref, true);
	sb_printf(sb, "<p>Geometric mean over scenes of each figure relative to the reference "
	              "builder <b>");
	report_escape(sb, s.ref);
	sb_printf(sb, "</b> on the same scene (its run with the fewest threads); below 1 is less "
	              "build time, a cheaper tree (SAH, end-point overlap) or fewer nodes "
	              "visited per ray. Pareto: among the rows of the same thread count over "
	              "as many scenes (a builder that ran on 1 thread only counts at every "
	              "thread count), on the front of build time against SAH cost, or the "
	              "fastest row on it at least as fast and as good.</p>\n");
	if (s.machines) {
		sb_printf(sb, "<p class=\"warn\">");
		sb_printf(sb, machines_note, ix->machine_count);
		sb_printf(sb, "</p>\n");
	}
	sb_printf(sb, "<table class=\"summary\"><tr><th class=\"l\">builder</th><th>threads</th>"
	              "%s<th>scenes</th>", s.machines ? "<th>machine</th>" : "");
	for (int m = 0; m < SUMMARY_METRICS; m++)
		sb_printf(sb, "<th>%s</th>", metric_names[m]);
	sb_printf(sb, "<th class=\"l\">Pareto (time × SAH)</th></tr>\n");
	for (int i = 0; i < s.n; i++)
		html_row(sb, &s, i);
	sb_printf(sb, "</table>\n");
	summary_finish(&s);
}
