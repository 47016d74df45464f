/*
 * lbvh phase 1: Morton codes of the centroids, a parallel LSD radix sort of
 * (code, primitive) pairs, and what the hierarchy needs from the order.
 *
 * The sort is stable and starts from primitive order, so pairs with equal
 * codes end up ordered by primitive id: the (code, id) order Karras's tie
 * rule needs, without widening the keys. Every thread histograms its chunk
 * of the current pairs, then scatters that chunk to the offsets its
 * histogram gets among all chunks' histograms, which keeps each pass stable
 * and the result independent of the thread count. A digit that is the same
 * in every code (the upper 34 bits of 30-bit codes, any digit of
 * coincident centroids) cannot change the order and its pass is skipped.
 *
 * The sort is memory bound, so the pairs shrink as soon as they can: an
 * LSD pass never looks at the digits below its own again, and once the
 * code bits still to sort plus the primitive id fit in 64 bits, the pair
 * travels packed as one word, (code >> base) << id_bits | id. The last pass
 * writes the ids into output->prim_index and keeps its words, the sorted
 * keys that Karras compares (see common_prefix()).
 */
#include <string.h>

#include "lbvh.h"

#define MAX_PASSES ((64 + RADIX_BITS - 1) / RADIX_BITS)
#define DIGIT(word, shift) ((uint32_t)((word) >> (shift)) & (RADIX - 1))

enum src_form { FROM_CODES, FROM_WIDE, FROM_PACKED }; /* FROM_CODES: ids implicit */
enum dst_form { TO_WIDE, TO_PACKED, TO_FINAL };

/* One pass: where its pairs come from and go, and in which form. */
struct pass {
	unsigned shift;        /* digit position in the code */
	unsigned word_shift;   /* digit position in the source words */
	int src, dst;          /* enum src_form, enum dst_form */
	const uint64_t *ks;    /* source words */
	const uint32_t *vs;    /* source ids, FROM_WIDE */
	uint64_t *kd;          /* destination words */
	uint32_t *vd;          /* destination ids, TO_WIDE and TO_FINAL */
};

/* Packing: code bits from `base` up, shifted above `id_bits` of id; the
 * sorted words have this form too (both 0 when they are the codes). */
struct packing {
	unsigned base, id_bits;
	const uint64_t *sorted; /* the last pass's words, in sorted order */
};

/* The bits of x spread out to every third bit, 21 bits into 63. */
static inline uint64_t spread21(uint64_t x)
{
	x &= 0x1fffffu;
	x = (x | x << 32) & 0x001f00000000ffffull;
	x = (x | x << 16) & 0x001f0000ff0000ffull;
	x = (x | x << 8) & 0x100f00f00f00f00full;
	x = (x | x << 4) & 0x10c30c30c30c30c3ull;
	x = (x | x << 2) & 0x1249249249249249ull;
	return x;
}

#define SPREAD_BITS 11

/* Centroid bounds to cells, per axis (a flat axis puts every centroid in
 * cell 0), and spread21 by table, 11 bits at a time: two loads instead of
 * fifteen operations per axis, from 16 KiB that stay in L1. */
struct quantiser {
	float lo[3], scale[3], top;
	uint64_t spread[1u << SPREAD_BITS];
};

static void quantiser_init(struct quantiser *q, const lbvh *b)
{
	const bvhlab_aabb *cb = &b->in->centroid_bounds;
	unsigned axis_bits = b->bits / 3;

	q->top = (float)((1u << axis_bits) - 1);
	for (int k = 0; k < 3; k++) {
		float extent = cb->hi[k] - cb->lo[k];
		float s = (float)(1u << axis_bits) / extent;
		q->lo[k] = cb->lo[k];
		q->scale[k] = extent > 0 && s < 1e30f ? s : 0.0f;
	}
	for (uint32_t v = 0; v < (1u << SPREAD_BITS); v++)
		q->spread[v] = spread21(v);
}

/* Clamped because c - lo can round up to the top edge; a NaN goes to
 * cell 0 rather than into an undefined conversion. Cells fit in int32_t,
 * whose conversion is one instruction (uint64_t's is a branch). */
static inline uint64_t axis(const struct quantiser *q, const float *c, int k)
{
	float x = (c[k] - q->lo[k]) * q->scale[k];
	uint32_t cell;

	x = x > 0 ? x : 0;
	x = x < q->top ? x : q->top;
	cell = (uint32_t)(int32_t)x;
	return q->spread[cell & ((1u << SPREAD_BITS) - 1)] |
	       q->spread[cell >> SPREAD_BITS] << (3 * SPREAD_BITS);
}

static inline uint64_t morton(const struct quantiser *q, const float *c)
{
	return axis(q, c, 0) << 2 | axis(q, c, 1) << 1 | axis(q, c, 2);
}

static void codes(lbvh *b, unsigned t)
{
	struct quantiser q;
	uint64_t any = 0, all = ~0ull;
	uint32_t lo, hi;

	quantiser_init(&q, b);
	chunk(b, t, b->n, &lo, &hi);
	for (uint32_t i = lo; i < hi; i++) {
		uint64_t code = morton(&q, b->in->centroids + 3 * (size_t)i);
		b->codes[i] = code;
		any |= code;
		all &= code;
	}
	b->span[t][0] = any;
	b->span[t][1] = all;
}

/* Shifts of the digits that vary between codes. */
static unsigned varying_digits(const lbvh *b, unsigned shift[MAX_PASSES])
{
	uint64_t any = 0, all = ~0ull;
	unsigned count = 0;

	for (unsigned t = 0; t < b->threads; t++) {
		any |= b->span[t][0];
		all &= b->span[t][1];
	}
	for (unsigned s = 0; s < b->bits; s += RADIX_BITS)
		if (DIGIT(any ^ all, s))
			shift[count++] = s;
	return count;
}

/*
 * The passes: the first reads the codes, then they alternate between the
 * two buffers; the pairs are wide (keys[], vals[]) until the code bits left
 * to sort fit beside the id in one word, packed from then on. Every thread
 * makes the same plan from the same spans.
 */
static unsigned plan(const lbvh *b, struct pass pass[MAX_PASSES], struct packing *pk)
{
	unsigned shift[MAX_PASSES], count = varying_digits(b, shift);
	int form = FROM_CODES;

	pk->id_bits = 32 - (unsigned)__builtin_clz(b->n - 1);
	pk->base = 0;
	for (unsigned k = 0; k < count; k++) {
		struct pass *p = &pass[k];
		unsigned next = k + 1 < count ? shift[k + 1] : b->bits;

		*p = (struct pass){ .shift = shift[k], .word_shift = shift[k], .src = form,
		                    .ks = k ? b->keys[(k + 1) % 2] : b->codes,
		                    .vs = b->vals[(k + 1) % 2],
		                    .kd = b->keys[k % 2], .vd = b->vals[k % 2] };
		if (form == FROM_PACKED)
			p->word_shift = shift[k] - pk->base + pk->id_bits;
		if (k + 1 == count) {
			p->dst = TO_FINAL;
			p->vd = b->prim_index;
		} else if (form == FROM_PACKED || b->bits - next + pk->id_bits <= 64) {
			pk->base = form == FROM_PACKED ? pk->base : next;
			p->dst = TO_PACKED;
			form = FROM_PACKED;
		} else {
			p->dst = TO_WIDE;
			form = FROM_WIDE;
		}
	}
	if (form != FROM_PACKED)
		pk->id_bits = 0;
	pk->sorted = count ? b->keys[(count - 1) % 2] : b->codes;
	return count;
}

static void histogram(lbvh *b, unsigned t, const struct pass *p)
{
	uint32_t *h = b->hist[t], lo, hi;

	memset(h, 0, RADIX * sizeof(*h));
	chunk(b, t, b->n, &lo, &hi);
	for (uint32_t i = lo; i < hi; i++)
		h[DIGIT(p->ks[i], p->word_shift)]++;
}

/* Where thread t's pairs of each digit go: after every pair of a lower
 * digit, and after the same digit's pairs of lower chunks (stability). */
static void offsets(const lbvh *b, unsigned t, uint32_t off[RADIX])
{
	uint32_t sum = 0;

	for (unsigned d = 0; d < RADIX; d++)
		for (unsigned u = 0; u < b->threads; u++) {
			if (u == t)
				off[d] = sum;
			sum += b->hist[u][d];
		}
}

/* One scatter loop per (source, destination) form: the forms are
 * constants after inlining, so each loop moves only what it must. */
static inline __attribute__((always_inline)) void
scatter_as(const struct pass *p, const struct packing *pk, uint32_t lo, uint32_t hi,
           uint32_t *off, int src, int dst)
{
	const uint64_t id_mask = (1ull << pk->id_bits) - 1;

	for (uint32_t i = lo; i < hi; i++) {
		uint64_t w = p->ks[i];
		uint32_t at = off[DIGIT(w, p->word_shift)]++;
		uint32_t id = src == FROM_PACKED ? (uint32_t)(w & id_mask)
		              : src == FROM_WIDE ? p->vs[i] : i;

		if (dst == TO_PACKED)
			p->kd[at] = src == FROM_PACKED ? w : (w >> pk->base) << pk->id_bits | id;
		else
			p->kd[at] = w;
		if (dst != TO_PACKED)
			p->vd[at] = id;
	}
}

static void scatter(lbvh *b, unsigned t, const struct pass *p, const struct packing *pk)
{
	uint32_t off[RADIX], lo, hi;

	offsets(b, t, off);
	chunk(b, t, b->n, &lo, &hi);
#define FORMS(s, d) ((s) * 3 + (d))
#define CASE(s, d) \
	case FORMS(s, d): \
		scatter_as(p, pk, lo, hi, off, s, d); \
		break
	switch (FORMS(p->src, p->dst)) {
		CASE(FROM_CODES, TO_WIDE);
		CASE(FROM_CODES, TO_PACKED);
		CASE(FROM_CODES, TO_FINAL);
		CASE(FROM_WIDE, TO_WIDE);
		CASE(FROM_WIDE, TO_PACKED);
		CASE(FROM_WIDE, TO_FINAL);
		CASE(FROM_PACKED, TO_PACKED);
		CASE(FROM_PACKED, TO_FINAL);
	}
#undef CASE
#undef FORMS
}

static void sort_passes(lbvh *b, unsigned t, struct packing *pk)
{
	struct pass pass[MAX_PASSES];
	unsigned count = plan(b, pass, pk);
	uint32_t lo, hi;

	/* Every thread made the same plan; thread 0 publishes the sorted
	 * words' form, which the others read after the barriers below. */
	if (t == 0) {
		b->sorted.words = pk->sorted;
		b->sorted.base = pk->base;
		b->sorted.id_bits = pk->id_bits;
	}
	if (count == 0) { /* every code equal: already in order */
		chunk(b, t, b->n, &lo, &hi);
		for (uint32_t i = lo; i < hi; i++)
			b->prim_index[i] = i;
		team_sync(b);
	}
	for (unsigned k = 0; k < count; k++) {
		histogram(b, t, &pass[k]);
		team_sync(b);
		scatter(b, t, &pass[k], pk);
		team_sync(b);
	}
}

/* The common prefixes of sorted neighbours: all Karras needs besides the
 * sorted words. */
static void common_prefixes(lbvh *b, unsigned t)
{
	uint32_t lo, hi, n = b->n;

	chunk(b, t, n, &lo, &hi);
	for (uint32_t k = lo; k < hi && k + 1 < n; k++)
		b->lcp[k] = common_prefix(b, k, k + 1);
	if (t == 0) {
		memset(b->lcp - LCP_PAD, 0, LCP_PAD);
		memset(b->lcp + n - 1, 0, LCP_PAD + 1);
	}
}

void lbvh_sort(lbvh *b, unsigned t)
{
	struct packing pk;

	codes(b, t);
	team_sync(b);
	sort_passes(b, t, &pk);
	common_prefixes(b, t);
	team_sync(b);
}
