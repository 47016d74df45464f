/*
 * Binned SAH: per node, `bins` equal bins per axis over the node's centroid
 * bounds (sah_bins.c); the cost is evaluated at every bin boundary of all
 * three axes and the range of prims[0] is partitioned in place. All bin
 * storage is on the stack of the call, so concurrent jobs share nothing.
 */
#include "sah_internal.h"
#include "sah_simd.h"

/* Branch-free in-place partition by bin (every element swapped with the
 * left boundary); returns the first right position. The children's
 * centroid bounds are gathered on the way (cbox[0] left, cbox[1] right):
 * they only place bins, never reach a node, so the order they are taken
 * in (which could only flip the sign of a zero) cannot change the tree. */
static uint32_t partition(const sah_grid *g, sah_prim *prims, uint32_t begin, uint32_t end,
                          int a, uint32_t split, bvhlab_aabb cbox[2])
{
	const v4 half = v4_set1(0.5f);
	v4 clo[2] = { v4_set1(INFINITY), v4_set1(INFINITY) };
	v4 chi[2] = { v4_set1(-INFINITY), v4_set1(-INFINITY) };
	uint32_t l = begin;

	for (uint32_t i = begin; i < end; i++) {
		sah_prim p = prims[i];
		bool left = sah_grid_bin(g, a, &p) < split;
		v4 cen = v4_mul(v4_add(v4_load3(p.lo), v4_load3(p.hi)), half);
		prims[i] = prims[l];
		prims[l] = p;
		l += left;
		clo[!left] = v4_min(clo[!left], cen);
		chi[!left] = v4_max(chi[!left], cen);
	}
	for (int c = 0; c < 2; c++) {
		v4_store3(cbox[c].lo, clo[c]);
		v4_store3(cbox[c].hi, chi[c]);
	}
	return l;
}

/* A median split child's centroid bounds and box. */
static void range_bounds(const sah_prim *prims, sah_job *c)
{
	const v4 half = v4_set1(0.5f);
	v4 lo = v4_set1(INFINITY), hi = v4_set1(-INFINITY);
	v4 clo = lo, chi = hi;

	for (uint32_t i = c->begin; i < c->end; i++) {
		v4 plo = v4_load3(prims[i].lo), phi = v4_load3(prims[i].hi);
		v4 cen = v4_mul(v4_add(plo, phi), half);
		lo = v4_min(lo, plo);
		hi = v4_max(hi, phi);
		clo = v4_min(clo, cen);
		chi = v4_max(chi, cen);
	}
	v4_store3(c->cbox.lo, clo);
	v4_store3(c->cbox.hi, chi);
	v4_store3(c->box.lo, lo);
	v4_store3(c->box.hi, hi);
}

unsigned sah_binned_split(sah_builder *b, const sah_job *job, sah_job child[2])
{
	sah_grid grid;
	sah_bins bins;
	float best;
	uint32_t split = 0, mid;

	sah_grid_init(&grid, job, b->opt.bins);
	sah_bins_fill(&bins, &grid, b->prims[0], job->begin, job->end, b->opt.simd);
	int axis = sah_bins_choose(&bins, &grid, &split, &best);
	if (sah_prefer_leaf(b, job, axis >= 0, best)) {
		sah_write_leaf(b, job);
		return 0;
	}
	/* No candidate: every centroid coincides; split the current order. */
	if (axis < 0) {
		sah_write_inner(b, job, job->begin + (job->end - job->begin) / 2, child);
		range_bounds(b->prims[0], &child[0]);
		range_bounds(b->prims[0], &child[1]);
		return 2;
	}
	bvhlab_aabb cbox[2];
	mid = partition(&grid, b->prims[0], job->begin, job->end, axis, split, cbox);
	sah_write_inner(b, job, mid, child);
	sah_bins_box(&bins, axis, 0, split, &child[0].box);
	sah_bins_box(&bins, axis, split, grid.nb, &child[1].box);
	child[0].cbox = cbox[0];
	child[1].cbox = cbox[1];
	return 2;
}
