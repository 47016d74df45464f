/*
 * Where a scatter's front labels go: the first slot around the point that
 * overlaps no marker or label placed before it and whose leader line
 * crosses no other marker.
 */
#include <math.h>
#include <stdbool.h>
#include <stddef.h>

#include "output/report_svg.h"

static bool overlaps(const struct placed *a, const struct placed *b)
{
	return a->x0 < b->x1 && b->x0 < a->x1 && a->y0 < b->y1 && b->y0 < a->y1;
}

/* Whether box b is inside the plot and clear of every box taken. */
static bool free_slot(const struct placed *taken, size_t n, const struct placed *b)
{
	if (b->y0 < PAD_T || b->y1 > PAD_T + PLOT_H || b->x0 < PLOT_X || b->x1 > W - PAD_R)
		return false;
	for (size_t i = 0; i < n; i++)
		if (overlaps(b, &taken[i]))
			return false;
	return true;
}

/* Whether the segment from (x0, y0) to (x1, y1) passes through box b
 * (Liang-Barsky: clip the segment's parameter range to each slab). */
static bool crosses(const struct placed *b, double x0, double y0, double x1, double y1)
{
	const double d[2] = {x1 - x0, y1 - y0};
	const double lo[2] = {b->x0 - x0, b->y0 - y0}, hi[2] = {b->x1 - x0, b->y1 - y0};
	double t0 = 0, t1 = 1;
	for (int a = 0; a < 2; a++) {
		if (d[a] == 0) {
			if (lo[a] > 0 || hi[a] < 0)
				return false;
			continue;
		}
		double ta = fmin(lo[a] / d[a], hi[a] / d[a]), tb = fmax(lo[a] / d[a], hi[a] / d[a]);
		t0 = fmax(t0, ta);
		t1 = fmin(t1, tb);
		if (t0 > t1)
			return false;
	}
	return true;
}

/* The distance from (cx, cy) to the segment from (x0, y0) to (x1, y1). */
static double segment_distance(double x0, double y0, double x1, double y1, double cx, double cy)
{
	double dx = x1 - x0, dy = y1 - y0, l2 = dx * dx + dy * dy;
	double t = l2 > 0 ? ((cx - x0) * dx + (cy - y0) * dy) / l2 : 0;
	t = fmax(0, fmin(1, t));
	return hypot(x0 + t * dx - cx, y0 + t * dy - cy);
}

/* Whether the leader from the point (x, y) to label box b passes over
 * another marker or label: it would tie the name to the wrong point. It
 * is seen from the edge of its own marker on; unless strict, markers that
 * overlap its own are passed over too (no leader avoids them all). */
static bool leader_blocked(const struct placed *taken, size_t n, double x, double y,
                           const struct placed *b, bool strict)
{
	double ax = b->x0 < x ? b->x1 : b->x0, ay = (b->y0 + b->y1) / 2;
	double len = hypot(ax - x, ay - y);
	if (len <= MARKER_R)
		return false;
	double sx = x + (ax - x) * MARKER_R / len, sy = y + (ay - y) * MARKER_R / len;
	for (size_t i = 0; i < n; i++) {
		const struct placed *t = &taken[i];
		double cx = (t->x0 + t->x1) / 2, cy = (t->y0 + t->y1) / 2, d = hypot(cx - x, cy - y);
		if (!t->point ? crosses(t, sx, sy, ax, ay)
		              : d > 0 && (strict || d >= 2 * MARKER_R) &&
		                        segment_distance(sx, sy, ax, ay, cx, cy) < MARKER_R + 0.5)
			return true;
	}
	return false;
}

/* Label box number `side` (right, left) of a point at (x, y), `step`
 * lines down and `far` units of 20 px further out. */
static struct placed slot(double x, double y, double w, int side, int step, int far)
{
	double gap = 7 + 20 * far;
	struct placed b = {side ? x - gap - w : x + gap, y - LINE_H / 2 + step * LINE_H, 0, 0, false};
	b.x1 = b.x0 + w;
	b.y1 = b.y0 + LINE_H;
	return b;
}

/* The first free slot for a label near (x, y): right of the point, then
 * left of it, moving down (then up) a line at a time and, where a leader
 * straight up or down would graze a neighbour, further out; *moved when it
 * is not beside the point, and then its leader line must pass no other
 * point or label. Every point is taken too, so no label hides one. */
static bool first_slot(const struct placed *taken, size_t n, double x, double y, double w,
                       bool strict, struct placed *out, bool *moved)
{
	for (int k = 0; k < 40; k++) {
		int step = k % 2 ? (k + 1) / 2 : -(k / 2);
		for (int far = 0; far < 3; far++)
			for (int side = 0; side < 2; side++) {
				struct placed b = slot(x, y, w, side, step, far);
				bool away = k > 0 || far > 0;
				if (free_slot(taken, n, &b) &&
				    (!away || !leader_blocked(taken, n, x, y, &b, strict))) {
					*out = b;
					*moved = away;
					return true;
				}
			}
	}
	return false;
}

/* A label's box for the point (x, y): the first free slot whose leader
 * passes no other marker, else one whose leader passes only markers that
 * overlap the point's own, else beside the point whatever it covers. */
struct placed svg_place(const struct placed *taken, size_t n, double x, double y, size_t len,
                        bool *moved)
{
	double w = CHAR_W * (double)len;
	struct placed b;
	if (first_slot(taken, n, x, y, w, true, &b, moved) ||
	    first_slot(taken, n, x, y, w, false, &b, moved))
		return b;
	*moved = false;
	return slot(x, y, w, 0, 0, 0);
}

