/*
 * Binned SAH: per node, `bins` equal bins per axis over the node's centroid
 * bounds; the cost is evaluated at every bin boundary of all three axes and
 * the range of prims[0] is partitioned in place. All bin storage is on the
 * stack of the call, so concurrent jobs share nothing. The bins' functions
 * (sah_kernel.h) serve sah_tasks' team splits too, so both choose alike.
 */
#include <float.h>
#include <string.h>

#include "sah_internal.h"
#include "sah_simd.h"

void sah_grid_init(sah_grid *g, const sah_job *job, uint32_t nb)
{
	g->nb = nb;
	for (int a = 0; a < 3; a++) {
		float extent = job->cbox.hi[a] - job->cbox.lo[a];
		float scale = (float)nb / extent;
		g->lo[a] = job->cbox.lo[a];
		/* A near-denormal extent overflows the scale: cap it. Should
		 * all centroids then land in one bin, the axis has no
		 * candidate, which the median fallback covers. */
		g->scale[a] = extent > 0 ? (scale <= FLT_MAX ? scale : FLT_MAX) : 0;
	}
}

static void bins_clear(sah_bins *g, uint32_t nb)
{
	const v4 inf = v4_set1(INFINITY), ninf = v4_set1(-INFINITY);

	for (int a = 0; a < 3; a++) {
		for (uint32_t j = 0; j < nb; j++) {
			g->count[a][j] = 0;
			v4_store(g->lo[a][j], inf);
			v4_store(g->hi[a][j], ninf);
		}
	}
}

/* The three bins of a primitive: sah_grid_bin's operations, lane-wise. */
static inline void bins_of(const sah_grid *g, v4 lo, v4 hi, int32_t k[4])
{
	const v4 half = v4_set1(0.5f), top = v4_set1((float)(g->nb - 1)), zero = v4_set1(0);
	const v4 base = v4_set3(g->lo[0], g->lo[1], g->lo[2]);
	const v4 scale = v4_set3(g->scale[0], g->scale[1], g->scale[2]);
	v4 f = v4_mul(v4_sub(v4_mul(v4_add(lo, hi), half), base), scale);

	v4_trunc(v4_max(v4_min(f, top), zero), k);
}

static inline void bins_add(sah_bins *g, const int32_t k[4], v4 lo, v4 hi)
{
	for (int a = 0; a < 3; a++) {
		float *bl = g->lo[a][k[a]], *bh = g->hi[a][k[a]];
		g->count[a][k[a]]++;
		v4_store(bl, v4_min(v4_load(bl), lo));
		v4_store(bh, v4_max(v4_load(bh), hi));
	}
}

/* Even and odd primitives go to two sets of bins, merged at the end:
 * neighbours in memory are neighbours in space, so consecutive primitives
 * mostly hit the same bins, and with one set each update would wait for
 * the store of the one before. */
void sah_bins_fill(sah_bins *out, const sah_grid *g, const sah_prim *prims, uint32_t begin,
                   uint32_t end)
{
	sah_bins odd;
	int32_t k[4], q[4];
	uint32_t i = begin;

	bins_clear(out, g->nb);
	bins_clear(&odd, g->nb);
	for (; i + 1 < end; i += 2) {
		v4 lo = v4_load3(prims[i].lo), hi = v4_load3(prims[i].hi);
		v4 lo2 = v4_load3(prims[i + 1].lo), hi2 = v4_load3(prims[i + 1].hi);
		bins_of(g, lo, hi, k);
		bins_of(g, lo2, hi2, q);
		bins_add(out, k, lo, hi);
		bins_add(&odd, q, lo2, hi2);
	}
	if (i < end) {
		v4 lo = v4_load3(prims[i].lo), hi = v4_load3(prims[i].hi);
		bins_of(g, lo, hi, k);
		bins_add(out, k, lo, hi);
	}
	sah_bins_merge(out, &odd, g->nb);
}

void sah_bins_merge(sah_bins *dst, const sah_bins *src, uint32_t nb)
{
	for (int a = 0; a < 3; a++) {
		for (uint32_t j = 0; j < nb; j++) {
			dst->count[a][j] += src->count[a][j];
			v4_store(dst->lo[a][j], v4_min(v4_load(dst->lo[a][j]), v4_load(src->lo[a][j])));
			v4_store(dst->hi[a][j], v4_max(v4_load(dst->hi[a][j]), v4_load(src->hi[a][j])));
		}
	}
}

/*
 * Lowest weighted area sum of one axis' boundaries below `best`, with the
 * first boundary reaching it in *split. Only boundaries right after a
 * non-empty bin are evaluated: any other one has the same sets as the
 * boundary before it, which already won the tie.
 */
static float evaluate_axis(const sah_bins *g, uint32_t nb, int a, float best, uint32_t *split)
{
	uint32_t used[SAH_MAX_BINS], m = 0, n = 0;
	float right[SAH_MAX_BINS];
	v4 lo = v4_set1(INFINITY), hi = v4_set1(-INFINITY);

	for (uint32_t j = 0; j < nb; j++)
		if (g->count[a][j])
			used[m++] = j;
	for (uint32_t j = m - 1; j > 0 && m > 0; j--) {
		uint32_t k = used[j];
		lo = v4_min(lo, v4_load(g->lo[a][k]));
		hi = v4_max(hi, v4_load(g->hi[a][k]));
		n += g->count[a][k];
		right[j] = v4_half_area(lo, hi) * (float)n;
	}
	lo = v4_set1(INFINITY);
	hi = v4_set1(-INFINITY);
	n = 0;
	for (uint32_t j = 0; j + 1 < m; j++) {
		uint32_t k = used[j];
		lo = v4_min(lo, v4_load(g->lo[a][k]));
		hi = v4_max(hi, v4_load(g->hi[a][k]));
		n += g->count[a][k];
		float cost = v4_half_area(lo, hi) * (float)n + right[j + 1];
		if (cost < best) {
			best = cost;
			*split = k + 1;
		}
	}
	return best;
}

int sah_bins_choose(const sah_bins *g, const sah_grid *grid, uint32_t *split, float *cost)
{
	float best = INFINITY;
	int axis = -1;

	for (int a = 0; a < 3; a++) {
		float c = grid->scale[a] > 0 ? evaluate_axis(g, grid->nb, a, best, split) : best;
		if (c < best) {
			best = c;
			axis = a;
		}
	}
	*cost = best;
	return axis;
}

void sah_bins_box(const sah_bins *g, int a, uint32_t from, uint32_t to, bvhlab_aabb *box)
{
	v4 lo = v4_set1(INFINITY), hi = v4_set1(-INFINITY);

	/* Empty bins hold the empty union, which min/max leave unchanged. */
	for (uint32_t j = from; j < to; j++) {
		lo = v4_min(lo, v4_load(g->lo[a][j]));
		hi = v4_max(hi, v4_load(g->hi[a][j]));
	}
	v4_store3(box->lo, lo);
	v4_store3(box->hi, hi);
}

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
	sah_bins_fill(&bins, &grid, b->prims[0], job->begin, job->end);
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
