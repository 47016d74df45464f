/*
 * Small subtrees: a job of at most SAH_SMALL_MAX primitives is built whole,
 * by the calling thread, with an exact SAH sweep over local copies of its
 * primitives. Most of a tree's nodes are small, and the per-node cost of
 * binning (bins to clear and scan for a handful of primitives) dominated a
 * binned build; here each small node costs a few linear passes over sorted
 * local index lists, like the sweep method but inside the L1 cache.
 *
 * The split rule is the kernel's (sah_kernel.h): every plane strictly
 * between two consecutive distinct centroids of each axis, cost
 * A_L * N_L + A_R * N_R, ties to the lower axis, then the lower position.
 * That is exact SAH, which both methods use below the threshold, so binned
 * trees get better there. Sets decide everything: the candidates, their
 * costs and the leaf rule depend on which primitives are in a node, not on
 * their order; only the object-median fallback (every centroid equal)
 * reads the order, and for it the x-order here equals the range's order.
 */
#include <string.h>

#include "sah_small.h"

typedef struct small {
	small_copy l;
	/* Local indices sorted by centroid along each axis (ties by index); a
	 * node's primitives occupy the same slots [lb, le) of all three. */
	uint8_t order[3][SAH_SMALL_MAX];
	uint8_t side[SAH_SMALL_MAX];      /* by local index: 0 left, 1 right */
	uint8_t tmp[SAH_SMALL_MAX];
} small;

static void load(small *s, const sah_prim *prims, uint32_t n)
{
	for (uint32_t k = 0; k < n; k++)
		small_load_prim(&s->l, &prims[s->l.begin + k], k);
}

#if defined(__SSE2__) && !defined(SAH_NO_SIMD)
/*
 * The identity sorted by (centroid, index), which is the stable sort by
 * centroid: each index is placed at its rank, the number of others that
 * come first. The ranges arrive sorted along one axis at most (a binned
 * parent partitions by bins), so an insertion sort does about n * n / 4
 * dependent moves per axis, with a mispredicted exit each; counting takes
 * n * n / 4 independent four-lane compares. Indices below k come first
 * when equal, those above when smaller: the lane masks pick <= or <.
 * Lanes past n hold +inf, which never comes first.
 */
static void sort_axis(small *s, int a, uint32_t n)
{
	float *c = s->l.cen[a];
	uint8_t *o = s->order[a];
	uint32_t n4 = (n + 3) & ~3u;
	static const int32_t below[4][4] = {
		{ 0, 0, 0, 0 }, { -1, 0, 0, 0 }, { -1, -1, 0, 0 }, { -1, -1, -1, 0 } };

	for (uint32_t k = n; k < n4; k++)
		c[k] = INFINITY;
	for (uint32_t k = 0; k < n; k++) {
		const __m128 ck = _mm_set1_ps(c[k]);
		const uint32_t at = k & ~3u;
		__m128i rank = _mm_setzero_si128();
		uint32_t j = 0;

		for (; j < at; j += 4)
			rank = _mm_sub_epi32(rank, _mm_castps_si128(_mm_cmple_ps(_mm_loadu_ps(c + j), ck)));
		__m128 cj = _mm_loadu_ps(c + j);
		__m128 mask = _mm_castsi128_ps(_mm_loadu_si128((const __m128i *)(const void *)below[k - at]));
		rank = _mm_sub_epi32(rank, _mm_castps_si128(_mm_or_ps(
		        _mm_and_ps(mask, _mm_cmple_ps(cj, ck)), _mm_andnot_ps(mask, _mm_cmplt_ps(cj, ck)))));
		for (j += 4; j < n4; j += 4)
			rank = _mm_sub_epi32(rank, _mm_castps_si128(_mm_cmplt_ps(_mm_loadu_ps(c + j), ck)));
		rank = _mm_add_epi32(rank, _mm_shuffle_epi32(rank, _MM_SHUFFLE(1, 0, 3, 2)));
		rank = _mm_add_epi32(rank, _mm_shuffle_epi32(rank, _MM_SHUFFLE(2, 3, 0, 1)));
		o[_mm_cvtsi128_si32(rank)] = (uint8_t)k;
	}
}
#else
/* Stable insertion sort of the identity by centroid (the plain C build). */
static void sort_axis(small *s, int a, uint32_t n)
{
	const float *c = s->l.cen[a];
	uint8_t *o = s->order[a];

	for (uint32_t k = 0; k < n; k++) {
		uint32_t j = k;
		float v = c[k];
		while (j > 0 && c[o[j - 1]] > v) {
			o[j] = o[j - 1];
			j--;
		}
		o[j] = (uint8_t)k;
	}
}
#endif

/* The sweep method's ranges are sorted already (x order is the range's
 * own); the other two axes are translated to local indices through the
 * kernel's by-id side marks, which only this job's primitives use now. */
static void take_presorted(small *s, uint32_t n)
{
	sah_builder *b = s->l.b;

	for (uint32_t k = 0; k < n; k++) {
		s->order[0][k] = (uint8_t)k;
		b->side[s->l.id[k]] = (uint8_t)k;
	}
	for (int a = 1; a < 3; a++)
		for (uint32_t k = 0; k < n; k++)
			s->order[a][k] = b->side[b->prims[a][s->l.begin + k].id];
}

/* Marks the sides by slot of the split axis and takes the children's boxes. */
static void mark(small *s, int axis, const small_node *c, uint32_t pos, small_node child[2])
{
	const uint8_t *o = s->order[axis];

	for (int h = 0; h < 2; h++) {
		uint32_t from = h ? pos : c->lb, to = h ? c->le : pos;
		v4 lo = v4_set1(INFINITY), hi = v4_set1(-INFINITY);
		for (uint32_t k = from; k < to; k++) {
			s->side[o[k]] = (uint8_t)h;
			lo = v4_min(lo, s->l.lo[o[k]]);
			hi = v4_max(hi, s->l.hi[o[k]]);
		}
		child[h].lb = from;
		child[h].le = to;
		v4_store3(child[h].box.lo, lo);
		v4_store3(child[h].box.hi, hi);
	}
}

/* Stable partition of the other axes' slots by side, so they stay sorted. */
static void partition(small *s, int axis, const small_node *c, uint32_t pos)
{
	for (int a = 0; a < 3; a++) {
		uint8_t *o = s->order[a];
		uint32_t l = c->lb, r = pos;
		if (a == axis)
			continue;
		for (uint32_t k = c->lb; k < c->le; k++) {
			uint32_t h = s->side[o[k]], mask = 0u - h;
			s->tmp[(r & mask) | (l & ~mask)] = o[k];
			r += h;
			l += h ^ 1;
		}
		memcpy(o + c->lb, s->tmp + c->lb, c->le - c->lb);
	}
}

/* A pair has one candidate at most: the same two sets on every axis
 * where the centroids differ, so the first such axis wins, at the cost the
 * sweep would give it (each area times 1; the sum commutes). About half
 * of all nodes are pairs. */
static float eval_pair(const small *s, const small_node *c, int *axis, uint32_t *pos)
{
	uint32_t i = s->order[0][c->lb], j = s->order[0][c->lb + 1];

	for (int a = 0; a < 3; a++) {
		if (s->l.cen[a][i] == s->l.cen[a][j])
			continue;
		*axis = a;
		*pos = c->lb + 1;
		return v4_half_area(s->l.lo[i], s->l.hi[i]) * 1.0f +
		       v4_half_area(s->l.lo[j], s->l.hi[j]) * 1.0f;
	}
	return INFINITY;
}

/* Decides one node; returns 2 and fills child[] when it splits. */
static unsigned split_node(void *state, const small_node *c, small_node child[2])
{
	small *s = state;
	uint32_t n = c->le - c->lb, pos = 0;
	float best = INFINITY;
	int axis = -1;

	if (n == 2)
		best = eval_pair(s, c, &axis, &pos);
	for (int a = 0; n > 2 && a < 3; a++) {
		const uint8_t *o = s->order[a];
		if (!(s->l.cen[a][o[c->lb]] < s->l.cen[a][o[c->le - 1]]))
			continue;
		float cost = small_sweep(&s->l, o, a, c->lb, c->le, best, &pos);
		if (cost < best) {
			best = cost;
			axis = a;
		}
	}
	if (n == 1 || sah_leaf_rule(&s->l.b->opt, n, &c->box, axis >= 0, best)) {
		small_write_leaf(&s->l, c, s->order[0]);
		return 0;
	}
	if (axis < 0) { /* every centroid coincides: split the x order's middle */
		axis = 0;
		pos = c->lb + n / 2;
	}
	mark(s, axis, c, pos, child);
	partition(s, axis, c, pos);
	return small_write_inner(&s->l, c, child);
}

void sah_small_subtree(sah_builder *b, const sah_job *job)
{
	small s;
	uint32_t n = job->end - job->begin;

	load(&s, small_begin(&s.l, b, job), n);
	if (b->opt.method == SAH_SWEEP) {
		take_presorted(&s, n);
	} else {
		for (int a = 0; a < 3; a++)
			sort_axis(&s, a, n);
	}
	small_walk(job, n, &s, split_node);
}
