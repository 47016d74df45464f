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
	row->device = report_on_device(first);
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

/* "2", or "device" for a device builder's row (its one host thread says
 * nothing of what the device ran on; the fronts put it in a group of its
 * own). */
static const char *threads_cell(char *buf, size_t size, const struct summary_row *row)
{
	if (row->device)
		snprintf(buf, size, "device");
	else
		snprintf(buf, size, "%.0f", row->threads);
	return buf;
}

/* Where a row's runs stand on their scenes' fronts (time × SAH). */
struct row_verdict {
	int on, dominated, compared;
	const char *by[3]; /* the builders that dominate it, the first few */
	int nby;
};

/* The row of the entry's run (its own thread count, not a stand-in's),
 * or -1. */
static int row_of(const struct summary_row *rows, int n, const struct front_entry *e)
{
	double own = report_num(e->run, "threads");
	if (own != e->threads && e->threads != REPORT_DEVICE_GROUP)
		return -1; /* a 1-thread-only builder standing in: its row is at 1 thread */
	for (int i = 0; i < n; i++)
		if (rows[i].threads == own && rows[i].machine == e->machine &&
		    strcmp(rows[i].builder, report_str(e->run, "builder")) == 0)
			return i;
	return -1;
}

static void add_dominator(struct row_verdict *v, const char *name)
{
	for (int k = 0; k < v->nby; k++)
		if (strcmp(v->by[k], name) == 0)
			return;
	if (v->nby < 3)
		v->by[v->nby++] = name;
}

/* One scene's front verdicts added to its rows'. */
static void scene_verdicts(const struct report_index *ix, const struct summary_row *rows, int n,
                           const char *scene, struct row_verdict *v)
{
	size_t count, m;
	const cJSON *const *runs = report_scene_runs(ix, scene, &count);
	struct front_entry *e = report_front_entries(ix, runs, count, &m);
	struct front_point *p = calloc(m + 1, sizeof(*p));
	long *by = calloc(m + 1, sizeof(*by));
	if (e && p && by)
		report_entries_front(e, m, 0, p, by);
	for (size_t k = 0; e && p && by && k < m; k++) {
		int i = row_of(rows, n, &e[k]);
		if (i < 0 || by[k] == FRONT_NONE)
			continue;
		v[i].compared++;
		if (by[k] == FRONT_ON)
			v[i].on++;
		else {
			v[i].dominated++;
			add_dominator(&v[i], report_str(e[by[k]].run, "builder"));
		}
	}
	free(e);
	free(p);
	free(by);
}

/* Every row's verdict over the scenes (calloc'd; NULL on no memory). */
static struct row_verdict *row_verdicts(const struct report_index *ix,
                                        const struct summary_row *rows, int n)
{
	struct row_verdict *v = calloc((size_t)n + 1, sizeof(*v));
	const cJSON *scene;
	cJSON_ArrayForEach(scene, cJSON_GetObjectItem(ix->doc, "scenes"))
		if (v)
			scene_verdicts(ix, rows, n, report_str(scene, "name"), v);
	return v;
}

/* "front on 2 of 3 scenes, dominated on 1 by X", "dominated on 2 of 2
 * scenes by X, Y", "—" where no scene compared it. */
static const char *verdict_text(char *buf, size_t size, const struct row_verdict *v)
{
	if (v->compared == 0) {
		snprintf(buf, size, "—");
		return buf;
	}
	int len = 0;
	if (v->on > 0)
		len = snprintf(buf, size, "front on %d of %d scene%s", v->on, v->compared,
		               v->compared == 1 ? "" : "s");
	if (v->dominated > 0 && len >= 0 && (size_t)len < size) {
		if (v->on)
			len += snprintf(buf + len, size - (size_t)len, ", dominated on %d by ",
			                v->dominated);
		else
			len = snprintf(buf, size, "dominated on %d of %d scene%s by ", v->dominated,
			               v->compared, v->compared == 1 ? "" : "s");
		for (int k = 0; k < v->nby && len >= 0 && (size_t)len < size; k++)
			len += snprintf(buf + len, size - (size_t)len, "%s%s", k ? ", " : "", v->by[k]);
	}
	return buf;
}

static const char intro[] =
	"Geometric mean over scenes of each figure relative to the reference builder "
	"**%s** on the same scene (its run with the fewest threads); below 1 is less "
	"build time, a cheaper tree (SAH, end-point overlap) or fewer nodes visited per "
	"ray. Scenes: how many had ok runs of both. Pareto: on how many of the scenes "
	"that compared it the run is on the scene's front of build time against SAH cost "
	"(the scene's Pareto fronts table, same thread count), and on how many it is "
	"dominated, by whom: a verdict per scene, never one over geometric means of "
	"builders valid on different scenes.\n\n";

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

struct summary {
	struct summary_row *rows;
	const char *ref;
	int n;
	struct row_verdict *v; /* where each row's runs stand on their scenes' fronts */
	bool machines; /* runs from several machines: a machine column */
};

static bool summary_init(struct summary *s, const struct report_index *ix)
{
	s->machines = ix->machine_count > 1;
	s->n = report_summary(ix, &s->rows, &s->ref);
	s->v = row_verdicts(ix, s->rows, s->n);
	return s->n > 0 && s->v;
}

static void summary_finish(struct summary *s)
{
	free(s->rows);
	free(s->v);
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
	report_budget_summary(sb, ix, false);
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
		sb_printf(sb, " %s |", threads_cell(buf, sizeof(buf), &s.rows[i]));
		if (s.machines)
			sb_printf(sb, " M%ld |", s.rows[i].machine + 1);
		sb_printf(sb, " %d |", s.rows[i].scenes);
		for (int m = 0; m < SUMMARY_METRICS; m++)
			sb_printf(sb, " %s |", ratio_text(buf, sizeof(buf), s.rows[i].ratio[m]));
		report_md_cell(sb, verdict_text(buf, sizeof(buf), &s.v[i]));
		sb_printf(sb, "\n");
	}
	summary_finish(&s);
}

static void html_row(struct strbuf *sb, const struct summary *s, int i)
{
	char buf[256];
	sb_printf(sb, "<tr><td class=\"l\">");
	report_escape(sb, s->rows[i].builder);
	sb_printf(sb, "</td><td>%s</td>", threads_cell(buf, sizeof(buf), &s->rows[i]));
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
	const struct row_verdict *v = &s->v[i];
	sb_printf(sb, "<td class=\"l%s\">", v->compared && v->on == v->compared ? " front" : "");
	report_escape(sb, verdict_text(buf, sizeof(buf), v));
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
	report_budget_summary(sb, ix, true);
	fallback_note(sb, ix->doc, s.ref, true);
	sb_printf(sb, "<p>Geometric mean over scenes of each figure relative to the reference "
	              "builder <b>");
	report_escape(sb, s.ref);
	sb_printf(sb, "</b> on the same scene (its run with the fewest threads); below 1 is less "
	              "build time, a cheaper tree (SAH, end-point overlap) or fewer nodes "
	              "visited per ray. Pareto: on how many of the scenes that compared it the "
	              "run is on the scene's front of build time against SAH cost (same "
	              "thread count), and on how many it is dominated, by whom.</p>\n");
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
