/*
 * Binned SAH: per node, `bins` equal bins per axis over the node's centroid
 * bounds; the cost is evaluated at every bin boundary of all three axes and
 * the range of prims[0] is partitioned in place. All bin storage is on the
 * stack of the call, so concurrent jobs share nothing.
 */
#include <float.h>
#include <string.h>

#include "sah_internal.h"
#include "sah_simd.h"

typedef struct binning {
	uint32_t nb;                          /* bins per axis */
	float lo[3];                          /* centroid bounds' minimum */
	float scale[3];                       /* bins per unit length; 0: axis unusable */
	uint64_t full[3][SAH_MAX_BINS / 64]; /* bit k: bin k is not empty */
	uint32_t count[3][SAH_MAX_BINS];      /* primitives per bin, where full */
	float blo[3][SAH_MAX_BINS][4];        /* their boxes' union, where full */
	float bhi[3][SAH_MAX_BINS][4];
	uint32_t used[SAH_MAX_BINS];          /* one axis' non-empty bins, ascending */
	float right[SAH_MAX_BINS];            /* A_R * N_R from used[j] to the last bin */
} binning;

static void setup(binning *g, const sah_job *job, uint32_t nb)
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
		memset(g->full[a], 0, sizeof(g->full[a]));
	}
}

/* A centroid's bin, for one axis. fill() computes the same for three
 * axes at once, with the same operations: the two must agree exactly. */
static inline uint32_t bin_of(const binning *g, int a, const sah_prim *p)
{
	float f = (0.5f * (p->lo[a] + p->hi[a]) - g->lo[a]) * g->scale[a];
	f = minf(f, (float)(g->nb - 1));
	return f > 0 ? (uint32_t)f : 0;
}

/* Bins are set up on first use: small nodes touch few of them, and only
 * the non-empty ones are visited later. */
static inline void bin_add(binning *g, int a, int32_t k, v4 lo, v4 hi)
{
	float *bl = g->blo[a][k], *bh = g->bhi[a][k];
	uint64_t *word = &g->full[a][k >> 6], bit = (uint64_t)1 << (k & 63);

	if (*word & bit) {
		g->count[a][k]++;
		v4_store(bl, v4_min(v4_load(bl), lo));
		v4_store(bh, v4_max(v4_load(bh), hi));
	} else {
		*word |= bit;
		g->count[a][k] = 1;
		v4_store(bl, lo);
		v4_store(bh, hi);
	}
}

/* The non-empty bins of axis a in [from, to), ascending, into list. */
static uint32_t full_bins(const binning *g, int a, uint32_t from, uint32_t to,
                          uint32_t *list)
{
	uint32_t m = 0;

	for (uint32_t w = 0; w < (g->nb + 63) / 64; w++) {
		for (uint64_t bits = g->full[a][w]; bits; bits &= bits - 1) {
			uint32_t k = 64 * w + (uint32_t)__builtin_ctzll(bits);
			if (k >= from && k < to)
				list[m++] = k;
		}
	}
	return m;
}

/*
 * Large nodes: every bin starts as the empty union (+inf, -inf; count 0),
 * so the loop below needs no first-use branch; min(+inf, x) and
 * max(-inf, x) are x exactly, so the bins equal fill()'s bit for bit. The
 * full bits are set from the counts afterwards.
 */
/* A second set of bins for the odd primitives: neighbours in memory are
 * neighbours in space, so consecutive primitives mostly hit the same bins,
 * and with one set each update waits for the store of the one before. */
typedef struct bins2 {
	uint32_t count[3][64];
	float blo[3][64][4];
	float bhi[3][64][4];
} bins2;

static inline void add_dense(uint32_t *count, float *bl, float *bh, v4 lo, v4 hi)
{
	(*count)++;
	v4_store(bl, v4_min(v4_load(bl), lo));
	v4_store(bh, v4_max(v4_load(bh), hi));
}

static void fill_dense(binning *g, const sah_prim *prims, uint32_t begin, uint32_t end)
{
	const v4 half = v4_set1(0.5f), top = v4_set1((float)(g->nb - 1)), zero = v4_set1(0);
	const v4 base = v4_set3(g->lo[0], g->lo[1], g->lo[2]);
	const v4 scale = v4_set3(g->scale[0], g->scale[1], g->scale[2]);
	const v4 inf = v4_set1(INFINITY), ninf = v4_set1(-INFINITY);
	bins2 h;
	int32_t k[4], q[4];

	for (int a = 0; a < 3; a++) {
		for (uint32_t j = 0; j < g->nb; j++) {
			g->count[a][j] = h.count[a][j] = 0;
			v4_store(g->blo[a][j], inf);
			v4_store(g->bhi[a][j], ninf);
			v4_store(h.blo[a][j], inf);
			v4_store(h.bhi[a][j], ninf);
		}
	}
	uint32_t i = begin;
	for (; i + 1 < end; i += 2) {
		v4 lo = v4_load3(prims[i].lo), hi = v4_load3(prims[i].hi);
		v4 lo2 = v4_load3(prims[i + 1].lo), hi2 = v4_load3(prims[i + 1].hi);
		v4 f = v4_mul(v4_sub(v4_mul(v4_add(lo, hi), half), base), scale);
		v4 f2 = v4_mul(v4_sub(v4_mul(v4_add(lo2, hi2), half), base), scale);
		v4_trunc(v4_max(v4_min(f, top), zero), k);
		v4_trunc(v4_max(v4_min(f2, top), zero), q);
		for (int a = 0; a < 3; a++) {
			add_dense(&g->count[a][k[a]], g->blo[a][k[a]], g->bhi[a][k[a]], lo, hi);
			add_dense(&h.count[a][q[a]], h.blo[a][q[a]], h.bhi[a][q[a]], lo2, hi2);
		}
	}
	for (; i < end; i++) {
		v4 lo = v4_load3(prims[i].lo), hi = v4_load3(prims[i].hi);
		v4 f = v4_mul(v4_sub(v4_mul(v4_add(lo, hi), half), base), scale);
		v4_trunc(v4_max(v4_min(f, top), zero), k);
		for (int a = 0; a < 3; a++)
			add_dense(&g->count[a][k[a]], g->blo[a][k[a]], g->bhi[a][k[a]], lo, hi);
	}
	for (int a = 0; a < 3; a++) {
		for (uint32_t j = 0; j < g->nb; j++) {
			g->count[a][j] += h.count[a][j];
			v4_store(g->blo[a][j], v4_min(v4_load(g->blo[a][j]), v4_load(h.blo[a][j])));
			v4_store(g->bhi[a][j], v4_max(v4_load(g->bhi[a][j]), v4_load(h.bhi[a][j])));
			g->full[a][j >> 6] |= (uint64_t)(g->count[a][j] != 0) << (j & 63);
		}
	}
}

static void fill(binning *g, const sah_prim *prims, uint32_t begin, uint32_t end)
{
	const v4 half = v4_set1(0.5f), top = v4_set1((float)(g->nb - 1)), zero = v4_set1(0);
	const v4 base = v4_set3(g->lo[0], g->lo[1], g->lo[2]);
	const v4 scale = v4_set3(g->scale[0], g->scale[1], g->scale[2]);
	int32_t k[4];

	for (uint32_t i = begin; i < end; i++) {
		v4 lo = v4_load3(prims[i].lo), hi = v4_load3(prims[i].hi);
		v4 f = v4_mul(v4_sub(v4_mul(v4_add(lo, hi), half), base), scale);
		v4_trunc(v4_max(v4_min(f, top), zero), k);
		bin_add(g, 0, k[0], lo, hi);
		bin_add(g, 1, k[1], lo, hi);
		bin_add(g, 2, k[2], lo, hi);
	}
}

/*
 * Lowest weighted area sum of one axis' boundaries below `best`, with the
 * first boundary reaching it in *split. Only boundaries right after a
 * non-empty bin are evaluated: any other one has the same sets as the
 * boundary before it, which already won the tie.
 */
static float evaluate_axis(binning *g, int a, float best, uint32_t *split)
{
	const uint32_t *count = g->count[a], *used = g->used;
	uint32_t m = full_bins(g, a, 0, g->nb, g->used), n = 0;
	v4 lo = v4_set1(INFINITY), hi = v4_set1(-INFINITY);

	for (uint32_t j = m - 1; j > 0; j--) {
		uint32_t k = used[j];
		lo = v4_min(lo, v4_load(g->blo[a][k]));
		hi = v4_max(hi, v4_load(g->bhi[a][k]));
		n += count[k];
		g->right[j] = v4_half_area(lo, hi) * (float)n;
	}
	lo = v4_set1(INFINITY);
	hi = v4_set1(-INFINITY);
	n = 0;
	for (uint32_t j = 0; j + 1 < m; j++) {
		uint32_t k = used[j];
		lo = v4_min(lo, v4_load(g->blo[a][k]));
		hi = v4_max(hi, v4_load(g->bhi[a][k]));
		n += count[k];
		float cost = v4_half_area(lo, hi) * (float)n + g->right[j + 1];
		if (cost < best) {
			best = cost;
			*split = k + 1;
		}
	}
	return best;
}

/* Branch-free in-place partition by bin (every element swapped with the
 * left boundary); returns the first right position. The children's
 * centroid bounds are gathered on the way (cbox[0] left, cbox[1] right):
 * they only place bins, never reach a node, so the order they are taken
 * in (which could only flip the sign of a zero) cannot change the tree. */
static uint32_t partition(const binning *g, sah_prim *prims, uint32_t begin, uint32_t end,
                          int a, uint32_t split, bvhlab_aabb cbox[2])
{
	const v4 half = v4_set1(0.5f);
	v4 clo[2] = { v4_set1(INFINITY), v4_set1(INFINITY) };
	v4 chi[2] = { v4_set1(-INFINITY), v4_set1(-INFINITY) };
	uint32_t l = begin;

	for (uint32_t i = begin; i < end; i++) {
		sah_prim p = prims[i];
		bool left = bin_of(g, a, &p) < split;
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

static void bins_box(binning *g, int a, uint32_t from, uint32_t to, bvhlab_aabb *box)
{
	uint32_t m = full_bins(g, a, from, to, g->used);
	v4 lo = v4_set1(INFINITY), hi = v4_set1(-INFINITY);

	for (uint32_t j = 0; j < m; j++) {
		lo = v4_min(lo, v4_load(g->blo[a][g->used[j]]));
		hi = v4_max(hi, v4_load(g->bhi[a][g->used[j]]));
	}
	v4_store3(box->lo, lo);
	v4_store3(box->hi, hi);
}

/* A median split child's centroid bounds and, when want_box, its box. */
static void range_bounds(const sah_prim *prims, sah_job *c, bool want_box)
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
	if (want_box) {
		v4_store3(c->box.lo, lo);
		v4_store3(c->box.hi, hi);
	}
}

unsigned sah_binned_split(sah_builder *b, const sah_job *job, sah_job child[2])
{
	binning g;
	float best = INFINITY;
	uint32_t split = 0, mid;
	int axis = -1;

	setup(&g, job, b->opt.bins);
	/* Dense bins pay 3 * bins initialisations to save a branch per add. */
	if (job->end - job->begin >= 8 * g.nb && g.nb <= 64)
		fill_dense(&g, b->prims[0], job->begin, job->end);
	else
		fill(&g, b->prims[0], job->begin, job->end);
	for (int a = 0; a < 3; a++) {
		float cost = g.scale[a] > 0 ? evaluate_axis(&g, a, best, &split) : best;
		if (cost < best) {
			best = cost;
			axis = a;
		}
	}
	if (sah_prefer_leaf(b, job, axis >= 0, best)) {
		sah_write_leaf(b, job);
		return 0;
	}
	/* No candidate: every centroid coincides; split the current order. */
	if (axis < 0) {
		sah_write_inner(b, job, job->begin + (job->end - job->begin) / 2, child);
		range_bounds(b->prims[0], &child[0], true);
		range_bounds(b->prims[0], &child[1], true);
		return 2;
	}
	bvhlab_aabb cbox[2];
	mid = partition(&g, b->prims[0], job->begin, job->end, axis, split, cbox);
	sah_write_inner(b, job, mid, child);
	bins_box(&g, axis, 0, split, &child[0].box);
	bins_box(&g, axis, split, g.nb, &child[1].box);
	child[0].cbox = cbox[0];
	child[1].cbox = cbox[1];
	return 2;
}
