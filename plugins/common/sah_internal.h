/*
 * Private to the SAH kernel's sources: box helpers and the per-method split
 * functions behind sah_split_job. Plugins include sah_kernel.h only.
 */
#ifndef BVHLAB_SAH_INTERNAL_H
#define BVHLAB_SAH_INTERNAL_H

#include <math.h>
#include <stdbool.h>

#include "sah_kernel.h"

/* Comparisons rather than fminf/fmaxf: they compile to single min/max
 * instructions, and primitive boxes are never NaN. */
static inline float minf(float a, float b)
{
	return a < b ? a : b;
}

static inline float maxf(float a, float b)
{
	return a > b ? a : b;
}

static inline void box_empty(bvhlab_aabb *b)
{
	for (int k = 0; k < 3; k++) {
		b->lo[k] = INFINITY;
		b->hi[k] = -INFINITY;
	}
}

static inline void box_grow(bvhlab_aabb *b, const bvhlab_aabb *p)
{
	for (int k = 0; k < 3; k++) {
		b->lo[k] = minf(b->lo[k], p->lo[k]);
		b->hi[k] = maxf(b->hi[k], p->hi[k]);
	}
}

/* Half the surface area: the factor 2 cancels in every SAH ratio. */
static inline float box_half_area(const bvhlab_aabb *b)
{
	float dx = b->hi[0] - b->lo[0], dy = b->hi[1] - b->lo[1], dz = b->hi[2] - b->lo[2];
	return dx * dy + dy * dz + dz * dx;
}

/* The kernel's one definition of a centroid (see sah_prim). */
static inline float prim_centroid(const sah_prim *p, int axis)
{
	return 0.5f * (p->lo[axis] + p->hi[axis]);
}

static inline void prim_box(const sah_prim *p, bvhlab_aabb *box)
{
	for (int k = 0; k < 3; k++) {
		box->lo[k] = p->lo[k];
		box->hi[k] = p->hi[k];
	}
}

/* Grows b by the box of p. */
static inline void box_grow_prim(bvhlab_aabb *b, const sah_prim *p)
{
	for (int k = 0; k < 3; k++) {
		b->lo[k] = minf(b->lo[k], p->lo[k]);
		b->hi[k] = maxf(b->hi[k], p->hi[k]);
	}
}

/* Grows b by the centroid of p. */
static inline void box_grow_centroid(bvhlab_aabb *b, const sah_prim *p)
{
	for (int k = 0; k < 3; k++) {
		float c = prim_centroid(p, k);
		b->lo[k] = minf(b->lo[k], c);
		b->hi[k] = maxf(b->hi[k], c);
	}
}

/*
 * Copies the input boxes into dst (prim_count records, id order) and sets
 * b->root_cbox; with input->threads > 1 the parts are copied by that many
 * threads at once (sah_prims.c).
 */
void sah_copy_prims(sah_builder *b, const bvhlab_build_input *input, sah_prim *dst);

/* Jobs of at most this many primitives are built whole by
 * sah_small_subtree (exact SAH on local copies, see sah_small.c). Local
 * indices are bytes, so at most 256. */
#define SAH_SMALL_MAX 64

/* Builds job's whole subtree on the calling thread. */
void sah_small_subtree(sah_builder *b, const sah_job *job);

/* Writes job's node as a leaf over its whole range. */
void sah_write_leaf(sah_builder *b, const sah_job *job);

/*
 * Writes job's node as an inner node, allocates its two children and sets
 * their node, range [begin, mid) / [mid, end) and depth; boxes are the
 * caller's to fill.
 */
void sah_write_inner(sah_builder *b, const sah_job *job, uint32_t mid, sah_job child[2]);

/*
 * Writes nodes[node] as an inner node with box and allocates its two
 * adjacent children; their first slot goes to *first.
 */
void sah_write_node(sah_builder *b, uint32_t node, const bvhlab_aabb *box, uint32_t *first);

/*
 * The leaf rule for a node of n primitives with box, given `found` (a
 * candidate split exists) and its best weighted area sum A_L*N_L + A_R*N_R.
 */
bool sah_leaf_rule(const sah_options *opt, uint32_t n, const bvhlab_aabb *box, bool found,
                   float best);

/*
 * The leaf rule: true when job should become a leaf given `found` (a
 * candidate split exists) and its best weighted area sum
 * A_L * N_L + A_R * N_R. The caller handles N == 1 and the median fallback.
 */
bool sah_prefer_leaf(const sah_builder *b, const sah_job *job, bool found, float best);

/* The methods behind sah_split_job; same contract. */
unsigned sah_sweep_split(sah_builder *b, const sah_job *job, sah_job child[2]);
unsigned sah_binned_split(sah_builder *b, const sah_job *job, sah_job child[2]);

/*
 * Fills b->prims[0..2] with the primitives sorted by centroid along each
 * axis (stable, so ties stay in id order). 0 or -ENOMEM.
 */
int sah_presort(sah_builder *b);

#endif /* BVHLAB_SAH_INTERNAL_H */
