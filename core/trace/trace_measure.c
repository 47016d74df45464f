/*
 * Timed ray batches: the whole batch is traced again and again until a
 * minimum time (and ray count, and number of passes) is reached, and the
 * throughput is the median over passes. One pass of 65k rays lasts a few
 * milliseconds, short enough for a scheduler hiccup or another process to
 * decide the figure; the median of many passes is what stays put between
 * runs on a shared machine. The counters come from one pass, so per-ray
 * averages stay exact.
 */
#include <errno.h>
#include <math.h>
#include <stdlib.h>

#include <bvhlab/machine.h>
#include <bvhlab/traversal.h>

#include "trace/trace_batch.h"
#include "trace/trace_kernel.h"
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
		w[k].stats = (bvhlab_trace_stats){0};
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

/* seconds: the tracing threads' CPU time so far (per thread), so a busy
 * machine stretches the wall time of a measurement, not shrinks it. */
static bool more(const bvhlab_trace_options *o, uint32_t done, double seconds, uint64_t rays)
{
	uint32_t max = o->max_repeats ? o->max_repeats : DEFAULT_MAX_REPEATS;
	uint32_t min = o->min_repeats ? o->min_repeats : 1;
	if (done >= max)
		return false;
	if (seconds * 1e3 < o->min_ms || rays < o->min_rays)
		return true;
	/* min_repeats gives way once passes are so slow that they took ten
	 * times min_ms: a median of a few long passes is steady anyway. */
	return done < min && seconds * 1e3 < MIN_REPEATS_CAP * o->min_ms;
}

/* Median, min and max of n samples (sorts them). */
static void summarise(double *x, uint32_t n, double *median, double *min, double *max)
{
	qsort(x, n, sizeof(*x), cmp_double);
	*min = x[0];
	*max = x[n - 1];
	*median = n % 2 ? x[n / 2] : 0.5 * (x[n / 2 - 1] + x[n / 2]);
}

static double mrays(size_t rays, double seconds)
{
	return seconds > 0 ? (double)rays / seconds * 1e-6 : 0;
}

static int grow(double **a, double **b, uint32_t *cap)
{
	double *ga = realloc(*a, 2 * *cap * sizeof(**a));
	if (ga)
		*a = ga;
	double *gb = ga ? realloc(*b, 2 * *cap * sizeof(**b)) : NULL;
	if (!gb)
		return -ENOMEM;
	*b = gb;
	*cap *= 2;
	return 0;
}

/* Keeps each tile's least CPU time over the passes so far. */
static void keep_best(const double *tile, double *best, size_t tiles)
{
	for (size_t i = 0; i < tiles; i++)
		best[i] = tile[i] < best[i] ? tile[i] : best[i];
}

static int run_passes(struct batch *b, struct worker *w, uint32_t threads,
                      const bvhlab_trace_options *o, bvhlab_trace_timing *t)
{
	uint32_t cap = 64, n = 0;
	double cpu_total = 0;
	size_t tiles = trace_tiles(b->count);
	double *cpu = malloc(cap * sizeof(*cpu)), *wall = malloc(cap * sizeof(*wall));
	double *best = malloc(tiles * sizeof(*best));
	b->tile_cpu = malloc(tiles * sizeof(*b->tile_cpu));
	int r = cpu && wall && best && b->tile_cpu ? 0 : -ENOMEM;
	for (size_t i = 0; r == 0 && i < tiles; i++)
		best[i] = INFINITY;
	while (r == 0) {
		bvhlab_trace_stats st;
		double c, s = pass(b, w, threads, &st, &c);
		if (n == 0) {
			if (b->traversal != BVHLAB_TRAVERSAL_WIDE)
				t->stats = st;
			b->hits = NULL; /* filled once; later passes only time */
			b->nodes = NULL;
		}
		keep_best(b->tile_cpu, best, tiles);
		cpu[n] = mrays(b->count, c / threads);
		wall[n++] = mrays(b->count, s);
		t->seconds_total += s;
		cpu_total += c / threads;
		if (!more(o, n, cpu_total, (uint64_t)n * b->count))
			break;
		if (n == cap && grow(&cpu, &wall, &cap) < 0)
			break; /* the passes so far still make a median */
	}
	if (r == 0) {
		double sum = 0;
		for (size_t i = 0; i < tiles; i++)
			sum += best[i];
		t->repeats = n;
		t->mrays_best = mrays(b->count, sum / threads);
		summarise(cpu, n, &t->mrays_median, &t->mrays_min, &t->mrays_max);
		summarise(wall, n, &t->wall_mrays_median, &t->wall_mrays_min, &t->wall_mrays_max);
	}
	free(cpu);
	free(wall);
	free(best);
	free(b->tile_cpu);
	b->tile_cpu = NULL;
	return r;
}

/* The wide traversal's untimed pass of the stack traversal, for counters
 * of the binary tree; then the wide nodes for the timed passes. */
static int count_binary(const bvhlab_tree *tree, const bvhlab_scene *scene, struct batch *b,
                        struct worker *w, uint32_t threads, bvhlab_trace_timing *t)
{
	bvhlab_hit *hits = b->hits;
	double cpu;
	b->traversal = BVHLAB_TRAVERSAL_STACK;
	b->hits = NULL;
	pass(b, w, threads, &t->stats, &cpu);
	b->traversal = BVHLAB_TRAVERSAL_WIDE;
	b->hits = hits;
	b->nodes = NULL;
	return trace_view_wide(tree, scene, &b->view);
}

int bvhlab_trace_measure(const bvhlab_tree *tree, const bvhlab_scene *scene,
                         const bvhlab_ray *rays, size_t count, const bvhlab_trace_options *opts,
                         bvhlab_hit *hits, uint32_t *nodes, bvhlab_trace_timing *timing)
{
	struct batch b = {.tree = tree, .scene = scene, .rays = rays, .count = count,
	                  .any = opts->any_hit, .traversal = opts->traversal, .hits = hits,
	                  .nodes = nodes};
	uint32_t *parents = NULL;
	*timing = (bvhlab_trace_timing){0};
	if (!bvhlab_traversal_name(opts->traversal))
		return -EINVAL;
	if (count == 0)
		return 0;
	if (opts->traversal == BVHLAB_TRAVERSAL_STACKLESS) {
		int r = bvhlab_tree_parents(tree, &parents);
		if (r < 0)
			return r;
	}
	uint32_t threads = trace_thread_count(opts->threads, count);
	struct worker *w = calloc(threads, sizeof(*w));
	int r = w ? trace_view_copy(tree, scene, &b.view) : -ENOMEM;
	b.view.parents = parents;
	atomic_init(&b.next, 0);
	if (r == 0 && opts->traversal == BVHLAB_TRAVERSAL_WIDE)
		r = count_binary(tree, scene, &b, w, threads, timing);
	if (r == 0)
		r = run_passes(&b, w, threads, opts, timing);
	timing->threads = threads;
	free(w);
	trace_view_free(&b.view);
	free(parents);
	return r;
}
