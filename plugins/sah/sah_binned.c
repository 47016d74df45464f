/*
 * Binned SAH: per node, `bins` equal bins per axis over the node's centroid
 * bounds (sah_bins.c); the cost is evaluated at every bin boundary of all
 * three axes and the node's range is partitioned into the builder's other
 * array (sah_job.alt). All bin storage is on the stack of the call, so
 * concurrent jobs share nothing.
 *
 * With option sample (sah_tasks), a node of more than 4 * sample
 * primitives bins only `sample` of them, evenly spaced in its range: the
 * bins then choose the plane but know neither the children's counts nor
 * their boxes, so the scatter finds both (left side from the front, right
 * side from the back, which reverses its order: still a function of the
 * range alone, so the tree stays the same for every thread count).
 */
#include <math.h>

#include "sah_bins.h"
#include "sah_nodes.h"
#include "sah_split.h"
#include "sah_simd.h"

/* The primitives of axis a's bins below split. */
static uint32_t left_count(const sah_bins *g, int a, uint32_t split)
{
	uint32_t n = 0;

	for (uint32_t k = 0; k < split; k++)
		n += g->count[a][k];
	return n;
}

/*
 * Stable partition by bin from src into dst, the builder's other array:
 * the bins give the left count, so every record's place is known when it
 * is read (an arithmetic select, no branch to mispredict, no iteration
 * waiting for the store of the one before), and no pass copies back. The
 * children's centroid bounds are gathered on the way (cbox[0] left,
 * cbox[1] right). Returns the first right position.
 */
static uint32_t scatter(const sah_grid *g, const sah_prim *src, sah_prim *dst,
                        const sah_job *job, int a, uint32_t split, uint32_t left,
                        bvhlab_aabb cbox[2])
{
	const v4 half = v4_set1(0.5f);
	v4 clo[2] = { v4_set1(INFINITY), v4_set1(INFINITY) };
	v4 chi[2] = { v4_set1(-INFINITY), v4_set1(-INFINITY) };
	uint32_t l = job->begin, mid = job->begin + left, r = mid;

	for (uint32_t i = job->begin; i < job->end; i++) {
		uint32_t right = sah_grid_bin(g, a, &src[i]) >= split, mask = 0u - right;
		v4 cen = v4_mul(v4_add(v4_load3(src[i].lo), v4_load3(src[i].hi)), half);
		dst[(r & mask) | (l & ~mask)] = src[i];
		r += right;
		l += right ^ 1;
		clo[right] = v4_min(clo[right], cen);
		chi[right] = v4_max(chi[right], cen);
	}
	for (int c = 0; c < 2; c++) {
		v4_store3(cbox[c].lo, clo[c]);
		v4_store3(cbox[c].hi, chi[c]);
	}
	return mid;
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

/*
 * scatter's counterpart for sampled bins: the same plane, but both sides
 * grow from the range's ends and each child's box and centroid bounds are
 * gathered on the way, as the sampled bins hold neither. Returns the first
 * right position.
 */
static uint32_t scatter_both(const sah_grid *g, const sah_prim *src, sah_prim *dst,
                             const sah_job *job, int a, uint32_t split, sah_job child[2])
{
	const v4 half = v4_set1(0.5f);
	v4 clo[2] = { v4_set1(INFINITY), v4_set1(INFINITY) };
	v4 chi[2] = { v4_set1(-INFINITY), v4_set1(-INFINITY) };
	v4 blo[2] = { clo[0], clo[0] }, bhi[2] = { chi[0], chi[0] };
	uint32_t l = job->begin, r = job->end;

	for (uint32_t i = job->begin; i < job->end; i++) {
		uint32_t right = sah_grid_bin(g, a, &src[i]) >= split, mask = 0u - right;
		v4 lo = v4_load3(src[i].lo), hi = v4_load3(src[i].hi);
		v4 cen = v4_mul(v4_add(lo, hi), half);
		dst[((r - 1) & mask) | (l & ~mask)] = src[i];
		r -= right;
		l += right ^ 1;
		clo[right] = v4_min(clo[right], cen);
		chi[right] = v4_max(chi[right], cen);
		blo[right] = v4_min(blo[right], lo);
		bhi[right] = v4_max(bhi[right], hi);
	}
	for (int c = 0; c < 2; c++) {
		v4_store3(child[c].cbox.lo, clo[c]);
		v4_store3(child[c].cbox.hi, chi[c]);
		v4_store3(child[c].box.lo, blo[c]);
		v4_store3(child[c].box.hi, bhi[c]);
	}
	return l;
}

/* The bins of `count` primitives evenly spaced over the job's range. */
static void fill_sample(sah_bins *bins, const sah_grid *grid, const sah_prim *src,
                        const sah_job *job, uint32_t count, int simd)
{
	sah_prim pick[SAH_MAX_SAMPLE];
	uint64_t n = job->end - job->begin;

	for (uint32_t k = 0; k < count; k++)
		pick[k] = src[job->begin + (uint32_t)((uint64_t)k * n / count)];
	sah_bins_fill(bins, grid, pick, 0, count, simd);
}

/* A split decided on a sample (the sample's plane separates two of the
 * node's primitives, so neither child is empty). */
static unsigned sampled_split(sah_builder *b, const sah_job *job, sah_job child[2])
{
	sah_grid grid;
	sah_bins bins;
	sah_job kids[2];
	float best;
	uint32_t split = 0;
	const sah_prim *src = sah_job_prims(b, job);

	sah_grid_init(&grid, job, b->opt.bins);
	fill_sample(&bins, &grid, src, job, b->opt.sample, b->opt.simd);
	int axis = sah_bins_choose(&bins, &grid, &split, &best);
	if (axis < 0) {
		sah_write_inner(b, job, job->begin + (job->end - job->begin) / 2, child);
		range_bounds(src, &child[0]);
		range_bounds(src, &child[1]);
		return 2;
	}
	uint32_t mid = scatter_both(&grid, src, job->alt ? b->prims[0] : b->alt, job, axis,
	                            split, kids);
	sah_write_inner(b, job, mid, child);
	for (int c = 0; c < 2; c++) {
		child[c].alt = !job->alt;
		child[c].box = kids[c].box;
		child[c].cbox = kids[c].cbox;
	}
	return 2;
}

unsigned sah_binned_split(sah_builder *b, const sah_job *job, sah_job child[2])
{
	sah_grid grid;
	sah_bins bins;
	float best;
	uint32_t split = 0, mid;

	if (b->opt.sample && job->end - job->begin > 4 * b->opt.sample)
		return sampled_split(b, job, child);
	sah_grid_init(&grid, job, b->opt.bins);
	const sah_prim *src = sah_job_prims(b, job);

	sah_bins_fill(&bins, &grid, src, job->begin, job->end, b->opt.simd);
	int axis = sah_bins_choose(&bins, &grid, &split, &best);
	if (sah_prefer_leaf(b, job, axis >= 0, best)) {
		sah_write_leaf(b, job);
		return 0;
	}
	/* No candidate: every centroid coincides; split the current order. */
	if (axis < 0) {
		sah_write_inner(b, job, job->begin + (job->end - job->begin) / 2, child);
		range_bounds(src, &child[0]);
		range_bounds(src, &child[1]);
		return 2;
	}
	bvhlab_aabb cbox[2];
	mid = scatter(&grid, src, job->alt ? b->prims[0] : b->alt, job, axis, split,
	              left_count(&bins, axis, split), cbox);
	sah_write_inner(b, job, mid, child);
	child[0].alt = child[1].alt = !job->alt;
	sah_bins_box(&bins, axis, 0, split, &child[0].box);
	sah_bins_box(&bins, axis, split, grid.nb, &child[1].box);
	child[0].cbox = cbox[0];
	child[1].cbox = cbox[1];
	return 2;
}
