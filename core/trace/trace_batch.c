/*
 * Tracing a batch of rays on the process's executor (core/exec), placed on
 * the caller's CPU set and pinned as builds are. Rays are handed out in
 * tiles from one atomic counter, so threads that draw cheap rays take more
 * tiles; each thread keeps its own counters and they are summed at the
 * end, so nothing is shared in the hot loop but the counter.
 */
#include <errno.h>
#include <stdatomic.h>
#include <stdlib.h>
#include <time.h>

#include <bvhlab/machine.h>
#include <bvhlab/trace.h>

#include "exec/exec.h"
#include "util/util.h"

#include "trace/trace_batch.h"
#include "trace/trace_instances.h"
#include "trace/trace_kernel.h"
#include "trace/trace_wide8.h"

void trace_ray_view(int traversal, const bvhlab_tree *tree, const bvhlab_scene *scene,
                    const struct trace_view *view, const bvhlab_ray *ray, bool any,
                    bvhlab_hit *hit, bvhlab_trace_stats *st)
{
	if (traversal == BVHLAB_TRAVERSAL_WIDE8 && view->wide8)
		trace_ray_wide8(tree, scene, view, ray, any, hit, st);
	else if (trace_is_wide(traversal))
		trace_ray_wide(tree, scene, view, ray, any, hit, st);
	else if (traversal == BVHLAB_TRAVERSAL_STACKLESS)
		trace_ray_stackless(tree, scene, view, ray, any, hit, st);
	else
		trace_ray_stack(tree, scene, view, ray, any, hit, st);
}

static void trace_tile(struct batch *b, size_t begin, size_t end, bvhlab_trace_stats *st)
{
	for (size_t i = begin; i < end; i++) {
		bvhlab_hit hit;
		uint64_t before = st->nodes_visited;
		if (b->two_level)
			trace_two_level_hit(b->two_level, &b->rays[i], &hit, st);
		else
			trace_ray_view(b->traversal, b->tree, b->scene, &b->view, &b->rays[i], b->any,
			               &hit, st);
		if (b->hits)
			b->hits[i] = hit;
		if (b->nodes)
			b->nodes[i] = (uint32_t)(st->nodes_visited - before);
	}
}

static double cpu_seconds(void)
{
	struct timespec t;
	clock_gettime(CLOCK_THREAD_CPUTIME_ID, &t);
	return (double)t.tv_sec + 1e-9 * (double)t.tv_nsec;
}

static void work(void *arg, uint32_t member)
{
	struct batch *b = arg;
	struct worker *w = &b->workers[member];
	double t0 = cpu_seconds();
	for (;;) {
		size_t begin = atomic_fetch_add_explicit(&b->next, TILE, memory_order_relaxed);
		if (begin >= b->count)
			break;
		size_t end = b->count - begin < TILE ? b->count : begin + TILE;
		double c0 = b->tile_cpu ? cpu_seconds() : 0;
		trace_tile(b, begin, end, &w->stats);
		/* Each tile is one thread's: no other thread writes this slot. */
		if (b->tile_cpu)
			b->tile_cpu[begin / TILE] = cpu_seconds() - c0;
	}
	w->cpu_s = cpu_seconds() - t0;
}

uint32_t trace_thread_count(uint32_t threads, size_t count)
{
	size_t tiles = (count + TILE - 1) / TILE;
	if (threads == 0)
		threads = bvhlab_hardware_threads();
	if (threads > tiles)
		threads = tiles ? (uint32_t)tiles : 1;
	return threads;
}

/* A team of `threads`, the calling thread as member 0; a smaller team
 * (the pool short of threads) still traces everything. Workers of members
 * that did not run keep zero counters. A place that cannot be had (the
 * mask unreadable) leaves the caller alone. */
void trace_run_workers(struct batch *b, struct worker *w, uint32_t threads)
{
	struct exec_place place;
	b->workers = w;
	if (exec_place_begin(&place) == 0)
		exec_run_some(&place, threads, work, b);
	else
		work(b, 0);
	exec_place_end(&place);
}

int bvhlab_trace_batch(const bvhlab_tree *tree, const bvhlab_scene *scene,
                       const bvhlab_ray *rays, size_t count, bool any_hit, uint32_t threads,
                       bvhlab_hit *hits, uint32_t *nodes, bvhlab_trace_stats *stats,
                       double *seconds)
{
	struct batch b = {.tree = tree, .scene = scene, .rays = rays, .count = count,
	                  .any = any_hit, .hits = hits, .nodes = nodes,
	                  .view = trace_view_plain(tree)};
	atomic_init(&b.next, 0);
	threads = trace_thread_count(threads, count);
	struct worker *w = calloc(threads, sizeof(*w));
	if (!w)
		return -ENOMEM;
	double t0 = util_now();
	trace_run_workers(&b, w, threads);
	if (seconds)
		*seconds = util_now() - t0;
	for (uint32_t k = 0; stats && k < threads; k++) {
		stats->rays += w[k].stats.rays;
		stats->nodes_visited += w[k].stats.nodes_visited;
		stats->tris_tested += w[k].stats.tris_tested;
	}
	free(w);
	return 0;
}
