/*
 * The horizontal half of sah_tasks: one large node binned and partitioned
 * by a team of P threads, each working on a contiguous chunk of the node's
 * range. The split chosen is the kernel's binned split bit for bit: bins
 * are min/max unions and integer counts, which do not depend on the order
 * they are gathered in, and the cost is evaluated with the kernel's exact
 * operations (sah_binned.c). The partition is stable on both sides (chunk
 * prefix sums give every element its place), so its result does not depend
 * on P either; it differs from the kernel's in-place partition only in the
 * order inside each child, which binned splits ignore (they depend on the
 * set). Only the object-median fallback, reached when more than max_leaf
 * centroids coincide, reads that order.
 *
 * Protocol, each step a barrier apart: the caller's tasks_split_begin;
 * parts 0..P-1 of tasks_bin; the caller's tasks_choose; parts of
 * tasks_count; the caller's tasks_counted; parts of tasks_scatter; parts of
 * tasks_copy; the caller's tasks_split_end.
 */
#ifndef BVHLAB_TASKS_SPLIT_H
#define BVHLAB_TASKS_SPLIT_H

#include <stdbool.h>
#include <stdint.h>

#include "sah_kernel.h"

/* One thread's private bins, all three axes. */
typedef struct tasks_bins {
	uint32_t count[3][SAH_MAX_BINS];
	float lo[3][SAH_MAX_BINS][4];
	float hi[3][SAH_MAX_BINS][4];
} tasks_bins;

typedef struct tasks_split {
	sah_builder *b;
	sah_prim *temp;     /* [prim_count] scatter target, by position */
	uint32_t parts;     /* team size P */
	tasks_bins *bins;   /* [P]; part t writes bins[t] only */
	uint32_t *left;     /* [P] left count of chunk t */
	bvhlab_aabb *cbox;  /* [2P] centroid bounds of chunk t's left and right part */
	sah_job job;        /* the node being split */
	uint32_t nb, split, mid;
	int axis;           /* -1: no candidate */
	float lo[3], scale[3];
} tasks_split;

/* Allocates the per-part scratch and the temp array. 0 or -ENOMEM. */
int tasks_split_init(tasks_split *s, sah_builder *b, uint32_t parts);
void tasks_split_free(tasks_split *s);

void tasks_split_begin(tasks_split *s, const sah_job *job);
void tasks_bin(tasks_split *s, uint32_t part);
/* Reduces the bins in part order and picks the split; false when no
 * candidate exists (the caller then lets the kernel split the node). */
bool tasks_choose(tasks_split *s);
void tasks_count(tasks_split *s, uint32_t part);
/* Sets mid from the parts' left counts. */
void tasks_counted(tasks_split *s);
void tasks_scatter(tasks_split *s, uint32_t part);
void tasks_copy(tasks_split *s, uint32_t part);
/* Writes the inner node and fills both children. */
void tasks_split_end(tasks_split *s, sah_job child[2]);

#endif /* BVHLAB_TASKS_SPLIT_H */
