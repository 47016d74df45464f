/*
 * Exact SAH by sweeping: the primitives are presorted once per build along
 * each axis; every node sweeps its three sorted ranges and partitions them
 * stably, so the children's ranges stay sorted and no node sorts again.
 * O(N log N) for the whole build (N per tree level), and every pass streams
 * through the position-indexed arrays.
 */
#include <errno.h>
#include <stdlib.h>
#include <string.h>

#include "sah_box.h"
#include "sah_nodes.h"
#include "sah_split.h"
#include "sah_simd.h"

/* ---- presort: stable LSD radix sort on order-preserving float keys ---- */

#define RADIX_BITS 11
#define RADIX_SIZE (1u << RADIX_BITS)
#define RADIX_PASSES 3 /* 11 + 11 + 10 bits */

/* Flips negative floats entirely and the sign of positive ones, so unsigned
 * order equals float order. */
static inline uint32_t float_key(float f)
{
	uint32_t u;

	memcpy(&u, &f, sizeof(u));
	return u ^ ((uint32_t)-(int32_t)(u >> 31) | 0x80000000u);
}

static void histogram(const uint32_t *keys, uint32_t n, uint32_t (*hist)[RADIX_SIZE])
{
	memset(hist, 0, RADIX_PASSES * sizeof(*hist));
	for (uint32_t i = 0; i < n; i++) {
		uint32_t k = keys[i];
		for (unsigned p = 0; p < RADIX_PASSES; p++)
			hist[p][(k >> (p * RADIX_BITS)) & (RADIX_SIZE - 1)]++;
	}
}

static void scatter(const uint32_t *keys, const uint32_t *idx, uint32_t *dkeys, uint32_t *didx,
                    uint32_t n, unsigned shift, const uint32_t *count)
{
	uint32_t offset[RADIX_SIZE], sum = 0;

	for (uint32_t d = 0; d < RADIX_SIZE; d++) {
		offset[d] = sum;
		sum += count[d];
	}
	for (uint32_t i = 0; i < n; i++) {
		uint32_t pos = offset[(keys[i] >> shift) & (RADIX_SIZE - 1)]++;
		dkeys[pos] = keys[i];
		didx[pos] = idx[i];
	}
}

/* Sorts b->temp (the primitives in id order) by centroid along axis into
 * b->prims[axis]; scratch holds 4 * prim_count words. */
static void sort_axis(sah_builder *b, int axis, uint32_t *scratch)
{
	uint32_t n = b->prim_count, hist[RADIX_PASSES][RADIX_SIZE];
	uint32_t *sk = scratch, *dk = scratch + n, *si = scratch + 2 * (size_t)n;
	uint32_t *di = scratch + 3 * (size_t)n;
	const sah_prim *src = b->temp;
	sah_prim *dst = b->prims[axis];

	for (uint32_t i = 0; i < n; i++) {
		sk[i] = float_key(prim_centroid(&src[i], axis));
		si[i] = i;
	}
	histogram(sk, n, hist);
	for (unsigned p = 0; p < RADIX_PASSES; p++) {
		unsigned shift = p * RADIX_BITS;
		/* A digit shared by every key would leave the order unchanged. */
		if (hist[p][(sk[0] >> shift) & (RADIX_SIZE - 1)] == n)
			continue;
		scatter(sk, si, dk, di, n, shift, hist[p]);
		uint32_t *t = sk;
		sk = dk;
		dk = t;
		t = si;
		si = di;
		di = t;
	}
	for (uint32_t i = 0; i < n; i++)
		dst[i] = src[si[i]];
}

int sah_presort(sah_builder *b)
{
	uint32_t *scratch = malloc(4 * (size_t)b->prim_count * sizeof(uint32_t));

	if (!scratch)
		return -ENOMEM;
	for (int axis = 0; axis < 3; axis++)
		sort_axis(b, axis, scratch);
	free(scratch);
	return 0;
}

/* ---- per-node sweep ---------------------------------------------------- */

/*
 * Evaluates every position of one axis; returns the lowest weighted area
 * sum below `best` (else best) and its first position in *pos. Positions
 * between equal centroids are skipped: such a split is no plane.
 */
static float sweep_axis(sah_builder *b, const sah_job *job, int axis, float best,
                        uint32_t *pos)
{
	const sah_prim *prims = b->prims[axis];
	float *area = b->area;
	uint32_t begin = job->begin, end = job->end;
	v4 lo = v4_set1(INFINITY), hi = v4_set1(-INFINITY);

	for (uint32_t i = end - 1; i > begin; i--) {
		lo = v4_min(lo, v4_load3(prims[i].lo));
		hi = v4_max(hi, v4_load3(prims[i].hi));
		area[i] = v4_half_area(lo, hi);
	}
	lo = v4_set1(INFINITY);
	hi = v4_set1(-INFINITY);
	float next = prim_centroid(&prims[begin], axis);
	for (uint32_t i = begin; i + 1 < end; i++) {
		float cur = next;
		lo = v4_min(lo, v4_load3(prims[i].lo));
		hi = v4_max(hi, v4_load3(prims[i].hi));
		next = prim_centroid(&prims[i + 1], axis);
		if (!(cur < next))
			continue;
		float cost = v4_half_area(lo, hi) * (float)(i + 1 - begin) +
		             area[i + 1] * (float)(end - i - 1);
		if (cost < best) {
			best = cost;
			*pos = i + 1;
		}
	}
	return best;
}

/* Marks every primitive of the split axis' range left or right and
 * computes the children's boxes on the way. */
static void mark_sides(sah_builder *b, int axis, sah_job child[2])
{
	const sah_prim *prims = b->prims[axis];
	uint8_t *side = b->side;

	for (int s = 0; s < 2; s++) {
		v4 lo = v4_set1(INFINITY), hi = v4_set1(-INFINITY);
		for (uint32_t i = child[s].begin; i < child[s].end; i++) {
			side[prims[i].id] = (uint8_t)s;
			lo = v4_min(lo, v4_load3(prims[i].lo));
			hi = v4_max(hi, v4_load3(prims[i].hi));
		}
		v4_store3(child[s].box.lo, lo);
		v4_store3(child[s].box.hi, hi);
	}
}

/* Stable partition of one axis' range by the marks: into temp at the same
 * positions, then back. */
static void partition_axis(sah_builder *b, int axis, const sah_job *job, uint32_t mid)
{
	sah_prim *prims = b->prims[axis], *temp = b->temp;
	const uint8_t *side = b->side;
	uint32_t l = job->begin, r = mid;

	for (uint32_t i = job->begin; i < job->end; i++) {
		/* Arithmetic select: a branch on the side mispredicts half the
		 * time. */
		uint32_t s = side[prims[i].id], mask = 0u - s;
		temp[(r & mask) | (l & ~mask)] = prims[i];
		r += s;
		l += s ^ 1;
	}
	memcpy(prims + job->begin, temp + job->begin, (job->end - job->begin) * sizeof(sah_prim));
}

/* Sorted ranges give the children's centroid bounds at their ends. */
static void child_cbox(const sah_builder *b, sah_job *c)
{
	for (int k = 0; k < 3; k++) {
		c->cbox.lo[k] = prim_centroid(&b->prims[k][c->begin], k);
		c->cbox.hi[k] = prim_centroid(&b->prims[k][c->end - 1], k);
	}
}

unsigned sah_sweep_split(sah_builder *b, const sah_job *job, sah_job child[2])
{
	uint32_t n = job->end - job->begin, pos = 0;
	float best = INFINITY;
	int axis = -1;

	for (int a = 0; a < 3; a++) {
		const sah_prim *prims = b->prims[a];
		if (!(prim_centroid(&prims[job->begin], a) < prim_centroid(&prims[job->end - 1], a)))
			continue;
		float cost = sweep_axis(b, job, a, best, &pos);
		if (cost < best) {
			best = cost;
			axis = a;
		}
	}
	if (sah_prefer_leaf(b, job, axis >= 0, best)) {
		sah_write_leaf(b, job);
		return 0;
	}
	if (axis < 0) {
		axis = 0;
		pos = job->begin + n / 2;
	}
	sah_write_inner(b, job, pos, child);
	mark_sides(b, axis, child);
	for (int a = 0; a < 3; a++)
		if (a != axis)
			partition_axis(b, a, job, pos);
	child_cbox(b, &child[0]);
	child_cbox(b, &child[1]);
	return 2;
}
