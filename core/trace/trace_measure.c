/*
 * Timed ray batches: the whole batch is traced again and again until a
 * minimum time (and ray count, and number of passes) is reached, and the
 * throughput is the median over passes. One pass of 65k rays lasts a few
 * milliseconds, short enough for a scheduler hiccup or another process to
 * decide the figure; the median of many passes is what stays put between
 * runs on a shared machine. The counters come from one pass, so per-ray
 * averages stay exact. A measurement is a series of slices
 * (trace_series.h): one for bvhlab_trace_measure, one per round for the
 * harness's interleaved rounds.
 */
#include <errno.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include <bvhlab/machine.h>
#include <bvhlab/trace.h>

#include "trace/trace_batch.h"
#include "trace/trace_cl.h"
#include "trace/trace_instances.h"
#include "trace/trace_kernel.h"
#include "trace/trace_series.h"
#include "util/util.h"

#define DEFAULT_MAX_REPEATS 10000
#define MIN_REPEATS_CAP 10.0

const char *bvhlab_traversal_name(int traversal)
{
	switch (traversal) {
	case BVHLAB_TRAVERSAL_STACK:
		return "stack";
	case BVHLAB_TRAVERSAL_STACKLESS:
		return "stackless";
	case BVHLAB_TRAVERSAL_WIDE:
		return "wide";
	case BVHLAB_TRAVERSAL_DEVICE_STACK:
		return "device_stack";
	case BVHLAB_TRAVERSAL_DEVICE_STACKLESS:
		return "device_stackless";
	case BVHLAB_TRAVERSAL_WIDE4:
		return "wide4";
	case BVHLAB_TRAVERSAL_WIDE8:
		return "wide8";
	case BVHLAB_TRAVERSAL_DEVICE_WIDE8:
		return "device_wide8";
	default:
		return NULL;
	}
}

static int cmp_double(const void *a, const void *b)
{
	double x = *(const double *)a, y = *(const double *)b;
	return (x > y) - (x < y);
}

/* One timed pass: wall seconds, *cpu the threads' CPU seconds; the
 * counters of every worker go to *stats. */
static double pass(struct batch *b, struct worker *w, uint32_t threads,
                   bvhlab_trace_stats *stats, double *cpu)
{
	atomic_store_explicit(&b->next, 0, memory_order_relaxed);
	for (uint32_t k = 0; k < threads; k++)
		w[k] = (struct worker){0};
	double t0 = util_now();
	trace_run_workers(b, w, threads);
	double seconds = util_now() - t0;
	*stats = (bvhlab_trace_stats){0};
	*cpu = 0;
	for (uint32_t k = 0; k < threads; k++) {
		*cpu += w[k].cpu_s;
		stats->rays += w[k].stats.rays;
		stats->nodes_visited += w[k].stats.nodes_visited;
		stats->tris_tested += w[k].stats.tris_tested;
	}
	return seconds;
}

/* seconds: the slice's tracing CPU time so far (per thread), so a busy
 * machine stretches the wall time of a measurement, not shrinks it. */
static bool more(const bvhlab_trace_options *o, uint32_t done, double seconds, uint64_t rays)
{
	uint32_t min = o->min_repeats ? o->min_repeats : 1;
	if (seconds * 1e3 < o->min_ms || rays < o->min_rays)
		return true;
	/* min_repeats gives way once passes are so slow that they took ten
	 * times min_ms: a median of a few long passes is steady anyway. */
	return done < min && seconds * 1e3 < MIN_REPEATS_CAP * o->min_ms;
}

/* Median, min and max of n samples (sorts a copy). */
static void summarise(const double *x, uint32_t n, double *median, double *min, double *max)
{
	double *y = malloc(n * sizeof(*y));
	if (!y || n == 0) {
		free(y);
		return;
	}
	memcpy(y, x, n * sizeof(*y));
	qsort(y, n, sizeof(*y), cmp_double);
	*min = y[0];
	*max = y[n - 1];
	*median = n % 2 ? y[n / 2] : 0.5 * (y[n / 2 - 1] + y[n / 2]);
	free(y);
}

static double mrays(size_t rays, double seconds)
{
	return seconds > 0 ? (double)rays / seconds * 1e-6 : 0;
}

struct trace_series {
	struct batch b;
	struct worker *w;
	uint32_t threads;
	uint32_t max_repeats;
	uint32_t *parents;      /* stackless: the tree's parent links */
	double *best;           /* [tiles] least CPU seconds of each tile so far */
	double *cpu, *wall;     /* [cap] Mrays/s of each pass on either clock */
	uint32_t n, cap;
	bool counted;           /* stats hold the counters of one pass */
	bvhlab_trace_stats stats;
	double seconds_total;
	double cpu_total;       /* CPU seconds per thread of all passes */
	/* the device traversals: the tree (owned unless borrowed from the
	 * series this one was made like), the batch, the least kernel time */
	struct trace_cl_tree *cl_tree;
	struct trace_cl_batch *cl_batch;
	bool cl_borrowed;
	double cl_best_s;
	bvhlab_error err;       /* why a slice failed */
};

static int grow(struct trace_series *s)
{
	uint32_t cap = s->cap ? 2 * s->cap : 64;
	double *cpu = realloc(s->cpu, cap * sizeof(*cpu));
	if (cpu)
		s->cpu = cpu;
	double *wall = cpu ? realloc(s->wall, cap * sizeof(*wall)) : NULL;
	if (!wall)
		return -ENOMEM;
	s->wall = wall;
	s->cap = cap;
	return 0;
}

/* Keeps each tile's least CPU time over the passes so far. */
static void keep_best(const double *tile, double *best, size_t tiles)
{
	for (size_t i = 0; i < tiles; i++)
		best[i] = tile[i] < best[i] ? tile[i] : best[i];
}

/* One timed pass into the series' samples; its CPU seconds per thread. */
static double timed_pass(struct trace_series *s)
{
	bvhlab_trace_stats st;
	double c, w = pass(&s->b, s->w, s->threads, &st, &c);
	if (!s->counted) {
		if (!trace_is_wide(s->b.traversal))
			s->stats = st;
		s->counted = true;
		s->b.hits = NULL; /* filled once; later passes only time */
		s->b.nodes = NULL;
	}
	keep_best(s->b.tile_cpu, s->best, trace_tiles(s->b.count));
	s->cpu[s->n] = mrays(s->b.count, c / s->threads);
	s->wall[s->n++] = mrays(s->b.count, w);
	s->seconds_total += w;
	s->cpu_total += c / s->threads;
	return c / s->threads;
}

/* A device pass: its kernel time is the "cpu" sample, and the wall time
 * (launch to completion) what min_ms counts. Negative errno on failure. */
static double timed_pass_cl(struct trace_series *s)
{
	bvhlab_trace_stats st;
	double k, w;
	bool first = !s->counted;
	int r = trace_cl_pass(s->cl_batch, first ? s->b.hits : NULL, first ? s->b.nodes : NULL,
	                      first ? &st : NULL, &k, &w, &s->err);
	if (r < 0)
		return r;
	if (first) {
		s->stats = st;
		s->counted = true;
		s->b.hits = NULL;
		s->b.nodes = NULL;
	}
	s->cl_best_s = s->n == 0 || k < s->cl_best_s ? k : s->cl_best_s;
	s->cpu[s->n] = mrays(s->b.count, k);
	s->wall[s->n++] = mrays(s->b.count, w);
	s->seconds_total += w;
	s->cpu_total += w;
	return w;
}

int trace_series_slice(struct trace_series *s, const bvhlab_trace_options *o)
{
	double cpu_s = 0;
	uint32_t done = 0;
	if (s->b.count == 0)
		return 0;
	while (s->n < s->max_repeats) {
		if (s->n == s->cap && grow(s) < 0)
			return s->n ? 0 : -ENOMEM; /* the passes so far still make a median */
		double t = s->cl_batch ? timed_pass_cl(s) : timed_pass(s);
		if (t < 0)
			return s->n ? 0 : (int)t;
		cpu_s += t;
		done++;
		if (!more(o, done, cpu_s, (uint64_t)done * s->b.count))
			break;
	}
	return 0;
}

bool trace_series_done(const struct trace_series *s, const bvhlab_trace_options *o)
{
	return s->b.count == 0 || s->n >= s->max_repeats ||
	       (s->n && !more(o, s->n, s->cpu_total, (uint64_t)s->n * s->b.count));
}

void trace_series_timing(const struct trace_series *s, bvhlab_trace_timing *t)
{
	*t = (bvhlab_trace_timing){.stats = s->stats, .threads = s->threads, .repeats = s->n,
	                           .seconds_total = s->seconds_total};
	if (s->n == 0)
		return;
	double sum = 0;
	for (size_t i = 0; i < trace_tiles(s->b.count); i++)
		sum += s->best[i];
	t->mrays_best = s->cl_batch ? mrays(s->b.count, s->cl_best_s)
	                            : mrays(s->b.count, sum / s->threads);
	summarise(s->cpu, s->n, &t->mrays_median, &t->mrays_min, &t->mrays_max);
	summarise(s->wall, s->n, &t->wall_mrays_median, &t->wall_mrays_min, &t->wall_mrays_max);
	/* A batch of a few rays over a few triangles can take less than the
	 * thread clock's step in every tile (seen: 64 rays over two
	 * triangles, Mrays/s 0 in one run of fifty): no best time to speak
	 * of, but the passes' medians, by that clock or by the wall clock,
	 * still say how fast it went. */
	if (t->mrays_best <= 0)
		t->mrays_best = t->mrays_median > 0 ? t->mrays_median : t->wall_mrays_median;
}

/* The wide traversal's untimed pass of the stack traversal, for counters
 * of the binary tree; then the wide nodes for the timed passes. */
static int count_binary(struct trace_series *s)
{
	struct batch *b = &s->b;
	bvhlab_hit *hits = b->hits;
	int traversal = b->traversal;
	double cpu;
	b->traversal = BVHLAB_TRAVERSAL_STACK;
	b->hits = NULL;
	pass(b, s->w, s->threads, &s->stats, &cpu);
	b->traversal = traversal;
	b->hits = hits;
	b->nodes = NULL;
	return trace_view_wide(b->tree, b->scene, traversal, &b->view);
}

void trace_series_destroy(struct trace_series *s)
{
	if (!s)
		return;
	trace_view_free(&s->b.view);
	trace_cl_batch_destroy(s->cl_batch);
	if (!s->cl_borrowed)
		trace_cl_tree_destroy(s->cl_tree);
	free(s->parents);
	free(s->w);
	free(s->best);
	free(s->b.tile_cpu);
	free(s->cpu);
	free(s->wall);
	free(s);
}

/* The stack and stackless traversals read the binary copies
 * (trace_view_copy); a wide one reads its wide nodes, so its counting pass
 * walks the tree in place (the same nodes visited, the same triangles
 * tested) and the tree is not held three times at once: at 68.8M
 * triangles the binary copies alone are up to 6.9 GB (docs/benchmarks.md). */
static int series_views(struct trace_series *s, int traversal, bool counters)
{
	s->b.view = trace_view_plain(s->b.tree);
	if (trace_is_wide(traversal) && !s->b.count)
		return 0;
	if (trace_is_wide(traversal))
		return counters ? count_binary(s)
		                : trace_view_wide(s->b.tree, s->b.scene, traversal, &s->b.view);
	if (traversal == BVHLAB_TRAVERSAL_STACKLESS) {
		int r = bvhlab_tree_parents(s->b.tree, &s->parents);
		if (r < 0)
			return r;
	}
	int r = trace_view_copy(s->b.tree, s->b.scene, &s->b.view);
	s->b.view.parents = s->parents;
	return r;
}

/* A series with its buffers but no tracing copies yet. */
static struct trace_series *series_alloc(const struct batch *b, uint32_t threads,
                                         uint32_t max_repeats)
{
	struct trace_series *s = calloc(1, sizeof(*s));
	if (!s)
		return NULL;
	s->b = *b;
	atomic_init(&s->b.next, 0);
	s->threads = trace_thread_count(threads, b->count);
	s->max_repeats = max_repeats ? max_repeats : DEFAULT_MAX_REPEATS;
	size_t tiles = trace_tiles(b->count);
	s->w = calloc(s->threads, sizeof(*s->w));
	s->best = malloc((tiles ? tiles : 1) * sizeof(*s->best));
	s->b.tile_cpu = malloc((tiles ? tiles : 1) * sizeof(*s->b.tile_cpu));
	if (!s->w || !s->best || !s->b.tile_cpu) {
		trace_series_destroy(s);
		return NULL;
	}
	for (size_t i = 0; i < tiles; i++)
		s->best[i] = INFINITY;
	return s;
}

/* The device's copies of the tree and rays, instead of the CPU's. */
static int series_device(struct trace_series *s, const bvhlab_trace_options *o)
{
	int r = trace_cl_tree_create(o->device, o->traversal, s->b.tree, s->b.scene, &s->cl_tree,
	                             &s->err);
	if (r == 0)
		r = trace_cl_batch_create(s->cl_tree, s->b.rays, s->b.count, o->any_hit,
		                          &s->cl_batch, &s->err);
	return r;
}

int trace_series_create(const bvhlab_tree *tree, const bvhlab_scene *scene,
                        const bvhlab_ray *rays, size_t count, const bvhlab_trace_options *opts,
                        bvhlab_hit *hits, uint32_t *nodes, bool counters,
                        struct trace_series **out, bvhlab_error *err)
{
	*out = NULL;
	if (!bvhlab_traversal_name(opts->traversal)) {
		error_set(err, "no traversal %d", opts->traversal);
		return -EINVAL;
	}
	struct batch b = {.tree = tree, .scene = scene, .rays = rays, .count = count,
	                  .any = opts->any_hit, .traversal = opts->traversal, .hits = hits,
	                  .nodes = nodes};
	struct trace_series *s = series_alloc(&b, opts->threads, opts->max_repeats);
	if (!s) {
		error_set(err, "out of memory");
		return -ENOMEM;
	}
	int r = trace_cl_traversal(opts->traversal) ? series_device(s, opts)
	                                    : series_views(s, opts->traversal, counters);
	if (r < 0) {
		if (s->err.message[0])
			error_set(err, "%s", s->err.message);
		else
			error_set(err, "%s", r == -ENOMEM ? "out of memory" : "the tree's links");
		trace_series_destroy(s);
		return r;
	}
	*out = s;
	return 0;
}

int trace_series_create_like(const struct trace_series *base, const bvhlab_ray *rays,
                             size_t count, bool any, struct trace_series **out)
{
	struct batch b = base->b;
	b.any = any;
	b.rays = rays;
	b.count = count;
	b.hits = NULL;
	b.nodes = NULL;
	b.view.owned = NULL; /* borrowed: base frees them */
	b.view.owned_tris = NULL;
	b.view.owned_wide = NULL;
	b.view.owned_wide8 = NULL;
	*out = series_alloc(&b, base->threads, base->max_repeats);
	if (!*out)
		return -ENOMEM;
	if (!base->cl_tree)
		return 0;
	(*out)->cl_tree = base->cl_tree;
	(*out)->cl_borrowed = true;
	int r = trace_cl_batch_create(base->cl_tree, rays, count, b.any, &(*out)->cl_batch,
	                              &(*out)->err);
	if (r < 0) {
		trace_series_destroy(*out);
		*out = NULL;
	}
	return r;
}

const char *trace_series_error(const struct trace_series *s)
{
	return s->err.message;
}

const char *trace_series_device(const struct trace_series *s)
{
	return s->cl_tree ? trace_cl_device_name(s->cl_tree) : NULL;
}

int trace_measure(const bvhlab_tree *tree, const bvhlab_scene *scene, const bvhlab_ray *rays,
                  size_t count, const bvhlab_trace_options *opts, bvhlab_hit *hits,
                  uint32_t *nodes, bvhlab_trace_timing *timing, char *device, size_t device_size,
                  bvhlab_error *err)
{
	struct trace_series *s;
	*timing = (bvhlab_trace_timing){0};
	if (!bvhlab_traversal_name(opts->traversal)) {
		error_set(err, "no traversal %d", opts->traversal);
		return -EINVAL;
	}
	if (count == 0)
		return 0;
	int r = trace_series_create(tree, scene, rays, count, opts, hits, nodes, true, &s, err);
	if (r < 0)
		return r;
	r = trace_series_slice(s, opts);
	if (r == 0)
		trace_series_timing(s, timing);
	else
		error_set(err, "%s", s->err.message[0] ? s->err.message : strerror(-r));
	if (device && device_size && trace_series_device(s))
		snprintf(device, device_size, "%s", trace_series_device(s));
	trace_series_destroy(s);
	return r;
}

/* A two-level series on the device: tl's trees and the rays uploaded. */
static int two_level_device(struct trace_series *s, const struct trace_two_level *tl,
                            const bvhlab_trace_options *o)
{
	int r = trace_cl_two_level_create(o->device, o->traversal, tl, &s->cl_tree, &s->err);
	if (r == 0)
		r = trace_cl_batch_create(s->cl_tree, s->b.rays, s->b.count, false, &s->cl_batch,
		                          &s->err);
	return r;
}

/* The timed slice of a two-level batch b (its hits into b->hits), on the
 * CPU (b->two_level prepared) or on the device (tl's trees uploaded). */
static int two_level_slice(const struct batch *b, const struct trace_two_level *tl,
                           const bvhlab_trace_options *opts, bvhlab_trace_timing *timing,
                           char *device, size_t device_size, bvhlab_error *err)
{
	struct trace_series *s = series_alloc(b, opts->threads, opts->max_repeats);
	if (!s) {
		error_set(err, "out of memory");
		return -ENOMEM;
	}
	int r = trace_cl_traversal(opts->traversal) ? two_level_device(s, tl, opts) : 0;
	if (r == 0)
		r = trace_series_slice(s, opts);
	if (r == 0)
		trace_series_timing(s, timing);
	if (r < 0)
		error_set(err, "%s", s->err.message[0] ? s->err.message : strerror(-r));
	if (device && device_size && trace_series_device(s))
		snprintf(device, device_size, "%s", trace_series_device(s));
	trace_series_destroy(s);
	return r;
}

int trace_measure_two_level(const struct trace_two_level *tl, const bvhlab_ray *rays,
                            size_t count, const bvhlab_trace_options *opts, bvhlab_hit *hits,
                            bvhlab_trace_timing *timing, char *device, size_t device_size,
                            bvhlab_error *err)
{
	struct trace_two_level prepared = *tl;
	bool on_device = trace_cl_traversal(opts->traversal);
	*timing = (bvhlab_trace_timing){0};
	int r = on_device ? 0 : trace_two_level_prepare(&prepared, opts->traversal);
	if (r < 0) {
		error_set(err, "%s", r == -EINVAL ? "not a traversal of two-level scenes"
		                                  : "out of memory");
		return r;
	}
	/* The batch's own traversal stays the stack's, so its first pass keeps
	 * the counters (the two levels' nodes, whichever kernel walks them). */
	struct batch b = {.two_level = &prepared, .rays = rays, .count = count,
	                  .traversal = BVHLAB_TRAVERSAL_STACK, .hits = hits};
	if (count)
		r = two_level_slice(&b, tl, opts, timing, device, device_size, err);
	if (!on_device)
		trace_two_level_release(&prepared);
	return r;
}

int bvhlab_trace_measure(const bvhlab_tree *tree, const bvhlab_scene *scene,
                         const bvhlab_ray *rays, size_t count, const bvhlab_trace_options *opts,
                         bvhlab_hit *hits, uint32_t *nodes, bvhlab_trace_timing *timing)
{
	bvhlab_error err = {{0}};
	return trace_measure(tree, scene, rays, count, opts, hits, nodes, timing, NULL, 0, &err);
}
