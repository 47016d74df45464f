/*
 * The renderings of a results document (results.csv, report.md,
 * report.html; results.c writes them) and the sections they share. Reading
 * the document is report_doc.h's.
 */
#ifndef BVHLAB_CORE_REPORT_H
#define BVHLAB_CORE_REPORT_H

#include <stddef.h>

#include <cJSON.h>

#include "output/report_doc.h"
#include "util/util.h"

/* The CSV and Markdown renderings of a results document (malloc'd text). */
char *report_csv(const struct cJSON *doc);
char *report_markdown(const struct cJSON *doc);
/* report.html: self-contained but for the PNGs it names (images/...). */
char *report_html(const struct cJSON *doc);

/* A document's runs by scene, for rendering in time linear in their
 * number (report_index.c). */
struct report_slot;
struct report_index {
	struct report_slot *scenes, *pairs; /* open-addressed tables of cap slots */
	struct report_slot *names;          /* builder labels, numbered */
	const cJSON **order;                /* every run, grouped by scene */
	const cJSON **machines;             /* distinct machines, first seen first */
	size_t cap, builder_count, machine_count;
	const cJSON *doc;
};

/* 0, or -ENOMEM (the index is then empty, and finishing it is safe). */
int report_index_init(struct report_index *ix, const cJSON *doc);
void report_index_finish(struct report_index *ix);
/* The scene's runs, in document order; *count 0 when it has none. */
const cJSON *const *report_scene_runs(const struct report_index *ix, const char *scene,
                                      size_t *count);
/* The builder's number in order of first appearance (its colour in every
 * chart), or -1 when no run has it. */
long report_builder_number(const struct report_index *ix, const char *builder);
/* The number of the machine the run was measured on (0 for M1), in order
 * of first appearance; a document from one machine has only 0. */
long report_machine_number(const struct report_index *ix, const cJSON *run);
/* Build-time speedup of a run over the same builder's 1-thread run on
 * the same scene and machine, or NaN when there is none or the builder never ran on
 * more than 1 thread (a builder without the PARALLEL flag). */
double report_speedup(const struct report_index *ix, const cJSON *run);

/* Appends the thesis-style speedup tables (parallel builders against
 * sah_seq on 1 thread, per thread count > 1) to a report; nothing when the
 * document has no such runs. ix: the document's runs by scene.
 * report_thesis.c. */
void report_thesis(struct strbuf *sb, const struct cJSON *doc, const struct report_index *ix);

/* A section listing the machines the runs come from, when there are several
 * (a merged sweep; report_machines.c); nothing otherwise. */
void report_machines_md(struct strbuf *sb, const cJSON *doc);
void report_machines_html(struct strbuf *sb, const cJSON *doc);

/* A scene's animation section (report_frames.c): its runs' frames summed
 * up, the cheapest strategy, and in HTML SAH and cumulative cost over the
 * frames as charts; nothing for a scene without frames. */
void report_frames_md(struct strbuf *sb, const struct report_index *ix, const cJSON *scene);
/* The scene's two-level runs' levels apart, and each against the flat run
 * of its bottom's plugin (report_two_level.c); nothing without such runs. */
void report_two_level_md(struct strbuf *sb, const cJSON *const *runs, size_t n);
void report_two_level_html(struct strbuf *sb, const cJSON *const *runs, size_t n);
void report_frames_html(struct strbuf *sb, const struct report_index *ix, const cJSON *scene);

/* A scene's memory per triangle (report_memory.c): the builds' peak, with
 * the scene, and the whole child's, per run; nothing when no run has a
 * memory figure. */
void report_memory_md(struct strbuf *sb, const cJSON *const *runs, size_t n);
void report_memory_html(struct strbuf *sb, const cJSON *const *runs, size_t n);

/* "Cost per triangle against N" (report_scale.c): ns and bytes per
 * triangle of each builder, thread count and mesh over the mesh's sizes;
 * nothing unless some series has three sizes. */
void report_scale_md(struct strbuf *sb, const struct report_index *ix);
void report_scale_html(struct strbuf *sb, const struct report_index *ix);

/* ---- Pareto fronts (report_front.c) -------------------------------------- */

/* One candidate: its build time and a tree figure, both lower-is-better;
 * only points of the same group (thread count) are compared. */
struct front_point {
	double time, figure;
	long group;
};
#define FRONT_ON (-1)   /* on the front */
#define FRONT_NONE (-2) /* not compared: a figure is missing */

/* by[i]: FRONT_ON, FRONT_NONE, or the index of the point that dominates
 * point i (no slower, a figure no more than 0.05 % worse, better in one;
 * the fastest such on the front). O(n^2); all FRONT_NONE on no memory. */
void report_front_points(const struct front_point *p, size_t n, long *by);
/* "front", "—" or "dominated by X (0.80× time, −1.2 % SAH)" for point a. */
void report_front_text(char *buf, size_t size, const struct front_point *p, long by,
                       size_t a, const char *by_name, const char *figure);
/* One candidate of a scene's front at a thread count: a run with that
 * many threads, or the 1-thread run of a builder that ran on 1 thread only
 * (it cannot use more, and is still a choice at every thread count). */
struct front_entry {
	const cJSON *run;
	double threads; /* the front it competes on */
	size_t order;   /* the run's place in the scene */
	long machine;   /* report_machine_number's: fronts never mix machines */
};
/* The scene's entries by machine, thread count, then run order (malloc'd;
 * NULL on no memory). */
struct front_entry *report_front_entries(const struct report_index *ix,
                                         const cJSON *const *runs, size_t n, size_t *count);
/* The front_entry threads of a device builder's runs (a "device" in
 * results.json): a group of their own, after every CPU thread count. */
#define REPORT_DEVICE_GROUP 99999.0
/* Whether run ran on an OpenCL device (BVHLAB_BUILDER_DEVICE). */
bool report_on_device(const cJSON *run);
/* The front_point group of a machine's thread count. */
long report_front_group(long machine, double threads);
/* The SAH's weights, the report's SAH cost's and its ray cost's. */
#define REPORT_C_TRAV 1.0
#define REPORT_C_ISECT 1.0
/* The second front's figure: c_trav x nodes + c_isect x triangles visited
 * per primary ray (counting nodes alone rewards tiny leaves); NaN when
 * either was not measured. */
double report_ray_cost(const cJSON *run);
/* A front view's figure of a run (0: SAH cost, 1: ray cost) and its name
 * on the charts. */
double report_front_figure(int view, const cJSON *run);
const char *report_front_view_name(int view);
/* The entries as points of view's figure (runs not ok are not compared),
 * grouped by machine and thread count, and their verdicts. */
void report_entries_front(const struct front_entry *e, size_t m, int view,
                          struct front_point *p, long *by);
/* The distinct thread counts of the runs, ascending, at most max. */
size_t report_thread_counts(const cJSON *const *runs, size_t n, double *out, size_t max);
/* The scene's front table (both views: SAH cost, ray cost). */
void report_front_md(struct strbuf *sb, const struct report_index *ix,
                     const cJSON *const *runs, size_t n);
void report_front_html(struct strbuf *sb, const struct report_index *ix,
                       const cJSON *const *runs, size_t n);

/* A point's shape: bvhlab's own builders are circles, each peer library's
 * (report_style.c) has its own. */
enum svg_shape { SVG_CIRCLE, SVG_SQUARE, SVG_DIAMOND, SVG_TRIANGLE_DOWN };

/* One point or bar: a label and its values. */
struct svg_point {
	const char *label;  /* bars: beside the bar; scatter: the point's tooltip */
	const char *group;  /* the builder: the legend's entry, a line's series */
	double x, y;
	char colour[16];    /* the group's (svg_colour) */
	bool front;         /* scatter: on the Pareto front (a line joins them) */
	enum svg_shape shape; /* the group's (svg_plugin_shape) */
	const char *mark;   /* why its time is not to be trusted ("busy: ..."), or
	                     * NULL/"": drawn with a dashed ring, said in the tooltip */
};

/* ---- how points look (report_style.c) ----------------------------------- */

/* The colour of builder number k (report_builder_number) in every chart,
 * "#rrggbb" into buf (16 bytes): no two numbers share one. */
const char *svg_colour(long k, char *buf, size_t size);
/* The shape of a plugin's points: a peer library's own, else a circle. */
enum svg_shape svg_plugin_shape(const char *plugin);
/* "embree", "tinybvh", "bvh2" or "bvhlab": whose points have the shape. */
const char *svg_shape_name(enum svg_shape shape);
/* Opens a shape's element at (x, y), radius about r, filled, with extra
 * attributes; the caller closes it ("/>" or "><title>...</...>": the
 * element is svg_shape_tag's). */
void svg_shape(struct strbuf *sb, enum svg_shape shape, double x, double y, double r,
               const char *fill, const char *extra);
/* The element name svg_shape opened ("circle", "rect", "polygon"). */
const char *svg_shape_tag(enum svg_shape shape);
/* The dashed ring around a point whose time is marked busy or noisy. */
void svg_warn_ring(struct strbuf *sb, double x, double y, double r);
/* "noisy: why; busy: load", or "" for a run with no mark (report_marks.c's
 * verdicts, in the words of report.md's marks column). */
const char *report_run_marks(char *buf, size_t size, const struct report_index *ix,
                             const cJSON *run);

/* Horizontal bars of y, one per point, labelled. */
void svg_bars(struct strbuf *sb, const char *title, const char *unit,
              const struct svg_point *p, size_t n);
/* Points at (x, y) with axes named, a legend of the groups, the front's
 * points joined by a line and named. */
void svg_scatter(struct strbuf *sb, const char *title, const char *xname, const char *yname,
                 const struct svg_point *p, size_t n);
/* One polyline per group, points in the given order, each drawn as a
 * marker too, and a legend. */
void svg_lines(struct strbuf *sb, const char *title, const char *xname, const char *yname,
               const struct svg_point *p, size_t n);
/* svg_lines with a marker at each line's end only: points that sample a
 * curve. */
void svg_curves(struct strbuf *sb, const char *title, const char *xname, const char *yname,
                const struct svg_point *p, size_t n);

/* ---- break-even against the reference (report_breakeven.c) -------------- */

enum breakeven_kind {
	BREAKEVEN_NONE,   /* a figure is missing */
	BREAKEVEN_SAME,   /* the same cost at any ray count */
	BREAKEVEN_ALWAYS, /* no slower to build nor to trace: cheaper from the first ray */
	BREAKEVEN_NEVER,  /* no faster to build nor to trace */
	BREAKEVEN_AFTER,  /* slower build, faster rays: cheaper after `rays` rays */
	BREAKEVEN_UNTIL,  /* faster build, slower rays: cheaper up to `rays` rays */
};
struct breakeven {
	enum breakeven_kind kind;
	double rays;
};

/* Where build_ms + n rays at mrays Mrays/s costs the same as the
 * reference's build and rays. */
struct breakeven report_breakeven(double build_ms, double mrays, double ref_build_ms,
                                  double ref_mrays);
/* "after 1.2 M rays (33 frames)", "always cheaper", ...; frame_rays <= 0:
 * no frames. */
void report_breakeven_text(char *buf, size_t size, struct breakeven b, double frame_rays);
/* The scene's break-even table against reference builder ref (none when
 * ref is NULL or no run has rays). */
void report_breakeven_md(struct strbuf *sb, const struct report_index *ix, const char *ref,
                         const cJSON *const *runs, size_t n);
void report_breakeven_html(struct strbuf *sb, const struct report_index *ix, const char *ref,
                           const cJSON *const *runs, size_t n);

/* "950", "12.3 k", "1.2 M", "3.4 G": a count of rays. */
void report_ray_count(char *buf, size_t size, double n);

/* ---- the cheapest builder for a ray budget (report_budget.c) ------------ */

/* Where one candidate is the cheapest: from `from` rays up to `to`
 * (INFINITY: beyond). */
struct budget_interval {
	size_t index;
	double from, to;
};
/* The lower envelope of the lines build[k] + n * ray[k] (seconds) over
 * n >= 0: the cheapest candidate by ray count, in order, into out (room
 * for n); candidates with a NaN or a ray time <= 0 are left out. Returns
 * the intervals' count (0: no candidate). */
size_t report_budget_intervals(const double *build, const double *ray, size_t n,
                               struct budget_interval *out);
/* The summary's first lines: per scene and thread count, "up to N rays:
 * X; up to M: Y; beyond: Z", or "not measured". */
void report_budget_summary(struct strbuf *sb, const struct report_index *ix, bool html);
/* The scene's ray-budget table (and in HTML its charts). */
void report_budget_md(struct strbuf *sb, const struct report_index *ix, const char *scene);
void report_budget_html(struct strbuf *sb, const struct report_index *ix, const char *scene);

/* ---- marks on figures not to trust (report_marks.c) --------------------- */

/* Whether two runs built the very same tree (SAH cost, nodes, primary
 * nodes per ray all equal). */
bool report_same_tree(const cJSON *a, const cJSON *b);
/* The relative difference under which two throughputs count as noise. */
#define REPORT_NOISE 0.05
/* (max - min) / median of the run's timed builds, or NaN. */
double report_build_spread(const cJSON *run);
/* Whether the run is marked noisy (build repeats spread > 5 %, or a run of
 * the same tree traced > 5 % faster or slower); buf says why. */
bool report_noise(const struct report_index *ix, const cJSON *run, char *buf, size_t size);
/* Whether the load around the run exceeded the cores it left free (plus
 * the sweep's own thread); buf gives the figures. */
bool report_busy(const cJSON *doc, const cJSON *run, char *buf, size_t size);
/* The report's warning when some runs are busy; nothing otherwise. */
void report_load_warning(struct strbuf *sb, const cJSON *doc, bool html);

/* ---- the summary across scenes (report_summary.c) ------------------------ */

#define SUMMARY_METRICS 5 /* build time, SAH, EPO, primary and diffuse nodes/ray */

/* One builder x thread count: geometric means over scenes of its figures
 * relative to the reference builder's (NaN: no scene had both). */
struct summary_row {
	const char *builder; /* points into the document */
	double threads;
	bool device;         /* the runs ran on an OpenCL device: threads is the host's */
	long machine;        /* report_machine_number's: rows never mix machines */
	int scenes;          /* scenes with ok runs of both */
	double ratio[SUMMARY_METRICS];
};

/* The reference builder: report.reference (default sah_seq) as a builder
 * label, else the first builder of that plugin; when neither ran, the
 * first builder with an ok run (*fallback true). NULL when no run is ok.
 * *asked: the name the config asked for. */
const char *report_reference(const cJSON *doc, const char **asked, bool *fallback);
/* The reference's ok run on a scene and machine (report_machine_number's;
 * -1: any) with `threads` threads, else its ok run with the fewest; NULL
 * when it has none there. */
const cJSON *report_reference_run(const struct report_index *ix, const char *ref,
                                  const char *scene, long machine, double threads);
/* The rows (malloc'd, in run order; one per builder, thread count and
 * machine) and the reference builder's label; 0 rows (and *ref NULL) when
 * no run is ok. */
int report_summary(const struct report_index *ix, struct summary_row **rows, const char **ref);
/* The column name of metric m. */
const char *report_summary_metric(int m);
/* The summary section of report.md / report.html. */
void report_summary_md(struct strbuf *sb, const struct report_index *ix);
/* A scene's "Rays by kind" table when some run measured shadow or AO rays
 * (nothing otherwise), in HTML or Markdown. (report_kinds.c) */
void report_kinds(struct strbuf *sb, const cJSON *const *runs, size_t n, bool html);
void report_summary_html(struct strbuf *sb, const struct report_index *ix);

/* ---- wide trees (report_wide.c) ------------------------------------------ */

/* A scene's wide trees: every run's width, collapse, SAH before and after
 * it, nodes and triangles per ray and bytes per triangle; per collapse
 * method the 8-wide runs ranked by binary SAH and by measured 8-wide cost
 * with the Spearman correlation; the wide runs on the front of build time
 * against wide ray cost. Nothing for a scene without a wide tree. */
void report_wide_md(struct strbuf *sb, const struct report_index *ix, const cJSON *const *runs,
                    size_t n);
void report_wide_html(struct strbuf *sb, const struct report_index *ix,
                      const cJSON *const *runs, size_t n);
/* Spearman's rank correlation of a[0 .. n) and b (ties get their mean
 * rank); NaN for n < 3 or a ranking of all ties. */
double report_spearman(const double *a, const double *b, size_t n);

#endif
