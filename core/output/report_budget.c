/*
 * The cheapest builder for a ray budget: the question a user brings to
 * the report. Tracing n rays through a builder's tree costs its build
 * plus n times its time per ray (the inverse of its measured primary
 * Mrays/s, as the break-even takes it), a line in n. Per scene, machine
 * and thread count the builders on the front of (build time, time per
 * ray) are the only ones that can be cheapest; the lower envelope of their
 * lines says which is, from which ray count to which. A run whose rays
 * were not traced has no time per ray and is left out; a group where none
 * was traced says "not measured" rather than guess.
 */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "output/report.h"
#include "output/results.h"

size_t report_budget_intervals(const double *build, const double *ray, size_t n,
                               struct budget_interval *out)
{
	long cur = -1;
	size_t m = 0;
	for (size_t j = 0; j < n; j++) /* the cheapest at 0 rays: fastest build, then rays */
		if (isfinite(build[j]) && ray[j] > 0 && isfinite(ray[j]) &&
		    (cur < 0 || build[j] < build[cur] || (build[j] == build[cur] && ray[j] < ray[cur])))
			cur = (long)j;
	double from = 0;
	while (cur >= 0) {
		long next = -1;
		double at = INFINITY;
		for (size_t j = 0; j < n; j++) {
			if (!isfinite(build[j]) || !(ray[j] > 0) || !(ray[j] < ray[cur]))
				continue;
			double x = fmax(from, (build[j] - build[cur]) / (ray[cur] - ray[j]));
			if (x < at || (x == at && ray[j] < ray[next]))
				at = x, next = (long)j;
		}
		out[m++] = (struct budget_interval){(size_t)cur, from, at};
		from = at;
		cur = next;
	}
	return m;
}

/* One scene group's candidates: the entries of a machine and thread
 * count, build and ray seconds, and where they stand. */
struct budget_group {
	const struct front_entry *e; /* [n] */
	size_t n;
	double *build, *ray;         /* seconds; NaN where not measured */
	long *by;                    /* report_front_points' verdicts */
	struct budget_interval *iv;  /* [niv] the cheapest, by ray count */
	size_t niv;
	bool traced;                 /* some run of the group has a time per ray */
};

static int group_init(struct budget_group *g, const struct front_entry *e, size_t n)
{
	memset(g, 0, sizeof(*g));
	g->e = e;
	g->n = n;
	g->build = calloc(n + 1, sizeof(*g->build));
	g->ray = calloc(n + 1, sizeof(*g->ray));
	g->by = calloc(n + 1, sizeof(*g->by));
	g->iv = calloc(n + 1, sizeof(*g->iv));
	struct front_point *p = calloc(n + 1, sizeof(*p));
	if (!g->build || !g->ray || !g->by || !g->iv || !p) {
		free(p);
		return -1;
	}
	for (size_t k = 0; k < n; k++) {
		bool ok = strcmp(report_str(e[k].run, "status"), "ok") == 0;
		double mrays = report_num(e[k].run, "rays.primary.mrays_per_s");
		g->build[k] = ok ? results_own_ms(e[k].run) / 1e3 : NAN;
		g->ray[k] = ok && mrays > 0 ? 1 / (mrays * 1e6) : NAN;
		g->traced |= isfinite(g->build[k]) && isfinite(g->ray[k]);
		p[k] = (struct front_point){g->build[k], g->ray[k], 0};
	}
	report_front_points(p, n, g->by);
	free(p);
	g->niv = report_budget_intervals(g->build, g->ray, n, g->iv);
	return 0;
}

static void group_finish(struct budget_group *g)
{
	free(g->build);
	free(g->ray);
	free(g->by);
	free(g->iv);
}

/* What a walk over a scene's groups hands each one: the sections below
 * print their header on the first. */
struct budget_walk {
	struct strbuf *sb, *charts;
	const struct report_index *ix;
	const char *scene;
	bool html, opened;
	size_t *order; /* room for a group's entries */
};

typedef void (*group_visit)(struct budget_walk *w, const struct budget_group *g);

/* Calls visit for each group (machine and thread count) of the scene's
 * front entries, which come sorted by machine and threads. */
static void each_group(struct budget_walk *w, group_visit visit)
{
	size_t count, n;
	const cJSON *const *runs = report_scene_runs(w->ix, w->scene, &count);
	struct front_entry *e = report_front_entries(w->ix, runs, count, &n);
	w->order = calloc(n + 1, sizeof(*w->order));
	for (size_t first = 0, k = 0; e && w->order && first < n; first = k) {
		while (k < n && e[k].machine == e[first].machine && e[k].threads == e[first].threads)
			k++;
		struct budget_group g;
		if (group_init(&g, &e[first], k - first) == 0)
			visit(w, &g);
		group_finish(&g);
	}
	if (!e || !w->order)
		w->sb->failed = true;
	free(w->order);
	free(e);
}

/* "1.2 M" rays (report_breakeven.c's count, without the unit). */
static const char *count(char *buf, size_t size, double n)
{
	report_ray_count(buf, size, n);
	return buf;
}

/* "2 threads", "2 threads on M2". */
static const char *group_title(char *buf, size_t size, const struct report_index *ix,
                               const struct front_entry *e)
{
	int len = e->threads == REPORT_DEVICE_GROUP
	                  ? snprintf(buf, size, "device: %s", report_str(e->run, "device.name"))
	                  : snprintf(buf, size, "%.0f thread%s", e->threads, e->threads == 1 ? "" : "s");
	if (ix->machine_count > 1 && len >= 0 && (size_t)len < size)
		snprintf(buf + len, size - (size_t)len, " on M%ld", e->machine + 1);
	return buf;
}

/* "up to 400.0 k rays: fast; up to 2.0 M: mid; beyond: slow". */
static void verdict_line(struct strbuf *sb, const struct budget_group *g)
{
	char n[32];
	if (!g->traced) {
		sb_printf(sb, "not measured (no run traced rays)");
		return;
	}
	for (size_t k = 0; k < g->niv; k++) {
		const char *name = report_str(g->e[g->iv[k].index].run, "builder");
		if (g->niv == 1)
			sb_printf(sb, "any ray count: %s", name);
		else if (isinf(g->iv[k].to))
			sb_printf(sb, "beyond: %s", name);
		else
			sb_printf(sb, "up to %s%s: %s; ", count(n, sizeof(n), g->iv[k].to),
			          k == 0 ? " rays" : "", name);
	}
}

/* The text escaped for HTML or for Markdown. */
static void put(struct strbuf *sb, bool html, const char *text)
{
	if (html)
		report_escape(sb, text);
	else
		report_md_text(sb, text);
}

static void summary_line(struct budget_walk *w, const struct budget_group *g)
{
	char title[160];
	if (!w->opened)
		sb_printf(w->sb, w->html ? "<p><b>Cheapest for a ray budget</b> (build plus primary "
		                           "rays at the measured Mrays/s; see each scene's table):"
		                           "</p>\n<ul>\n"
		                         : "**Cheapest for a ray budget** (build plus primary rays "
		                           "at the measured Mrays/s; see each scene's table):\n\n");
	w->opened = true;
	sb_printf(w->sb, w->html ? "<li>" : "- ");
	put(w->sb, w->html, w->scene);
	sb_printf(w->sb, ", %s: ", group_title(title, sizeof(title), w->ix, &g->e[0]));
	struct strbuf line = {0};
	verdict_line(&line, g);
	char *text = sb_take(&line);
	put(w->sb, w->html, text ? text : "");
	free(text);
	sb_printf(w->sb, w->html ? "</li>\n" : "\n");
}

void report_budget_summary(struct strbuf *sb, const struct report_index *ix, bool html)
{
	const cJSON *scene;
	struct budget_walk w = {.sb = sb, .ix = ix, .html = html};
	cJSON_ArrayForEach(scene, cJSON_GetObjectItem(ix->doc, "scenes")) {
		w.scene = report_str(scene, "name");
		each_group(&w, summary_line);
	}
	if (w.opened)
		sb_printf(sb, html ? "</ul>\n" : "\n");
}

static const char intro[] =
	"Per thread count, the builders on the front of build time against time per ray "
	"(the inverse of the primary Mrays/s, best tile, traced with the run's ray threads) "
	"and the ray counts for which each has the lowest total cost, build plus rays; a "
	"builder on that front whose line never lies lowest is never the cheapest. Runs "
	"whose rays were not traced are left out; where none was, not measured.";

/* "0", "400.0 k" or "beyond" (a bound of an interval). */
static const char *bound(char *buf, size_t size, double n)
{
	if (isinf(n))
		snprintf(buf, size, "beyond");
	else if (n == 0)
		snprintf(buf, size, "0");
	else
		count(buf, size, n);
	return buf;
}

/* The interval of entry k, or NULL when it is never the cheapest. */
static const struct budget_interval *interval_of(const struct budget_group *g, size_t k)
{
	for (size_t i = 0; i < g->niv; i++)
		if (g->iv[i].index == k)
			return &g->iv[i];
	return NULL;
}

/* The group's front, by build time: the order its lines take the lead. */
static size_t front_order(const struct budget_group *g, size_t *out)
{
	size_t m = 0;
	for (size_t k = 0; k < g->n; k++) {
		if (g->by[k] != FRONT_ON)
			continue;
		size_t i = m++;
		for (; i > 0 && g->build[out[i - 1]] > g->build[k]; i--)
			out[i] = out[i - 1];
		out[i] = k;
	}
	return m;
}

/* One front builder's row: -, ms, Mrays/s, from, to. */
static void row_cells(const struct budget_group *g, size_t k, char (*cell)[48])
{
	const struct budget_interval *iv = interval_of(g, k);
	report_plain(cell[1], 48, g->build[k] * 1e3);
	report_plain(cell[2], 48, 1 / (g->ray[k] * 1e6));
	if (!iv) {
		snprintf(cell[3], 48, "never cheapest");
		snprintf(cell[4], 48, "—");
		return;
	}
	bound(cell[3], 48, iv->from);
	bound(cell[4], 48, iv->to);
}

static void group_md(struct budget_walk *w, const struct budget_group *g)
{
	char title[160], cell[5][48] = {{0}};
	if (!w->opened)
		sb_printf(w->sb, "\n### Cheapest for a ray budget\n\n%s\n\n| threads | builder "
		                 "| median ms | primary Mrays/s | cheapest from (rays) | up to (rays) |\n"
		                 "|---|---|---:|---:|---:|---:|\n", intro);
	w->opened = true;
	group_title(title, sizeof(title), w->ix, &g->e[0]);
	if (!g->traced) {
		sb_printf(w->sb, "| %s | not measured | | | | |\n", title);
		return;
	}
	size_t m = front_order(g, w->order);
	for (size_t i = 0; i < m; i++) {
		row_cells(g, w->order[i], cell);
		sb_printf(w->sb, "| %s |", title);
		report_md_cell(w->sb, report_str(g->e[w->order[i]].run, "builder"));
		sb_printf(w->sb, " %s | %s | %s | %s |\n", cell[1], cell[2], cell[3], cell[4]);
	}
}

void report_budget_md(struct strbuf *sb, const struct report_index *ix, const char *scene)
{
	struct budget_walk w = {.sb = sb, .ix = ix, .scene = scene};
	each_group(&w, group_md);
}

/* The group's chart: each front builder's total cost (ms) against the
 * ray count, on log axes, sampled at SAMPLES ray counts. */
#define SAMPLES 48

static void group_chart(struct strbuf *sb, const struct report_index *ix,
                        const struct budget_group *g, const size_t *order, size_t m)
{
	double lo = 1e3, hi = 1e9;
	if (g->niv > 1) { /* two decades either side of the crossings */
		lo = fmax(1, g->iv[0].to / 100);
		hi = g->iv[g->niv - 2].to * 100;
	}
	struct svg_point *p = calloc(m * SAMPLES + 1, sizeof(*p));
	char (*marks)[256] = calloc(m + 1, sizeof(*marks)), title[96], t[64];
	for (size_t i = 0; p && marks && i < m; i++) {
		const cJSON *run = g->e[order[i]].run;
		const char *builder = report_str(run, "builder");
		report_run_marks(marks[i], sizeof(marks[i]), ix, run);
		for (int k = 0; k < SAMPLES; k++) {
			double rays = lo * pow(hi / lo, k / (SAMPLES - 1.0));
			struct svg_point *q = &p[i * SAMPLES + (size_t)k];
			*q = (struct svg_point){.label = builder, .group = builder, .x = rays,
			                        .y = 1e3 * (g->build[order[i]] + rays * g->ray[order[i]]),
			                        .shape = svg_plugin_shape(report_str(run, "plugin")),
			                        .mark = marks[i]};
			svg_colour(report_builder_number(ix, builder), q->colour, sizeof(q->colour));
		}
	}
	snprintf(title, sizeof(title), "Cost of a ray budget, %s",
	         group_title(t, sizeof(t), ix, &g->e[0]));
	if (p && marks)
		svg_curves(sb, title, "primary rays", "build + rays (ms)", p, m * SAMPLES);
	else
		sb->failed = true;
	free(p);
	free(marks);
}

static void group_html(struct budget_walk *w, const struct budget_group *g)
{
	char title[160], cell[5][48] = {{0}};
	if (!w->opened)
		sb_printf(w->sb, "<h3>Cheapest for a ray budget</h3>\n<p>%s</p>\n<table class=\"budget\">"
		                 "<tr><th class=\"l\">threads</th><th class=\"l\">builder</th><th>median "
		                 "ms</th><th>primary Mrays/s</th><th>cheapest from (rays)</th><th>up to "
		                 "(rays)</th></tr>\n", intro);
	w->opened = true;
	group_title(title, sizeof(title), w->ix, &g->e[0]);
	if (!g->traced) {
		sb_printf(w->sb, "<tr><td class=\"l\">%s</td><td class=\"l\" colspan=\"5\">not measured"
		                 "</td></tr>\n", title);
		return;
	}
	size_t m = front_order(g, w->order);
	for (size_t i = 0; i < m; i++) {
		row_cells(g, w->order[i], cell);
		sb_printf(w->sb, "<tr><td class=\"l\">%s</td><td class=\"l%s\">", title,
		          interval_of(g, w->order[i]) ? " front" : "");
		report_escape(w->sb, report_str(g->e[w->order[i]].run, "builder"));
		sb_printf(w->sb, "</td><td>%s</td><td>%s</td><td>%s</td><td>%s</td></tr>\n", cell[1],
		          cell[2], cell[3], cell[4]);
	}
	group_chart(w->charts, w->ix, g, w->order, m);
}

void report_budget_html(struct strbuf *sb, const struct report_index *ix, const char *scene)
{
	struct strbuf charts = {0};
	struct budget_walk w = {.sb = sb, .charts = &charts, .ix = ix, .scene = scene, .html = true};
	each_group(&w, group_html);
	if (w.opened)
		sb_printf(sb, "</table>\n");
	char *svg = sb_take(&charts);
	if (svg && *svg)
		sb_printf(sb, "<div class=\"charts\">\n%s</div>\n", svg);
	free(svg);
}
