/*
 * The bins of binned SAH (sah_kernel.h): the grid that places centroids,
 * filling, merging, the cost sweep and the children's boxes. The binned
 * split (sah_binned.c) and sah_tasks' team splits both use these, so a
 * node's split is the same whoever bins it and in how many parts.
 */
#include <float.h>
#include <math.h>

#include "sah_bins.h"
#include "sah_bins_avx2.h"
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

void sah_bins_clear(sah_bins *g, uint32_t nb)
{
	const v4 ninf = v4_set1(-INFINITY);

	for (int a = 0; a < 3; a++) {
		for (uint32_t j = 0; j < nb; j++) {
			g->count[a][j] = 0;
			v4_store(g->box[a][j], ninf);
			v4_store(g->box[a][j] + 4, ninf);
		}
	}
}

/* The three bins of a primitive: sah_grid_bin's operations, lane-wise
 * (sah_bins_avx2.c repeats them with the same instructions). */
static inline void bins_of(const sah_grid *g, v4 lo, v4 hi, int32_t k[4])
{
	const v4 half = v4_set1(0.5f), top = v4_set1((float)(g->nb - 1)), zero = v4_set1(0);
	const v4 base = v4_set3(g->lo[0], g->lo[1], g->lo[2]);
	const v4 scale = v4_set3(g->scale[0], g->scale[1], g->scale[2]);
	v4 f = v4_mul(v4_sub(v4_mul(v4_add(lo, hi), half), base), scale);

	v4_trunc(v4_max(v4_min(f, top), zero), k);
}

static inline void bins_add(sah_bins *g, const int32_t k[4], v4 nlo, v4 hi)
{
	for (int a = 0; a < 3; a++) {
		float *box = g->box[a][k[a]];
		g->count[a][k[a]]++;
		v4_store(box, v4_max(v4_load(box), nlo));
		v4_store(box + 4, v4_max(v4_load(box + 4), hi));
	}
}

static inline void add_prim(sah_bins *bins, const sah_grid *g, const sah_prim *p)
{
	int32_t k[4];
	v4 lo = v4_load3(p->lo), hi = v4_load3(p->hi);

	bins_of(g, lo, hi, k);
	bins_add(bins, k, v4_neg(lo), hi);
}

static void fill_sse(sah_bins *out, const sah_grid *g, const sah_prim *prims, uint32_t begin,
                     uint32_t end)
{
	sah_bins odd;

	sah_bins_clear(out, g->nb);
	sah_bins_clear(&odd, g->nb);
#define ADD_SSE(bins, i) add_prim(bins, g, &prims[i])
	SAH_BINS_EVEN_ODD(out, &odd, begin, end, ADD_SSE);
#undef ADD_SSE
	sah_bins_merge(out, &odd, g->nb);
}

void sah_bins_fill(sah_bins *out, const sah_grid *g, const sah_prim *prims, uint32_t begin,
                   uint32_t end, int simd)
{
#ifdef SAH_HAVE_AVX2
	if (simd == SAH_SIMD_AVX2) {
		sah_bins_fill_avx2(out, g, prims, begin, end);
		return;
	}
#endif
	(void)simd;
	fill_sse(out, g, prims, begin, end);
}

void sah_bins_merge(sah_bins *dst, const sah_bins *src, uint32_t nb)
{
	for (int a = 0; a < 3; a++) {
		for (uint32_t j = 0; j < nb; j++) {
			float *d = dst->box[a][j];
			const float *s = src->box[a][j];
			dst->count[a][j] += src->count[a][j];
			v4_store(d, v4_max(v4_load(d), v4_load(s)));
			v4_store(d + 4, v4_max(v4_load(d + 4), v4_load(s + 4)));
		}
	}
}

/* Grows the union (nlo, hi) by a bin. */
static inline void grow(v4 *nlo, v4 *hi, const float *box)
{
	*nlo = v4_max(*nlo, v4_load(box));
	*hi = v4_max(*hi, v4_load(box + 4));
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
	v4 nlo = v4_set1(-INFINITY), hi = nlo;

	for (uint32_t j = 0; j < nb; j++)
		if (g->count[a][j])
			used[m++] = j;
	for (uint32_t j = m - 1; j > 0 && m > 0; j--) {
		grow(&nlo, &hi, g->box[a][used[j]]);
		n += g->count[a][used[j]];
		right[j] = v4_half_area(v4_neg(nlo), hi) * (float)n;
	}
	nlo = hi = v4_set1(-INFINITY);
	n = 0;
	for (uint32_t j = 0; j + 1 < m; j++) {
		uint32_t k = used[j];
		grow(&nlo, &hi, g->box[a][k]);
		n += g->count[a][k];
		float cost = v4_half_area(v4_neg(nlo), hi) * (float)n + right[j + 1];
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
	v4 nlo = v4_set1(-INFINITY), hi = nlo;

	/* Empty bins hold the empty union, which max leaves unchanged. */
	for (uint32_t j = from; j < to; j++)
		grow(&nlo, &hi, g->box[a][j]);
	v4_store3(box->lo, v4_neg(nlo));
	v4_store3(box->hi, hi);
}
