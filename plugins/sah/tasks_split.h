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
 * tasks_scatter; the caller's tasks_split_end.
 *
 * As in the kernel's binned split, the node's primitives are read from one
 * of the builder's two arrays (sah_job.alt) and scattered into the other,
 * where its children then are.
 */
#ifndef BVHLAB_TASKS_SPLIT_H
#define BVHLAB_TASKS_SPLIT_H

#include <stdbool.h>
#include <stdint.h>

#include "sah_kernel.h"

typedef struct tasks_split {
	sah_builder *b;
	const sah_prim *src; /* the node's array: the builder's prims[0] or alt */
	sah_prim *dst;      /* the other one, where its children go */
	uint32_t parts;     /* team size P */
	sah_bins *bins;     /* [P]; part t writes bins[t] only */
	sah_bins *total;    /* the parts' bins merged, for the choice */
	uint32_t *left;     /* [P] left count of chunk t, from its bins */
	bvhlab_aabb *cbox;  /* [2P] centroid bounds of chunk t's left and right part */
	sah_job job;        /* the node being split */
	sah_grid grid;      /* the node's bins */
	uint32_t split, mid;
	int axis;           /* -1: no candidate */
} tasks_split;

/* Allocates the per-part scratch. 0 or -ENOMEM. */
int tasks_split_init(tasks_split *s, sah_builder *b, uint32_t parts);
void tasks_split_free(tasks_split *s);

void tasks_split_begin(tasks_split *s, const sah_job *job);
void tasks_bin(tasks_split *s, uint32_t part);
/* Reduces the bins in part order, picks the split and sets mid and the
 * parts' left counts from the bins; false when no candidate exists (the
 * caller then lets the kernel split the node). */
bool tasks_choose(tasks_split *s);
void tasks_scatter(tasks_split *s, uint32_t part);
/* Writes the inner node and fills both children. */
void tasks_split_end(tasks_split *s, sah_job child[2]);

#endif /* BVHLAB_TASKS_SPLIT_H */
