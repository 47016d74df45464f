/*
 * refit's shared state: the update (refit.c), the layout it sweeps
 * (refit_layout.c) and the sweep (refit_sweep.c).
 *
 * The layout refit streams is a pre-order of sibling pairs: the root at
 * slot 0, and below every inner node its two children side by side at
 * `first`, then the left child's descendants, then the right child's.
 * Every subtree's descendants are then one contiguous span of the array,
 * [first, end), and every node's children come after it: a span refits
 * in one backwards sweep, and spans refit in parallel. Leaves' prim_index
 * ranges follow their nodes' order, so a sweep reads prim_index as a
 * stream too. A tree in another layout (any builder's, or one that a
 * refinement changed) is rewritten into this one at its update.
 */
#ifndef BVHLAB_REFIT_H
#define BVHLAB_REFIT_H

#include <stdatomic.h>
#include <stdbool.h>
#include <stdint.h>

#include <bvhlab/builder.h>

#include "team.h"

/* Subtrees the top of the tree is cut into, for any thread count: the cut
 * decides which layouts are accepted as they are, and the tree's node
 * order must not depend on the thread count. */
#define CUT_ROOTS 128
/* Room for a breadth-first cut that overshoots by a level. */
#define CUT_MAX (4 * CUT_ROOTS)

enum refit_fault {
	FAULT_NONE,
	FAULT_LAYOUT, /* not the streamed layout: rewrite it, then refit */
	FAULT_SHAPE,
	FAULT_PRIM,
	FAULT_MEMORY,
};

/* The descendants of one cut subtree: [lo, hi) of the node array. */
struct span {
	uint32_t lo, hi;
};

typedef struct refit {
	const bvhlab_host *host;
	bvhlab_build_ctx *ctx;
	const bvhlab_aabb *boxes; /* [prim_count] the primitives' new boxes */
	uint32_t prim_count;
	bvhlab_build_output *out; /* the tree: its capacity is the rewrite's room */
	bvhlab_node *nodes;       /* out's arrays, again after out grows */
	uint32_t node_count;
	uint32_t *prim_index;
	uint32_t index_count;
	uint32_t roots[CUT_MAX]; /* the subtrees below the cut */
	uint32_t root_count;
	uint32_t top[CUT_MAX];   /* the inner nodes above it, in pre-order */
	uint32_t top_count;
	struct span spans[CUT_MAX]; /* the inner roots' descendants, by lo */
	uint32_t span_count;
	atomic_uint next;        /* the next span to take */
	atomic_uint fault;       /* enum refit_fault: the first problem met */
	team team;
	team_host th;             /* the executor the team runs on */
} refit;

/* Nodes a sweep lists by kind at a time: their 128 KiB stay in L2
 * between its passes. */
#define REFIT_CHUNK 4096

/* A thread's scratch for its sweeps (refit_sweep.c). */
struct refit_scratch {
	uint32_t idx[REFIT_CHUNK];
};

/* Cuts the tree and finds its spans; FAULT_LAYOUT when the top of the
 * tree does not tile the array as the streamed layout does (nothing is
 * written then). */
enum refit_fault refit_plan(refit *r);

/* Rewrites the tree into the streamed layout, shape and leaf contents
 * kept, through the output's capacity past the counts; FAULT_SHAPE for a
 * cycle or a child out of range, FAULT_PRIM for references out of range,
 * FAULT_MEMORY where the output cannot grow. */
enum refit_fault refit_relayout(refit *r);

/* Refits span s, from its end to its start; FAULT_LAYOUT when it is not
 * in the streamed layout (its boxes are then unspecified, nothing outside
 * it touched), FAULT_PRIM for a reference past the primitives. */
enum refit_fault refit_sweep(const refit *r, struct span s, struct refit_scratch *w);

/* A leaf's box from its primitives; false for a reference out of range. */
bool refit_leaf(const refit *r, bvhlab_node *n);

/* An inner node's box from its two (refitted) children. */
void refit_inner(const refit *r, bvhlab_node *n);

static inline bool refit_has_children(const refit *r, const bvhlab_node *n)
{
	return n->first < r->node_count && r->node_count - n->first >= 2;
}

#endif /* BVHLAB_REFIT_H */
