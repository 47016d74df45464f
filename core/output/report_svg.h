/* Chart geometry shared by report_svg.c and the label placement. */
#ifndef BVHLAB_REPORT_SVG_H
#define BVHLAB_REPORT_SVG_H

#include <stdbool.h>
#include <stddef.h>

#define W 640
#define PAD_R 20   /* plots: right margin */
#define PLOT_X 60  /* plots: left edge of the plotting area */
#define PAD_T 44   /* the title, then the y axis's name, above the plot */
#define PAD_B 40
#define BAR_H 18
#define PLOT_H 260
#define LEGEND_H 16 /* a row of the legend under a plot */
#define CHAR_W 6.2  /* the width of a character of the 11 px font, about */
#define LINE_H 12.0
#define MARKER_R 4.5 /* a scatter point's radius */

/* Text boxes already placed, to keep labels apart. */
struct placed {
	double x0, y0, x1, y1;
	bool point; /* a marker's box, not a label's */
};

/* A label's box of len characters for the point (x, y), clear of the
 * boxes taken (markers and labels placed before it); *moved when it is
 * not right beside the point (a leader line is drawn). */
struct placed svg_place(const struct placed *taken, size_t n, double x, double y, size_t len,
                        bool *moved);

#endif
