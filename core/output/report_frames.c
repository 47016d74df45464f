/*
 * The animated scenes' part of report.md and report.html: per scene, each
 * run's strategy over the frames (update time, SAH, modelled cost), the
 * frame from which rebuilding would have paid off for the runs that
 * update, the cheapest strategy over the whole animation, and in HTML the
 * SAH and the cumulative cost over the frames as SVG charts (one pair per
 * thread count, so each chart compares strategies on equal threads).
 */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "output/report.h"

/* One run's frames, summed up. */
struct strategy {
	const cJSON *run, *frames;
	int count;          /* frames recorded */
	bool all_valid, updates; /* every frame valid; some frame updated, not rebuilt */
	double update_ms, cost_ms, sah_mean, sah_last; /* SAH of the valid frames */
	int pays_off;       /* first frame where the rebuild run's cost was lower; -1 */
	long machine;       /* report_machine_number's */
};

static const cJSON *frame_list(const cJSON *run)
{
	const cJSON *f = cJSON_GetObjectItemCaseSensitive(run, "frames");
	return cJSON_IsArray(f) && cJSON_GetArraySize(f) > 0 ? f : NULL;
}

static bool is_true(const cJSON *o, const char *key)
{
	return cJSON_IsTrue(cJSON_GetObjectItemCaseSensitive(o, key));
}

/* Sums of the frames; SAH over the valid frames only. */
static void sum_up(const cJSON *run, struct strategy *s)
{
	const cJSON *f;
	*s = (struct strategy){.run = run, .frames = frame_list(run), .all_valid = true,
	                       .pays_off = -1};
	int measured = 0;
	cJSON_ArrayForEach(f, s->frames) {
		double sah = report_num(f, "sah");
		bool valid = is_true(f, "valid");
		s->count++;
		s->all_valid = s->all_valid && valid;
		s->updates = s->updates || !is_true(f, "rebuilt");
		s->update_ms += report_num(f, "update_ms");
		s->cost_ms += report_num(f, "cost_ms"); /* NaN from one frame not measured on */
		if (!valid || !isfinite(sah))
			continue; /* an invalid frame's tree has no SAH worth the name */
		s->sah_mean += sah;
		s->sah_last = sah;
		measured++;
	}
	s->sah_mean = measured ? s->sah_mean / measured : NAN;
	s->sah_last = measured ? s->sah_last : NAN;
}

/* The run that rebuilds every frame with the same plugin and threads, on
 * the same machine (another machine's costs are its own); a two-level
 * run's with the same top ("" for a one-level run: never each other's). */
static const struct strategy *rebuild_of(const struct strategy *s, size_t n,
                                         const struct strategy *u)
{
	for (size_t k = 0; k < n; k++)
		if (!s[k].updates && s[k].all_valid && s[k].count == u->count &&
		    s[k].machine == u->machine &&
		    strcmp(report_str(s[k].run, "plugin"), report_str(u->run, "plugin")) == 0 &&
		    strcmp(report_str(s[k].run, "two_level.top.plugin"),
		           report_str(u->run, "two_level.top.plugin")) == 0 &&
		    report_num(s[k].run, "threads") == report_num(u->run, "threads"))
			return &s[k];
	return NULL;
}

static void pays_off(struct strategy *s, size_t n)
{
	for (size_t k = 0; k < n; k++) {
		const struct strategy *r = s[k].updates ? rebuild_of(s, n, &s[k]) : NULL;
		const cJSON *a = r ? s[k].frames->child : NULL, *b = r ? r->frames->child : NULL;
		for (int f = 0; a && b; a = a->next, b = b->next, f++)
			if (!is_true(a, "rebuilt") && report_num(a, "cost_ms") > report_num(b, "cost_ms")) {
				s[k].pays_off = f;
				break;
			}
	}
}

/* The scene's runs with frames, summed up; NULL when there are none. */
static struct strategy *strategies(const struct report_index *ix, const char *scene, size_t *n)
{
	size_t count, m = 0;
	const cJSON *const *runs = report_scene_runs(ix, scene, &count);
	struct strategy *s = count ? calloc(count, sizeof(*s)) : NULL;
	for (size_t k = 0; s && k < count; k++)
		if (frame_list(runs[k])) {
			sum_up(runs[k], &s[m]);
			s[m++].machine = report_machine_number(ix, runs[k]);
		}
	*n = m;
	if (m == 0) {
		free(s);
		return NULL;
	}
	pays_off(s, m);
	return s;
}

/* The cheapest complete run, over all thread counts (threads < 0) or one. */
static const struct strategy *cheapest(const struct strategy *s, size_t n, double threads)
{
	const struct strategy *best = NULL;
	int most = 0;
	for (size_t k = 0; k < n; k++)
		most = s[k].count > most ? s[k].count : most;
	for (size_t k = 0; k < n; k++)
		if (s[k].all_valid && s[k].count == most && isfinite(s[k].cost_ms) &&
		    (threads < 0 || report_num(s[k].run, "threads") == threads) &&
		    (!best || s[k].cost_ms < best->cost_ms))
			best = &s[k];
	return best;
}

static void cheapest_line(struct strbuf *sb, const struct strategy *s, size_t n, bool html)
{
	const struct strategy *best = cheapest(s, n, -1);
	bool any_valid = false;
	char sah[32], update[32];
	for (size_t k = 0; k < n; k++)
		any_valid = any_valid || s[k].all_valid;
	if (!best) {
		sb_printf(sb, "%s%s%s\n", html ? "<p>" : "", any_valid ?
		          "No strategy's cost was measured (its rays were not traced): none is named "
		          "cheapest." : "No strategy has every frame valid.", html ? "</p>" : "\n");
		return;
	}
	sb_printf(sb, html ? "<p><b>Cheapest over the animation: " : "**Cheapest over the "
	                                                             "animation: ");
	(html ? report_escape : report_md_text)(sb, report_str(best->run, "builder"));
	sb_printf(sb, " at %.0f thread%s%s, %.1f ms modelled over %d frames (%s ms of "
	              "updates, mean SAH %s).", report_num(best->run, "threads"),
	          report_num(best->run, "threads") == 1 ? "" : "s", html ? "</b>" : "**",
	          best->cost_ms, best->count, report_figure(update, sizeof(update), best->update_ms, 1),
	          report_figure(sah, sizeof(sah), best->sah_mean, 3));
	sb_printf(sb, html ? "</p>\n" : "\n\n");
}

static const char *const head[] = {"strategy", "threads", "frames", "valid", "update ms",
                                   "mean SAH", "last SAH", "cost ms", "rebuild pays off"};

/* The row's cells after the strategy's name, as text. */
static void row_cells(const struct strategy *s, bool html, char (*cell)[32])
{
	snprintf(cell[0], 32, "%.0f", report_num(s->run, "threads"));
	snprintf(cell[1], 32, "%d", s->count);
	snprintf(cell[2], 32, "%s", s->all_valid ? "yes" : html ? "no" : "**no**");
	report_figure(cell[3], 32, s->update_ms, 2);
	report_figure(cell[4], 32, s->sah_mean, 3);
	report_figure(cell[5], 32, s->sah_last, 3);
	report_figure(cell[6], 32, s->cost_ms, 2);
	cell[7][0] = '\0';
	if (s->pays_off >= 0)
		snprintf(cell[7], 32, "frame %d", s->pays_off);
}

static void md_row(struct strbuf *sb, const struct strategy *s)
{
	char cell[8][32];
	row_cells(s, false, cell);
	sb_printf(sb, "|");
	report_md_cell(sb, report_str(s->run, "builder"));
	for (size_t k = 0; k < 8; k++)
		report_md_cell(sb, cell[k]);
	sb_printf(sb, "\n");
}

/* ---- HTML ----------------------------------------------------------------- */

static void html_row(struct strbuf *sb, const struct strategy *s)
{
	char cell[8][32];
	row_cells(s, true, cell);
	sb_printf(sb, "<tr><td>");
	report_escape(sb, report_str(s->run, "builder"));
	for (size_t k = 0; k < 8; k++)
		sb_printf(sb, k == 2 && !s->all_valid ? "</td><td><b class=\"bad\">%s</b>"
		                                      : "</td><td>%s", cell[k]);
	sb_printf(sb, "</td></tr>\n");
}

/* SAH and cumulative cost per frame of the runs at `threads`. */
static void charts(struct strbuf *sb, const struct report_index *ix, const struct strategy *s,
                   size_t n, double threads)
{
	size_t total = 0, m = 0, c = 0;
	for (size_t k = 0; k < n; k++)
		total += (size_t)s[k].count;
	struct svg_point *sah = calloc(total ? total : 1, sizeof(*sah));
	struct svg_point *cost = calloc(total ? total : 1, sizeof(*cost));
	char title[2][96], (*marks)[256] = calloc(n + 1, sizeof(*marks));
	for (size_t k = 0; sah && cost && marks && k < n; k++) {
		const cJSON *f;
		report_run_marks(marks[k], sizeof(marks[k]), ix, s[k].run); /* the cost is a time */
		double sum = 0;
		if (report_num(s[k].run, "threads") != threads)
			continue;
		cJSON_ArrayForEach(f, s[k].frames) {
			const char *g = report_str(s[k].run, "builder");
			struct svg_point p = {.label = "", .group = g, .x = report_num(f, "frame"),
			                      .shape = svg_plugin_shape(report_str(s[k].run, "plugin"))};
			svg_colour(report_builder_number(ix, g), p.colour, sizeof(p.colour));
			sum += report_num(f, "cost_ms"); /* NaN from the first frame not measured on */
			if (isfinite(report_num(f, "sah"))) {
				sah[m] = p;
				sah[m++].y = report_num(f, "sah");
			}
			if (isfinite(sum)) {
				cost[c] = p;
				cost[c].mark = marks[k];
				cost[c++].y = sum;
			}
		}
	}
	snprintf(title[0], sizeof(title[0]), "SAH over the frames, %.0f thread%s", threads,
	         threads == 1 ? "" : "s");
	snprintf(title[1], sizeof(title[1]), "Cumulative modelled cost, %.0f thread%s", threads,
	         threads == 1 ? "" : "s");
	if (m)
		svg_lines(sb, title[0], "frame", "SAH cost", sah, m);
	if (c)
		svg_lines(sb, title[1], "frame", "ms", cost, c);
	if (!sah || !cost || !marks)
		sb->failed = true;
	free(marks);
	free(sah);
	free(cost);
}

/* One pair of charts per thread count, in the order the runs have them. */
static void all_charts(struct strbuf *sb, const struct report_index *ix,
                       const struct strategy *s, size_t n)
{
	for (size_t k = 0; k < n; k++) {
		double t = report_num(s[k].run, "threads");
		bool seen = false;
		for (size_t j = 0; j < k && !seen; j++)
			seen = report_num(s[j].run, "threads") == t;
		if (!seen)
			charts(sb, ix, s, n, t);
	}
}

static const char explain[] =
	"Per run, over the frames: update ms sums each frame's rebuild or update with its "
	"stages (frame 0: the build), cost ms sums each frame's update and rays_per_frame "
	"rays at its measured rate; \"rebuild pays off\": the first updated frame that cost "
	"more than the same plugin's rebuild of it. frames.csv has every frame.";

/* The section in either rendering: what it shows, the table, the cheapest
 * strategy, and in HTML the charts. */
static void frames_section(struct strbuf *sb, const struct report_index *ix,
                           const cJSON *scene, bool html)
{
	size_t n;
	struct strategy *s = strategies(ix, report_str(scene, "name"), &n);
	if (!s)
		return;
	sb_printf(sb, html ? "<h3>Animation</h3>\n<p>%s</p>\n<table><tr>"
	                   : "\n### Animation\n\n%s\n\n|", explain);
	for (size_t k = 0; k < sizeof(head) / sizeof(head[0]); k++)
		sb_printf(sb, html ? "<th>%s</th>" : " %s |", head[k]);
	sb_printf(sb, html ? "</tr>\n" : "\n|---|---:|---:|---|---:|---:|---:|---:|---|\n");
	for (size_t k = 0; k < n; k++)
		(html ? html_row : md_row)(sb, &s[k]);
	sb_printf(sb, html ? "</table>\n" : "\n");
	cheapest_line(sb, s, n, html);
	if (html)
		all_charts(sb, ix, s, n);
	free(s);
}

void report_frames_md(struct strbuf *sb, const struct report_index *ix, const cJSON *scene)
{
	frames_section(sb, ix, scene, false);
}

void report_frames_html(struct strbuf *sb, const struct report_index *ix, const cJSON *scene)
{
	frames_section(sb, ix, scene, true);
}
