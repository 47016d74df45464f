/*
 * The batch tracer's internals, shared by bvhlab_trace_batch (one pass,
 * trace_batch.c) and bvhlab_trace_measure (timed passes, trace_measure.c).
 */
#ifndef BVHLAB_CORE_TRACE_BATCH_H
#define BVHLAB_CORE_TRACE_BATCH_H

#include <stdatomic.h>
#include <stdbool.h>
#include <stddef.h>
#include <stdint.h>

#include <bvhlab/trace.h>
#include <bvhlab/tree.h>

#include "trace/trace_kernel.h"

struct trace_two_level; /* trace_instances.h */

/* Rays per tile: large enough that the counter is rarely touched, small
 * enough to balance 2 to 64 threads over 64k rays. */
#define TILE 256

struct batch {
	const bvhlab_tree *tree;
	const bvhlab_scene *scene;
	const bvhlab_ray *rays;
	size_t count;
	bool any;
	int traversal;          /* enum bvhlab_traversal */
	const struct trace_two_level *two_level; /* a two-level scene's trees, traced with
	                                         * their own traversal (trace_instances.h)
	                                         * instead of tree and scene; or NULL */
	struct trace_view view; /* what the traversal reads */
	double *tile_cpu;       /* [tiles] CPU seconds of each tile of a pass, or NULL */
	bvhlab_hit *hits;
	uint32_t *nodes;
	atomic_size_t next;
	struct worker *workers; /* [threads] one per team member */
};

struct worker {
	bvhlab_trace_stats stats;
	double cpu_s; /* the thread's CPU time in the batch (CLOCK_THREAD_CPUTIME_ID) */
};

/* Tiles of a batch of `count` rays. */
static inline size_t trace_tiles(size_t count)
{
	return (count + TILE - 1) / TILE;
}

/* One ray through a view with a CPU traversal (enum bvhlab_traversal:
 * stack, stackless, wide, wide4, wide8; wide8 falls back to the 4-lane
 * kernel on a view without 8-lane nodes), as the batch tracer does. */
void trace_ray_view(int traversal, const bvhlab_tree *tree, const bvhlab_scene *scene,
                    const struct trace_view *view, const bvhlab_ray *ray, bool any,
                    bvhlab_hit *hit, bvhlab_trace_stats *st);

/* Threads a batch of `count` rays gets: 0 means all hardware threads, and
 * never more than there are tiles. */
uint32_t trace_thread_count(uint32_t threads, size_t count);

/* Traces the batch on a team of the executor of up to `threads`, w[0] on
 * the calling thread; each member's counters are added to its worker's
 * stats (w[] zeroed by the caller). */
void trace_run_workers(struct batch *b, struct worker *w, uint32_t threads);

#endif
