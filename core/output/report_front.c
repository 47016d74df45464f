/*
 * Pareto fronts: which builders are worth considering at all. Per scene,
 * machine and thread count, a run is on the front of build time against a
 * tree figure (SAH cost, ray cost: nodes and triangles per primary ray;
 * lower is better for both) when no other run is at least as fast and at
 * least as good with one of the two strictly better (figures within 0.05 % count as equal). A run off
 * the front names the run that dominates it: of those, the fastest on the
 * front (there is one without the tolerance; with it, the fastest of all
 * when none is), so the reader is sent to a builder worth looking at.
 */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "output/report.h"
#include "output/results.h"

/* Figures this close count as equal: a parallel build summing in another
 * order, or a tree that differs in a leaf, is not a better tree, and a
 * builder 0.001 % better but 10 % slower is no reason to keep one. */
#define SAME_FIGURE 5e-4

static bool dominates(const struct front_point *b, const struct front_point *a)
{
	bool no_worse = b->figure <= a->figure * (1 + SAME_FIGURE);
	bool better = b->figure < a->figure * (1 - SAME_FIGURE);
	return b->group == a->group && b->time <= a->time && no_worse &&
	       (b->time < a->time || better);
}

static bool usable(const struct front_point *p)
{
	return isfinite(p->time) && isfinite(p->figure) && p->time > 0;
}

/* Whether b is the better pick than c (index < 0: none yet) as a
 * dominator: on the front before off it, then faster, then better. */
static bool better_dominator(const struct front_point *p, const bool *on, long c, size_t b)
{
	if (c < 0 || on[b] != on[c])
		return c < 0 || on[b];
	return p[b].time < p[c].time || (p[b].time == p[c].time && p[b].figure < p[c].figure);
}

void report_front_points(const struct front_point *p, size_t n, long *by)
{
	bool *on = calloc(n + 1, sizeof(*on));
	for (size_t a = 0; !on && a < n; a++)
		by[a] = FRONT_NONE; /* no memory: nothing compared */
	for (size_t a = 0; on && a < n; a++) {
		on[a] = usable(&p[a]);
		for (size_t b = 0; b < n && on[a]; b++)
			on[a] = b == a || !usable(&p[b]) || !dominates(&p[b], &p[a]);
	}
	for (size_t a = 0; on && a < n; a++) {
		by[a] = !usable(&p[a]) ? FRONT_NONE : FRONT_ON;
		for (size_t b = 0; b < n && by[a] != FRONT_NONE && !on[a]; b++)
			if (b != a && usable(&p[b]) && dominates(&p[b], &p[a]) &&
			    better_dominator(p, on, by[a], b))
				by[a] = (long)b;
	}
	free(on);
}

void report_front_text(char *buf, size_t size, const struct front_point *p, long by,
                       size_t a, const char *by_name, const char *figure)
{
	if (by == FRONT_NONE) {
		snprintf(buf, size, "—");
		return;
	}
	if (by == FRONT_ON) {
		snprintf(buf, size, "front");
		return;
	}
	double t = p[by].time / p[a].time, f = 100 * (p[by].figure - p[a].figure) / p[a].figure;
	char change[48];
	if (fabs(f) < 0.05)
		snprintf(change, sizeof(change), "same %s", figure);
	else
		snprintf(change, sizeof(change), "%s%.1f %% %s", f < 0 ? "−" : "+", fabs(f), figure);
	snprintf(buf, size, "dominated by %s (%.2f× time, %s)", by_name, t, change);
}

/* Whether the scene holds a run of the builder with more than 1 thread on
 * the machine. */
static bool ran_parallel(const struct report_index *ix, const cJSON *const *runs, size_t n,
                         const char *builder, long machine)
{
	for (size_t k = 0; k < n; k++)
		if (report_num(runs[k], "threads") > 1 &&
		    report_machine_number(ix, runs[k]) == machine &&
		    strcmp(report_str(runs[k], "builder"), builder) == 0)
			return true;
	return false;
}

static int by_threads(const void *a, const void *b)
{
	const struct front_entry *x = a, *y = b;
	if (x->machine != y->machine)
		return (x->machine > y->machine) - (x->machine < y->machine);
	if (x->threads != y->threads)
		return (x->threads > y->threads) - (x->threads < y->threads);
	return (x->order > y->order) - (x->order < y->order);
}

bool report_on_device(const cJSON *run)
{
	return cJSON_IsObject(cJSON_GetObjectItemCaseSensitive(run, "device"));
}

/* Whether run k competes at thread count t: its own, or any for the
 * 1-thread run of a builder that ran on 1 thread only (on its machine). A
 * device builder's run competes in the device group only: its one host
 * thread says nothing of what the device ran on. */
static bool competes(const struct report_index *ix, const cJSON *const *runs, size_t n,
                     size_t k, double t)
{
	double own = report_num(runs[k], "threads");
	if (report_on_device(runs[k]))
		return t == REPORT_DEVICE_GROUP;
	if (t == REPORT_DEVICE_GROUP)
		return false; /* not even a 1-thread run standing in */
	return own == t || (own == 1 && t > 1 &&
	                    !ran_parallel(ix, runs, n, report_str(runs[k], "builder"),
	                                  report_machine_number(ix, runs[k])));
}

struct front_entry *report_front_entries(const struct report_index *ix,
                                         const cJSON *const *runs, size_t n, size_t *count)
{
	double t[65];
	size_t nt = report_thread_counts(runs, n, t, 64), m = 0;
	t[nt++] = REPORT_DEVICE_GROUP; /* after every thread count */
	struct front_entry *e = calloc(n * nt + 1, sizeof(*e));
	for (size_t i = 0; e && i < nt; i++)
		for (size_t k = 0; k < n; k++)
			if (competes(ix, runs, n, k, t[i]))
				e[m++] = (struct front_entry){runs[k], t[i], k,
				                              report_machine_number(ix, runs[k])};
	if (e)
		qsort(e, m, sizeof(*e), by_threads);
	*count = m;
	return e;
}

size_t report_thread_counts(const cJSON *const *runs, size_t n, double *out, size_t max)
{
	size_t m = 0;
	for (size_t k = 0; k < n; k++) {
		double t = report_num(runs[k], "threads");
		size_t i = 0;
		while (i < m && out[i] != t)
			i++;
		if (i < m || m == max || !isfinite(t))
			continue;
		for (i = m++; i > 0 && out[i - 1] > t; i--) /* insertion keeps them sorted */
			out[i] = out[i - 1];
		out[i] = t;
	}
	return m;
}

double report_ray_cost(const cJSON *run)
{
	return REPORT_C_TRAV * report_num(run, "rays.primary.nodes_per_ray") +
	       REPORT_C_ISECT * report_num(run, "rays.primary.tris_per_ray");
}

/* The two views the tables show: build time against each figure. */
static const char *const figure_names[2] = {"SAH", "ray cost"};
static const char *const view_names[2] = {"SAH cost", "ray cost (nodes + tris per ray)"};

double report_front_figure(int view, const cJSON *run)
{
	return view == 0 ? report_num(run, "tree.sah_cost") : report_ray_cost(run);
}

const char *report_front_view_name(int view)
{
	return view_names[view];
}

void report_entries_front(const struct front_entry *e, size_t m, int view,
                          struct front_point *p, long *by)
{
	for (size_t k = 0; k < m; k++) {
		bool ok = strcmp(report_str(e[k].run, "status"), "ok") == 0;
		p[k] = (struct front_point){ok ? results_own_ms(e[k].run) : NAN,
		                            report_front_figure(view, e[k].run),
		                            report_front_group(e[k].machine, e[k].threads)};
	}
	report_front_points(p, m, by);
}

struct front_table {
	struct front_entry *e;
	size_t n;
	struct front_point *p[2];
	long *by[2];
};

static int table_init(struct front_table *t, const struct report_index *ix,
                      const cJSON *const *runs, size_t n)
{
	memset(t, 0, sizeof(*t));
	t->e = report_front_entries(ix, runs, n, &t->n);
	for (int v = 0; t->e && v < 2; v++) {
		t->p[v] = calloc(t->n + 1, sizeof(*t->p[v]));
		t->by[v] = calloc(t->n + 1, sizeof(*t->by[v]));
		if (!t->p[v] || !t->by[v])
			return -1;
		report_entries_front(t->e, t->n, v, t->p[v], t->by[v]);
	}
	return t->e ? 0 : -1;
}

/* Whether some run was compared: a table of none would be empty. */
static bool any_compared(const struct front_table *t)
{
	for (size_t k = 0; k < t->n; k++)
		if (t->by[0][k] != FRONT_NONE)
			return true;
	return false;
}

static void table_finish(struct front_table *t)
{
	free(t->e);
	for (int v = 0; v < 2; v++) {
		free(t->p[v]);
		free(t->by[v]);
	}
}

/* The verdict of run k in view v. */
static void verdict(const struct front_table *t, int v, size_t k, char *buf, size_t size)
{
	long by = t->by[v][k];
	const char *name = by >= 0 ? report_str(t->e[by].run, "builder") : "";
	report_front_text(buf, size, t->p[v], by, k, name, figure_names[v]);
}

/* A figure as the tables print it, or "not measured" where it is not finite. */
static const char *measured(char *buf, size_t size, double v)
{
	return isfinite(v) ? report_plain(buf, size, v) : report_figure(buf, size, v, 0);
}

/* "2", or "2 (ran on 1)" for a 1-thread run standing in at 2 threads;
 * " on M2" after it when the runs come from several machines. */

static const char *threads_text(char *buf, size_t size, const struct report_index *ix,
                                const struct front_entry *e)
{
	double own = report_num(e->run, "threads");
	char on[32] = "";
	if (ix->machine_count > 1)
		snprintf(on, sizeof(on), " on M%ld", e->machine + 1);
	if (e->threads == REPORT_DEVICE_GROUP)
		snprintf(buf, size, "device: %s%s", report_str(e->run, "device.name"), on);
	else if (own == e->threads)
		snprintf(buf, size, "%.0f%s", own, on);
	else
		snprintf(buf, size, "%.0f (ran on %.0f)%s", e->threads, own, on);
	return buf;
}

long report_front_group(long machine, double threads)
{
	return machine * 100000 + (long)threads;
}

static const char intro[] =
	"Per thread count: a builder is on the front when no other is at least as fast "
	"and builds a tree at least as good (lower SAH cost; a lower ray cost: primary nodes "
	"plus triangles visited per ray, the SAH's own weights c_trav = c_isect = 1), "
	"one of the two strictly, figures within 0.05 % counting as equal; off it, the "
	"fastest builder on the front that dominates it, its build time as a multiple of "
	"this one's and the change in the figure. A builder that ran on 1 thread only "
	"competes with its 1-thread run at every thread count; a device builder's runs "
	"(OpenCL) compete among themselves, as \"device: NAME\". Build time here is a build's "
	"own (results.json's own_ms): the median less its phases input and convert, where a "
	"builder translates bvhlab's input into its own format and its tree into bvhlab's "
	"(a peer library, a device builder), which a user of its library does not pay.";

void report_front_md(struct strbuf *sb, const struct report_index *ix,
                     const cJSON *const *runs, size_t n)
{
	struct front_table t;
	char buf[256];
	if (table_init(&t, ix, runs, n) == 0 && any_compared(&t)) {
		sb_printf(sb, "\n### Pareto fronts\n\n%s\n\n| builder | threads | median ms | SAH cost "
		              "| time × SAH | ray cost | time × ray cost |\n"
		              "|---|---:|---:|---:|---|---:|---|\n", intro);
		for (size_t k = 0; k < t.n; k++) {
			if (t.by[0][k] == FRONT_NONE)
				continue;
			sb_printf(sb, "|");
			report_md_cell(sb, report_str(t.e[k].run, "builder"));
			report_md_cell(sb, threads_text(buf, sizeof(buf), ix, &t.e[k]));
			sb_printf(sb, " %s |", report_plain(buf, sizeof(buf), t.p[0][k].time));
			sb_printf(sb, " %s |", report_figure(buf, sizeof(buf), t.p[0][k].figure, 3));
			verdict(&t, 0, k, buf, sizeof(buf));
			report_md_cell(sb, buf);
			sb_printf(sb, " %s |", measured(buf, sizeof(buf), t.p[1][k].figure));
			verdict(&t, 1, k, buf, sizeof(buf));
			report_md_cell(sb, buf);
			sb_printf(sb, "\n");
		}
	}
	table_finish(&t);
}

static void html_verdict(struct strbuf *sb, const struct front_table *t, int v, size_t k)
{
	char buf[256];
	verdict(t, v, k, buf, sizeof(buf));
	sb_printf(sb, "<td class=\"l%s\">", t->by[v][k] == FRONT_ON ? " front" : "");
	report_escape(sb, buf);
	sb_printf(sb, "</td>");
}

static void html_row(struct strbuf *sb, const struct report_index *ix,
                     const struct front_table *t, size_t k)
{
	char buf[192], ms[32], fig[32];
	sb_printf(sb, "<tr><td class=\"l\">");
	report_escape(sb, report_str(t->e[k].run, "builder"));
	sb_printf(sb, "</td><td>");
	report_escape(sb, threads_text(buf, sizeof(buf), ix, &t->e[k])); /* a device's name */
	sb_printf(sb, "</td><td>%s</td><td>%s</td>", report_plain(ms, sizeof(ms), t->p[0][k].time),
	          report_figure(fig, sizeof(fig), t->p[0][k].figure, 3));
	html_verdict(sb, t, 0, k);
	sb_printf(sb, "<td>%s</td>", measured(fig, sizeof(fig), t->p[1][k].figure));
	html_verdict(sb, t, 1, k);
	sb_printf(sb, "</tr>\n");
}

void report_front_html(struct strbuf *sb, const struct report_index *ix,
                       const cJSON *const *runs, size_t n)
{
	struct front_table t;
	if (table_init(&t, ix, runs, n) == 0 && any_compared(&t)) {
		sb_printf(sb, "<h3>Pareto fronts</h3>\n<p>%s</p>\n<table><tr><th class=\"l\">builder"
		              "</th><th>threads</th><th>median ms</th><th>SAH cost</th>"
		              "<th class=\"l\">time × SAH</th><th>ray cost</th>"
		              "<th class=\"l\">time × ray cost</th></tr>\n", intro);
		for (size_t k = 0; k < t.n; k++)
			if (t.by[0][k] != FRONT_NONE)
				html_row(sb, ix, &t, k);
		sb_printf(sb, "</table>\n");
	}
	table_finish(&t);
}
