/*
 * How a point looks in every chart of report.html: its builder's colour,
 * its library's shape and its marks. A colour is a builder's across the
 * whole report; the shape says at a glance whether a point is a peer
 * library's (embree, tinybvh, bvh2: one shape each) or bvhlab's own
 * (a circle); a dashed orange ring marks a run whose time is not to be
 * trusted (busy or noisy, report_marks.c).
 */
#include <math.h>
#include <stdio.h>
#include <string.h>

#include "output/report.h"

/* Ten strong hues first (Tableau 10, told apart by most colour-blind
 * readers too), then black and light variants; past them, generated ones. */
static const char *const palette[] = {
	"#1f77b4", "#ff7f0e", "#2ca02c", "#d62728", "#9467bd", "#8c564b", "#e377c2",
	"#7f7f7f", "#bcbd22", "#17becf", "#000000", "#aec7e8", "#ffbb78", "#98df8a",
	"#ff9896", "#c5b0d5"};
#define PALETTE (sizeof(palette) / sizeof(palette[0]))

/* One channel of HSL to RGB (the CSS formula), 0 to 255. */
static int channel(double h, double s, double l, int n)
{
	double k = fmod(n + h / 30, 12), a = s * fmin(l, 1 - l);
	double v = l - a * fmax(-1, fmin(fmin(k - 3, 9 - k), 1));
	return (int)lround(255 * v);
}

/* Past the palette, hues a golden angle apart (each new one as far as it
 * can be from those before), at three lightnesses in turn: no two builders
 * of a 40-builder sweep share a colour, and neighbours in the run order
 * differ in lightness as well as hue. */
const char *svg_colour(long k, char *buf, size_t size)
{
	if (k < 0)
		snprintf(buf, size, "#888888");
	else if ((size_t)k < PALETTE)
		snprintf(buf, size, "%s", palette[k]);
	else {
		long g = k - (long)PALETTE;
		double h = fmod(15 + 137.508 * (double)g, 360), l = 0.38 + 0.14 * (double)(g % 3);
		snprintf(buf, size, "#%02x%02x%02x", channel(h, 0.7, l, 0), channel(h, 0.7, l, 8),
		         channel(h, 0.7, l, 4));
	}
	return buf;
}

/* The peer libraries' plugins and their shapes. */
static const struct {
	const char *plugin;
	enum svg_shape shape;
} peers[] = {
	{"embree", SVG_SQUARE},
	{"tinybvh", SVG_DIAMOND},
	{"bvh2", SVG_TRIANGLE_DOWN},
};

enum svg_shape svg_plugin_shape(const char *plugin)
{
	for (size_t k = 0; k < sizeof(peers) / sizeof(peers[0]); k++)
		if (strcmp(plugin, peers[k].plugin) == 0)
			return peers[k].shape;
	return SVG_CIRCLE;
}

const char *svg_shape_name(enum svg_shape shape)
{
	for (size_t k = 0; k < sizeof(peers) / sizeof(peers[0]); k++)
		if (peers[k].shape == shape)
			return peers[k].plugin;
	return "bvhlab";
}

void svg_shape(struct strbuf *sb, enum svg_shape shape, double x, double y, double r,
               const char *fill, const char *extra)
{
	switch (shape) {
	case SVG_SQUARE:
		r *= 0.9; /* the same area, about, as the circle */
		sb_printf(sb, "<rect x=\"%.1f\" y=\"%.1f\" width=\"%.1f\" height=\"%.1f\"", x - r, y - r,
		          2 * r, 2 * r);
		break;
	case SVG_DIAMOND:
		r *= 1.25;
		sb_printf(sb, "<polygon points=\"%.1f,%.1f %.1f,%.1f %.1f,%.1f %.1f,%.1f\"", x, y - r,
		          x + r, y, x, y + r, x - r, y);
		break;
	case SVG_TRIANGLE_DOWN:
		r *= 1.2;
		sb_printf(sb, "<polygon points=\"%.1f,%.1f %.1f,%.1f %.1f,%.1f\"", x - r, y - 0.7 * r,
		          x + r, y - 0.7 * r, x, y + r);
		break;
	case SVG_CIRCLE:
		sb_printf(sb, "<circle cx=\"%.1f\" cy=\"%.1f\" r=\"%.1f\"", x, y, r);
		break;
	}
	sb_printf(sb, " fill=\"%s\"%s", fill, extra ? extra : "");
}

void svg_warn_ring(struct strbuf *sb, double x, double y, double r)
{
	sb_printf(sb, "<circle cx=\"%.1f\" cy=\"%.1f\" r=\"%.1f\" fill=\"none\" stroke=\"#e08000\" "
	              "stroke-width=\"1.6\" stroke-dasharray=\"2,1.5\"/>", x, y, r + 3.5);
}

const char *report_run_marks(char *buf, size_t size, const struct report_index *ix,
                             const cJSON *run)
{
	char noise[160], load[160];
	bool noisy = report_noise(ix, run, noise, sizeof(noise));
	bool busy = report_busy(ix->doc, run, load, sizeof(load));
	snprintf(buf, size, "%s%s%s%s%s", noisy ? "noisy: " : "", noisy ? noise : "",
	         noisy && busy ? "; " : "", busy ? "busy: " : "", busy ? load : "");
	return buf;
}

const char *svg_shape_tag(enum svg_shape shape)
{
	return shape == SVG_CIRCLE ? "circle" : shape == SVG_SQUARE ? "rect" : "polygon";
}
