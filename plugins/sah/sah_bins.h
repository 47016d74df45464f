/*
 * Binning, for the kernel's binned splits and for schedulers that bin one
 * node in parts (sah_tasks): the grid places centroids, the bins gather
 * counts and box unions (types in sah_types.h). Unions are min/max and
 * counts integers, so bins filled in any parts and merged in any order are
 * bit-identical, and the choice depends only on the node's set of
 * primitives. Implemented by sah_bins.c.
 */
#ifndef BVHLAB_SAH_BINS_H
#define BVHLAB_SAH_BINS_H

#include "sah_types.h"

/* The grid of nb bins over job's centroid bounds. */
void sah_grid_init(sah_grid *g, const sah_job *job, uint32_t nb);

/* A centroid's bin along axis a. sah_bins_fill computes the same, with
 * the same operations, for three axes at once. */
static inline uint32_t sah_grid_bin(const sah_grid *g, int a, const sah_prim *p)
{
	float f = (0.5f * (p->lo[a] + p->hi[a]) - g->lo[a]) * g->scale[a];
	float top = (float)(g->nb - 1);

	f = f < top ? f : top;
	return f > 0 ? (uint32_t)f : 0;
}

/* Overwrites the grid's bins in out with prims[begin, end), with 8-lane
 * vectors when simd is SAH_SIMD_AVX2 (which sah_options_resolve only picks
 * where the CPU has AVX2). */
void sah_bins_fill(sah_bins *out, const sah_grid *g, const sah_prim *prims, uint32_t begin,
                   uint32_t end, int simd);

/* Every bin of the grid empty. */
void sah_bins_clear(sah_bins *g, uint32_t nb);

/* Adds src's bins into dst. */
void sah_bins_merge(sah_bins *dst, const sah_bins *src, uint32_t nb);

/*
 * The split of lowest cost A_L * N_L + A_R * N_R over every bin boundary
 * of the three axes (ties: lower axis, then lower boundary); candidate
 * boundaries separate two non-empty bins. Returns the axis (-1: none) and
 * sets *split (left = bins below it) and *cost.
 */
int sah_bins_choose(const sah_bins *g, const sah_grid *grid, uint32_t *split, float *cost);

/* The union of axis a's bins in [from, to). */
void sah_bins_box(const sah_bins *g, int a, uint32_t from, uint32_t to, bvhlab_aabb *box);

#endif /* BVHLAB_SAH_BINS_H */
