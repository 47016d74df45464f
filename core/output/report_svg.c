/*
 * Inline SVG charts for report.html: plain shapes and text, no scripts,
 * so the report opens anywhere and the charts print.
 */
#include <math.h>
#include <stdbool.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "output/report.h"
#include "output/report_svg.h"


static void open_svg(struct strbuf *sb, const char *title, int height)
{
	sb_printf(sb, "<svg xmlns=\"http://www.w3.org/2000/svg\" width=\"%d\" height=\"%d\" "
	              "viewBox=\"0 0 %d %d\" font-family=\"sans-serif\" font-size=\"11\">"
	              "<text x=\"%d\" y=\"16\" font-size=\"13\" font-weight=\"bold\">",
	          W, height, W, height, 4);
	report_escape(sb, title);
	sb_printf(sb, "</text>");
}

static void text_at(struct strbuf *sb, double x, double y, const char *anchor, const char *t)
{
	sb_printf(sb, "<text x=\"%.1f\" y=\"%.1f\" text-anchor=\"%s\">", x, y, anchor);
	report_escape(sb, t);
	sb_printf(sb, "</text>");
}

/* A bar's label, right-aligned at x; cut to max characters with an
 * ellipsis (the whole label its tooltip) so it never runs off the left. */
static void bar_label(struct strbuf *sb, double x, double y, const char *label, size_t max)
{
	size_t len = strlen(label);
	sb_printf(sb, "<text x=\"%.1f\" y=\"%.1f\" text-anchor=\"end\">", x, y);
	if (len <= max) {
		report_escape(sb, label);
	} else {
		char cut[256];
		snprintf(cut, sizeof(cut), "%.*s", (int)(max > 1 && max < sizeof(cut) ? max - 1 : 1),
		         label);
		report_escape(sb, cut);
		sb_printf(sb, "…<title>");
		report_escape(sb, label);
		sb_printf(sb, "</title>");
	}
	sb_printf(sb, "</text>");
}

/* Whether some point is marked busy or noisy. */
static bool any_mark(const struct svg_point *p, size_t n)
{
	for (size_t i = 0; i < n; i++)
		if (p[i].mark && *p[i].mark)
			return true;
	return false;
}

void svg_bars(struct strbuf *sb, const char *title, const char *unit,
              const struct svg_point *p, size_t n)
{
	double max = 0;
	size_t longest = 0, fit = (size_t)((W / 2 - 12) / CHAR_W);
	char buf[64], v[32];
	for (size_t i = 0; i < n; i++) {
		max = isfinite(p[i].y) && p[i].y > max ? p[i].y : max;
		longest = strlen(p[i].label) > longest ? strlen(p[i].label) : longest;
	}
	longest = longest < fit ? longest : fit;
	double left = 12 + CHAR_W * (double)longest; /* as much room as the labels need */
	double room = any_mark(p, n) ? 170 : 90;      /* for the value and its marks */
	open_svg(sb, title, PAD_T + (int)n * (BAR_H + 4) + 8);
	for (size_t i = 0; i < n; i++) {
		double y = PAD_T + (double)i * (BAR_H + 4);
		double w = max > 0 && isfinite(p[i].y) ? p[i].y / max * (W - left - room) : 0;
		bool marked = p[i].mark && *p[i].mark;
		bar_label(sb, left - 6, y + BAR_H - 5, p[i].label, longest);
		sb_printf(sb, "<rect x=\"%.1f\" y=\"%.1f\" width=\"%.1f\" height=\"%d\" fill=\"%s\"%s>"
		              "<title>", left, y, w, BAR_H, p[i].colour,
		          marked ? " stroke=\"#e08000\" stroke-width=\"2\" stroke-dasharray=\"3,2\"" : "");
		report_escape(sb, p[i].label);
		if (marked)
			sb_printf(sb, " (");
		report_escape(sb, marked ? p[i].mark : "");
		sb_printf(sb, "%s</title></rect>", marked ? ")" : "");
		if (p[i].shape != SVG_CIRCLE) { /* a peer library's bar: its shape at the bar's end */
			svg_shape(sb, p[i].shape, left + w, y + BAR_H / 2.0, 4, "#fff", " stroke=\"#222\"");
			sb_printf(sb, "/>");
		}
		snprintf(buf, sizeof(buf), "%s %s%s%s", report_plain(v, sizeof(v), p[i].y), unit,
		         marked && strstr(p[i].mark, "noisy") ? " ≈ noisy" : "",
		         marked && strstr(p[i].mark, "busy") ? " ⚠ busy" : "");
		text_at(sb, left + w + 6, y + BAR_H - 5, "start", buf);
	}
	sb_printf(sb, "</svg>\n");
}

/* One axis: its range, whether it is logarithmic and whether every value
 * on it is a whole number (thread counts: no tick between 1 and 2). */
struct axis {
	double lo, hi;
	bool log, whole;
};

/* Values spanning more than this factor get a log axis: a linear one
 * would crush the small ones into the corner. */
#define LOG_SPAN 20.0

/* A scatter's y values above this many times their median are drawn at
 * the plot's top edge, not scaled: one degenerate tree (tinybvh quick's
 * SAH 259,446 on conference.obj, where the others lie between 30 and 70)
 * otherwise squeezed every other point into one band. */
#define OFF_CHART 10.0

static int ascending(const void *a, const void *b)
{
	double x = *(const double *)a, y = *(const double *)b;
	return (x > y) - (x < y);
}

/* The value above which a scatter's y is off the chart: OFF_CHART times
 * the median of the finite values; infinite when none is above or there
 * are too few points to call one an outlier. */
static double off_chart(const struct svg_point *p, size_t n)
{
	double *v = malloc((n ? n : 1) * sizeof(*v)), cap = INFINITY;
	size_t m = 0;
	for (size_t i = 0; v && i < n; i++)
		if (isfinite(p[i].x) && isfinite(p[i].y))
			v[m++] = p[i].y;
	if (m >= 3) {
		qsort(v, m, sizeof(*v), ascending);
		double median = m % 2 ? v[m / 2] : 0.5 * (v[m / 2 - 1] + v[m / 2]);
		if (median > 0 && v[m - 1] > OFF_CHART * median)
			cap = OFF_CHART * median;
	}
	free(v);
	return cap;
}

/* The range of the points' x or y (values above cap left out), padded;
 * never empty. */
static void range(const struct svg_point *p, size_t n, bool y, double cap, struct axis *a)
{
	double lo = INFINITY, hi = -INFINITY;
	a->whole = true;
	for (size_t i = 0; i < n; i++) {
		double v = y ? p[i].y : p[i].x;
		if (isfinite(v) && v <= cap) {
			lo = v < lo ? v : lo;
			hi = v > hi ? v : hi;
			a->whole = a->whole && v == floor(v);
		}
	}
	if (!(lo <= hi))
		lo = 0, hi = 1;
	a->log = lo > 0 && hi / lo > LOG_SPAN;
	if (a->log) {
		a->lo = log10(lo) - 0.05 * (log10(hi) - log10(lo));
		a->hi = log10(hi) + 0.05 * (log10(hi) - log10(lo));
		return;
	}
	double pad = hi > lo ? 0.08 * (hi - lo) : (hi != 0 ? 0.1 * fabs(hi) : 1);
	a->lo = lo - pad;
	a->hi = hi + pad;
}

struct frame {
	struct axis x, y;
	double y_cap; /* y above this is drawn at the top edge (off_chart) */
};

/* Position along an axis in [0, 1]. */
static double unit(const struct axis *a, double v)
{
	double t = a->log ? log10(v) : v;
	return (t - a->lo) / (a->hi - a->lo);
}

static double px(const struct frame *f, double x)
{
	return PLOT_X + unit(&f->x, x) * (W - PLOT_X - PAD_R);
}

static double py(const struct frame *f, double y)
{
	if (y > f->y_cap)
		return PAD_T;
	return PAD_T + PLOT_H - unit(&f->y, y) * PLOT_H;
}

/* A 1, 2 or 5 times a power of ten step giving 3 to 7 ticks, and the
 * decimals that keep every tick label distinct at that step. */
static double tick_step(double lo, double hi, int *decimals)
{
	double raw = (hi - lo) / 5, mag = pow(10, floor(log10(raw))), step = mag;
	if (raw / mag > 5)
		step = 10 * mag;
	else if (raw / mag > 2)
		step = 5 * mag;
	else if (raw / mag > 1)
		step = 2 * mag;
	int d = -(int)floor(log10(step) + 1e-9);
	*decimals = d > 0 ? d : 0;
	return step;
}

/* Tick values of an axis, at most max; returns how many. */
static int ticks(const struct axis *a, double *v, int *decimals, int max)
{
	int n = 0;
	if (a->log) {
		/* Powers of ten, with 2 and 5 between them when there are few. */
		bool fine = a->hi - a->lo < 2.5;
		for (double e = floor(a->lo); e <= ceil(a->hi) && n < max; e++) {
			static const double mult[] = {1, 2, 5};
			for (int m = 0; m < (fine ? 3 : 1) && n < max; m++) {
				double t = mult[m] * pow(10, e);
				if (log10(t) >= a->lo && log10(t) <= a->hi)
					v[n++] = t;
			}
		}
		*decimals = v[0] < 1 ? (int)ceil(-log10(v[0])) : 0;
		return n;
	}
	double step = tick_step(a->lo, a->hi, decimals);
	if (a->whole && step < 1) {
		step = 1;
		*decimals = 0;
	}
	for (double t = ceil(a->lo / step) * step; t <= a->hi && n < max; t += step)
		v[n++] = fabs(t) < step * 1e-9 ? 0 : t;
	return n;
}

static void axes(struct strbuf *sb, const struct frame *f, const char *xname, const char *yname)
{
	char buf[64];
	double v[16];
	int d;
	sb_printf(sb, "<rect x=\"%d\" y=\"%d\" width=\"%d\" height=\"%d\" fill=\"none\" "
	              "stroke=\"#888\"/>", PLOT_X, PAD_T, W - PLOT_X - PAD_R, PLOT_H);
	int n = ticks(&f->x, v, &d, 16);
	for (int k = 0; k < n; k++) {
		snprintf(buf, sizeof(buf), "%.*f", d, v[k]);
		text_at(sb, px(f, v[k]), PAD_T + PLOT_H + 14, "middle", buf);
	}
	n = ticks(&f->y, v, &d, 16);
	for (int k = 0; k < n; k++) {
		snprintf(buf, sizeof(buf), "%.*f", d, v[k]);
		text_at(sb, 56, py(f, v[k]) + 4, "end", buf);
	}
	char name[160];
	snprintf(name, sizeof(name), "%s%s", xname, f->x.log ? " (log scale)" : "");
	text_at(sb, PLOT_X + 0.5 * (W - PLOT_X - PAD_R), PAD_T + PLOT_H + 32, "middle", name);
	snprintf(name, sizeof(name), "%s%s%s", yname, f->y.log ? " (log scale)" : "",
	         isfinite(f->y_cap) ? " (\u25b2 at the top: off the chart, value in its tooltip)" : "");
	text_at(sb, PLOT_X + 2, PAD_T - 8, "start", name); /* below the title's line */
}

/* Whether group g has a point that can be drawn. */
static bool drawable(const struct svg_point *p, size_t n, const char *g)
{
	for (size_t j = 0; j < n; j++)
		if (strcmp(p[j].group, g) == 0 && isfinite(p[j].x) && isfinite(p[j].y))
			return true;
	return false;
}

/* Whether point i is the first drawable one of its group. */
static bool opens_group(const struct svg_point *p, size_t n, size_t i)
{
	for (size_t j = 0; j < i; j++)
		if (strcmp(p[j].group, p[i].group) == 0)
			return false;
	return drawable(p, n, p[i].group);
}

/* One legend entry of width w at the running position; a new row when it
 * does not fit. Returns the entry's baseline. */
static double legend_slot(double *x, int *rows, double w, double top)
{
	if (*rows == 0 || (*x + w > W - 4 && *x > PLOT_X))
		*x = PLOT_X, (*rows)++;
	*x += w;
	return top + (*rows - 1) * LEGEND_H;
}

/* The legend under the plot: a swatch in the group's shape and colour and
 * the group's name per group drawn, then, when some point is marked, the
 * mark's ring; in rows that wrap at the chart's width. Draws when sb is
 * not NULL; returns the rows it takes. */
static int legend(struct strbuf *sb, const struct svg_point *p, size_t n, double top)
{
	static const char ring_text[] = "busy or noisy (hover a point: why)";
	double x = PLOT_X;
	int rows = 0;
	for (size_t i = 0; i < n; i++) {
		if (!opens_group(p, n, i))
			continue;
		double w = 16 + CHAR_W * (double)strlen(p[i].group) + 14;
		double y = legend_slot(&x, &rows, w, top), x0 = x - w; /* after any wrap */
		if (sb) {
			svg_shape(sb, p[i].shape, x0 + 5, y - 4, 5, p[i].colour, "/>");
			text_at(sb, x0 + 14, y, "start", p[i].group);
		}
	}
	if (any_mark(p, n)) {
		double w = 16 + CHAR_W * (double)strlen(ring_text) + 14;
		double y = legend_slot(&x, &rows, w, top), x0 = x - w;
		if (sb) {
			svg_warn_ring(sb, x0 + 5, y - 4, 1);
			text_at(sb, x0 + 14, y, "start", ring_text);
		}
	}
	return rows;
}

static double plot_frame(struct strbuf *sb, const char *title, const char *xname,
                         const char *yname, const struct svg_point *p, size_t n, double y_cap,
                         struct frame *f)
{
	f->y_cap = y_cap;
	range(p, n, false, INFINITY, &f->x);
	range(p, n, true, y_cap, &f->y);
	int rows = legend(NULL, p, n, 0);
	open_svg(sb, title, PAD_T + PLOT_H + PAD_B + 8 + rows * LEGEND_H);
	axes(sb, f, xname, yname);
	return PAD_T + PLOT_H + PAD_B + 8; /* the legend's first baseline */
}

static int by_x(const void *a, const void *b)
{
	const struct svg_point *p = *(const struct svg_point *const *)a;
	const struct svg_point *q = *(const struct svg_point *const *)b;
	return (p->x > q->x) - (p->x < q->x);
}

/* The front: a line through its points in order of x. */
static void front_line(struct strbuf *sb, const struct frame *f, const struct svg_point *p,
                       size_t n)
{
	const struct svg_point **on = malloc((n + 1) * sizeof(*on));
	size_t m = 0;
	for (size_t i = 0; on && i < n; i++)
		if (p[i].front && isfinite(p[i].x) && isfinite(p[i].y))
			on[m++] = &p[i];
	if (!on)
		sb->failed = true;
	if (m > 0) {
		qsort(on, m, sizeof(on[0]), by_x);
		sb_printf(sb, "<polyline fill=\"none\" stroke=\"#444\" stroke-width=\"1.5\" "
		              "stroke-dasharray=\"5,3\" points=\"");
		for (size_t i = 0; i < m; i++)
			sb_printf(sb, "%.1f,%.1f ", px(f, on[i]->x), py(f, on[i]->y));
		sb_printf(sb, "\"/>");
	}
	free(on);
}

/* A point in its shape, with its label (and its mark, ringed) as a
 * tooltip; front points are outlined. One off the chart is a triangle at
 * the top edge, its value in the tooltip. */
static void marker(struct strbuf *sb, const struct frame *f, const struct svg_point *p,
                   double r)
{
	const char *ring = p->front ? " stroke=\"#222\" stroke-width=\"1.5\">" : ">";
	double x = px(f, p->x), y = py(f, p->y);
	bool off = p->y > f->y_cap, marked = p->mark && *p->mark;
	if (marked)
		svg_warn_ring(sb, x, y, r);
	if (off)
		sb_printf(sb, "<polygon points=\"%.1f,%.1f %.1f,%.1f %.1f,%.1f\" fill=\"%s\"%s<title>",
		          x, y - r, x - r, y + r, x + r, y + r, p->colour, ring);
	else {
		svg_shape(sb, p->shape, x, y, r, p->colour, ring);
		sb_printf(sb, "<title>");
	}
	report_escape(sb, p->label);
	if (off)
		sb_printf(sb, ": %.6g, off the chart", p->y);
	if (marked)
		sb_printf(sb, " (");
	report_escape(sb, marked ? p->mark : "");
	sb_printf(sb, "%s</title></%s>", marked ? ")" : "", off ? "polygon" : svg_shape_tag(p->shape));
}

void svg_scatter(struct strbuf *sb, const char *title, const char *xname, const char *yname,
                 const struct svg_point *p, size_t n)
{
	struct frame f;
	struct placed *taken = malloc((2 * n + 1) * sizeof(*taken)); /* every marker and label */
	size_t nt = 0;
	double legend_top = plot_frame(sb, title, xname, yname, p, n, off_chart(p, n), &f);
	front_line(sb, &f, p, n);
	for (size_t i = 0; taken && i < n; i++) {
		if (!isfinite(p[i].x) || !isfinite(p[i].y))
			continue;
		marker(sb, &f, &p[i], MARKER_R);
		double x = px(&f, p[i].x), y = py(&f, p[i].y);
		taken[nt++] = (struct placed){x - 5, y - 5, x + 5, y + 5, true};
	}
	/* Only the front is named on the plot: the legend names every colour,
	 * and a name beside every point of a cluster would only collide. */
	for (size_t i = 0; taken && i < n; i++) {
		if (!p[i].front || !isfinite(p[i].x) || !isfinite(p[i].y))
			continue;
		double x = px(&f, p[i].x), y = py(&f, p[i].y);
		bool moved;
		struct placed b = svg_place(taken, nt, x, y, strlen(p[i].group), &moved);
		taken[nt++] = b;
		if (moved) /* a leader line ties a displaced label to its point */
			sb_printf(sb, "<line x1=\"%.1f\" y1=\"%.1f\" x2=\"%.1f\" y2=\"%.1f\" "
			              "stroke=\"#999\" stroke-width=\"0.7\"/>",
			          x, y, b.x0 < x ? b.x1 : b.x0, (b.y0 + b.y1) / 2);
		text_at(sb, b.x0, b.y1 - 2.5, "start", p[i].group);
	}
	if (!taken)
		sb->failed = true;
	free(taken);
	legend(sb, p, n, legend_top);
	sb_printf(sb, "</svg>\n");
}

static void lines(struct strbuf *sb, const char *title, const char *xname, const char *yname,
                  const struct svg_point *p, size_t n, bool markers)
{
	struct frame f;
	double legend_top = plot_frame(sb, title, xname, yname, p, n, INFINITY, &f);
	for (size_t i = 0; i < n; i++) {
		if (!opens_group(p, n, i))
			continue; /* the legend names only what is drawn */
		sb_printf(sb, "<polyline fill=\"none\" stroke=\"%s\" stroke-width=\"2\" points=\"",
		          p[i].colour);
		for (size_t j = i; j < n; j++)
			if (strcmp(p[j].group, p[i].group) == 0 && isfinite(p[j].y))
				sb_printf(sb, "%.1f,%.1f ", px(&f, p[j].x), py(&f, p[j].y));
		sb_printf(sb, "\"/>");
		/* Markers too: a series of one point draws no line. A curve's
		 * only at its end: its shape and its marks must show there too. */
		size_t last = n;
		for (size_t j = i; j < n; j++)
			if (strcmp(p[j].group, p[i].group) == 0 && isfinite(p[j].y)) {
				if (markers)
					marker(sb, &f, &p[j], 3.5);
				last = j;
			}
		if (!markers && last < n)
			marker(sb, &f, &p[last], 3.5);
	}
	legend(sb, p, n, legend_top);
	sb_printf(sb, "</svg>\n");
}

void svg_lines(struct strbuf *sb, const char *title, const char *xname, const char *yname,
               const struct svg_point *p, size_t n)
{
	lines(sb, title, xname, yname, p, n, true);
}

void svg_curves(struct strbuf *sb, const char *title, const char *xname, const char *yname,
                const struct svg_point *p, size_t n)
{
	lines(sb, title, xname, yname, p, n, false);
}
