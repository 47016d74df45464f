/*
 * What the two small-subtree builders share (sah_small.c at quality high,
 * sah_small_fast.c at fast): the local copies of a job's primitives, a
 * node of the walk, the sweep of one ordered run of slots and a leaf's
 * output. Static inline: they run per node and per primitive, in the
 * builders' own loops.
 */
#ifndef BVHLAB_SAH_SMALL_H
#define BVHLAB_SAH_SMALL_H

#include <math.h>
#include <string.h>

#include "sah_box.h"
#include "sah_nodes.h"
#include "sah_simd.h"
#include "sah_split.h"

/* A job's primitives copied by local index 0 .. n - 1. */
typedef struct small_copy {
	sah_builder *b;
	uint32_t begin;                   /* the subtree's first position */
	v4 lo[SAH_SMALL_MAX];             /* boxes, by local index */
	v4 hi[SAH_SMALL_MAX];
	float cen[3][SAH_SMALL_MAX];      /* centroids, by axis and local index */
	uint32_t id[SAH_SMALL_MAX];
	float right[SAH_SMALL_MAX];       /* the sweep's A_R * N_R of the slots from j on */
} small_copy;

typedef struct small_node {
	uint32_t node, lb, le; /* node slot; its slots [lb, le) */
	bvhlab_aabb box;
} small_node;

/* Starts the copies of job's primitives for builder b: the array they are
 * in, at the job's positions, for small_load_prim. */
static inline const sah_prim *small_begin(small_copy *l, sah_builder *b, const sah_job *job)
{
	l->b = b;
	l->begin = job->begin;
	return sah_job_prims(b, job);
}

/* Copies primitive p (the job's k-th) as local index k. */
static inline void small_load_prim(small_copy *l, const sah_prim *p, uint32_t k)
{
	l->lo[k] = v4_load3(p->lo);
	l->hi[k] = v4_load3(p->hi);
	for (int a = 0; a < 3; a++)
		l->cen[a][k] = prim_centroid(p, a);
	l->id[k] = p->id;
}

/*
 * The lowest cost below `best` of the planes of axis a between consecutive
 * distinct centroids of the node's slots [lb, le), taken in order o (by
 * that axis), first position in *pos; `best` itself when none is lower.
 * The counts (at most SAH_SMALL_MAX) convert as int32_t: one instruction,
 * where an unsigned count may cost a register copy more per plane.
 */
static inline float small_sweep(small_copy *l, const uint8_t *o, int a, uint32_t lb, uint32_t le,
                                float best, uint32_t *pos)
{
	const float *c = l->cen[a];
	v4 lo = v4_set1(INFINITY), hi = v4_set1(-INFINITY);

	for (uint32_t j = le - 1; j > lb; j--) {
		lo = v4_min(lo, l->lo[o[j]]);
		hi = v4_max(hi, l->hi[o[j]]);
		l->right[j] = v4_half_area(lo, hi) * (float)(int32_t)(le - j);
	}
	lo = v4_set1(INFINITY);
	hi = v4_set1(-INFINITY);
	for (uint32_t j = lb + 1; j < le; j++) {
		lo = v4_min(lo, l->lo[o[j - 1]]);
		hi = v4_max(hi, l->hi[o[j - 1]]);
		if (!(c[o[j - 1]] < c[o[j]]))
			continue;
		float cost = v4_half_area(lo, hi) * (float)(int32_t)(j - lb) + l->right[j];
		if (cost < best) {
			best = cost;
			*pos = j;
		}
	}
	return best;
}

/* Node c as a leaf over its slots, their primitives in order o. */
static inline void small_write_leaf(const small_copy *l, const small_node *c, const uint8_t *o)
{
	sah_builder *b = l->b;
	bvhlab_node *node = &b->nodes[c->node];

	memcpy(node->lo, c->box.lo, sizeof(node->lo));
	memcpy(node->hi, c->box.hi, sizeof(node->hi));
	node->first = l->begin + c->lb;
	node->count = c->le - c->lb;
	for (uint32_t k = c->lb; k < c->le; k++)
		b->ids[l->begin + k] = l->id[o[k]];
}

/* A node's two children written after it splits (their node slots too). */
static inline unsigned small_write_inner(const small_copy *l, const small_node *c,
                                         small_node child[2])
{
	sah_write_node(l->b, c->node, &c->box, &child[0].node);
	child[1].node = child[0].node + 1;
	return 2;
}

/*
 * The walk of a job's subtree over slots [0, n), depth first, the left
 * child first: split(state, node, child) decides each node, 2 when it
 * filled the children. Inlined into each builder with its own static
 * split, which the compiler then calls directly.
 */
static inline void small_walk(const sah_job *job, uint32_t n, void *state,
                              unsigned (*split)(void *state, const small_node *c,
                                                small_node child[2]))
{
	small_node stack[SAH_SMALL_MAX], child[2];
	uint32_t sp = 0;

	stack[sp++] = (small_node){ .node = job->node, .lb = 0, .le = n, .box = job->box };
	while (sp > 0) {
		small_node cur = stack[--sp];
		if (split(state, &cur, child) == 2) {
			stack[sp++] = child[1];
			stack[sp++] = child[0];
		}
	}
}

#endif /* BVHLAB_SAH_SMALL_H */
