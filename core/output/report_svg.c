/*
 * Inline SVG charts for report.html: plain shapes and text, no scripts,
 * so the report opens anywhere and the charts print.
 */
#include <math.h>
#include <stdio.h>
#include <string.h>

#include "output/report.h"

#define W 640
#define PAD_L 190
#define PAD_R 60
#define PAD_T 28
#define PAD_B 40
#define BAR_H 18
#define PLOT_H 260

static const char *const palette[] = {"#4477aa", "#ee6677", "#228833", "#ccbb44",
                                      "#66ccee", "#aa3377", "#bbbbbb", "#000000"};

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

void svg_bars(struct strbuf *sb, const char *title, const char *unit,
              const struct svg_point *p, size_t n)
{
	double max = 0;
	char buf[64];
	for (size_t i = 0; i < n; i++)
		max = isfinite(p[i].y) && p[i].y > max ? p[i].y : max;
	open_svg(sb, title, PAD_T + (int)n * (BAR_H + 4) + 8);
	for (size_t i = 0; i < n; i++) {
		double y = PAD_T + (double)i * (BAR_H + 4);
		double w = max > 0 && isfinite(p[i].y) ? p[i].y / max * (W - PAD_L - PAD_R) : 0;
		text_at(sb, PAD_L - 6, y + BAR_H - 5, "end", p[i].label);
		sb_printf(sb, "<rect x=\"%d\" y=\"%.1f\" width=\"%.1f\" height=\"%d\" fill=\"%s\"/>",
		          PAD_L, y, w, BAR_H, palette[0]);
		snprintf(buf, sizeof(buf), "%.3g %s", p[i].y, unit);
		text_at(sb, PAD_L + w + 4, y + BAR_H - 5, "start", buf);
	}
	sb_printf(sb, "</svg>\n");
}

/* The range of the points' x or y, padded; never empty. */
static void range(const struct svg_point *p, size_t n, bool y, double *lo, double *hi)
{
	*lo = INFINITY;
	*hi = -INFINITY;
	for (size_t i = 0; i < n; i++) {
		double v = y ? p[i].y : p[i].x;
		if (isfinite(v)) {
			*lo = v < *lo ? v : *lo;
			*hi = v > *hi ? v : *hi;
		}
	}
	if (!(*lo <= *hi))
		*lo = 0, *hi = 1;
	double pad = *hi > *lo ? 0.08 * (*hi - *lo) : (*hi != 0 ? 0.1 * fabs(*hi) : 1);
	*lo -= pad;
	*hi += pad;
}

struct frame {
	double x0, x1, y0, y1;
};

static double px(const struct frame *f, double x)
{
	return 60 + (x - f->x0) / (f->x1 - f->x0) * (W - 60 - PAD_R);
}

static double py(const struct frame *f, double y)
{
	return PAD_T + PLOT_H - (y - f->y0) / (f->y1 - f->y0) * PLOT_H;
}

static void axes(struct strbuf *sb, const struct frame *f, const char *xname, const char *yname)
{
	char buf[64];
	sb_printf(sb, "<rect x=\"60\" y=\"%d\" width=\"%d\" height=\"%d\" fill=\"none\" "
	              "stroke=\"#888\"/>", PAD_T, W - 60 - PAD_R, PLOT_H);
	for (int k = 0; k <= 4; k++) {
		double x = f->x0 + (f->x1 - f->x0) * k / 4, y = f->y0 + (f->y1 - f->y0) * k / 4;
		snprintf(buf, sizeof(buf), "%.3g", x);
		text_at(sb, px(f, x), PAD_T + PLOT_H + 14, "middle", buf);
		snprintf(buf, sizeof(buf), "%.3g", y);
		text_at(sb, 56, py(f, y) + 4, "end", buf);
	}
	text_at(sb, px(f, 0.5 * (f->x0 + f->x1)), PAD_T + PLOT_H + 32, "middle", xname);
	text_at(sb, 62, PAD_T - 4, "start", yname);
}

static void plot_frame(struct strbuf *sb, const char *title, const char *xname,
                       const char *yname, const struct svg_point *p, size_t n, struct frame *f)
{
	range(p, n, false, &f->x0, &f->x1);
	range(p, n, true, &f->y0, &f->y1);
	open_svg(sb, title, PAD_T + PLOT_H + PAD_B + 4);
	axes(sb, f, xname, yname);
}

void svg_scatter(struct strbuf *sb, const char *title, const char *xname, const char *yname,
                 const struct svg_point *p, size_t n)
{
	struct frame f;
	plot_frame(sb, title, xname, yname, p, n, &f);
	for (size_t i = 0; i < n; i++) {
		if (!isfinite(p[i].x) || !isfinite(p[i].y))
			continue;
		sb_printf(sb, "<circle cx=\"%.1f\" cy=\"%.1f\" r=\"4\" fill=\"%s\"/>", px(&f, p[i].x),
		          py(&f, p[i].y), palette[i % 8]);
		text_at(sb, px(&f, p[i].x) + 6, py(&f, p[i].y) - 4, "start", p[i].label);
	}
	sb_printf(sb, "</svg>\n");
}

void svg_lines(struct strbuf *sb, const char *title, const char *xname, const char *yname,
               const struct svg_point *p, size_t n)
{
	struct frame f;
	size_t color = 0;
	plot_frame(sb, title, xname, yname, p, n, &f);
	for (size_t i = 0; i < n; i++) {
		bool seen = false;
		for (size_t j = 0; j < i && !seen; j++)
			seen = strcmp(p[j].group, p[i].group) == 0;
		if (seen)
			continue;
		const char *c = palette[color++ % 8];
		sb_printf(sb, "<polyline fill=\"none\" stroke=\"%s\" stroke-width=\"2\" points=\"", c);
		for (size_t j = i; j < n; j++)
			if (strcmp(p[j].group, p[i].group) == 0 && isfinite(p[j].y))
				sb_printf(sb, "%.1f,%.1f ", px(&f, p[j].x), py(&f, p[j].y));
		sb_printf(sb, "\"/>");
		text_at(sb, W - PAD_R + 4, PAD_T + 12 * (double)color, "start", p[i].group);
	}
	sb_printf(sb, "</svg>\n");
}
