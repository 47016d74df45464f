/*
 * lbvh phase 1: Morton codes of the centroids, their sort into (code,
 * primitive) order, and what the hierarchy needs from that order.
 *
 * Each pair travels packed as one word, (code >> base) << id_bits | id:
 * the code's upper bits above the primitive id, so that ordering the words
 * orders the pairs, and a pass moves 8 bytes per pair. base is 0 when the
 * whole code fits beside the id (30-bit codes, few primitives), else the
 * lowest code bits are left out and only runs of words whose code bits are
 * equal are put in order by the full codes afterwards (fix_ties()); on a
 * real scene such runs are rare and short.
 *
 * The sort: one MSD pass on the codes' top TOP_BITS bits scatters the
 * words into buckets (thread t's share of each bucket after the shares of
 * lower chunks, so each bucket is in id order), then each bucket is
 * sorted on its own by LSD passes, while it sits in cache: one pass over
 * memory instead of up to eight, and the buckets are shared out among the
 * threads as they come free. Nothing depends on the thread count: the
 * result is the (code, id) order. The sorted words go to keys[0], the ids
 * to output->prim_index; Karras compares the words (common_prefix()).
 */
#include <string.h>

#include "lbvh.h"

/* Digits of the sort inside a bucket: 8 bits, so that the counts of all
 * of a bucket's digits stay in L1 and cost little to clear per bucket. */
#define LOCAL_BITS 8
#define LOCAL_RADIX (1u << LOCAL_BITS)
#define LOCAL_DIGITS (64 / LOCAL_BITS)
#define DIGIT(word, shift) ((uint32_t)((word) >> (shift)) & (LOCAL_RADIX - 1))
/* Buckets this small are insertion sorted: fewer moves than a pass. */
#define SMALL_RUN 24
/* Top digits handed out at a time in the bucket sort. */
#define BUCKET_BLOCK 16

/* The packed form: code bits from `base` up, above `id_bits` of id. */
struct packing {
	unsigned base, id_bits;
	unsigned top_shift; /* position of the top digit in the words */
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

static void packing_init(const lbvh *b, struct packing *pk)
{
	unsigned id_bits = 32 - (unsigned)__builtin_clz(b->n - 1);
	unsigned kept = b->bits < 64 - id_bits ? b->bits : 64 - id_bits;

	pk->id_bits = id_bits;
	pk->base = b->bits - kept;
	pk->top_shift = id_bits + kept - TOP_BITS;
}

static inline uint64_t pack(const struct packing *pk, uint64_t code, uint32_t id)
{
	return (code >> pk->base) << pk->id_bits | id;
}

/* Zeroes the arrival counters and flags of [lo, hi) (of n; n - 1 flags),
 * which are left from the build before when the scratch is in the output. */
static void clear_counters(lbvh *b, uint32_t lo, uint32_t hi)
{
	memset(b->visits + lo, 0, (hi - lo) * sizeof(*b->visits));
	if (b->node_flags)
		memset(b->node_flags + lo, 0, hi - lo);
}

/* The codes, by id, and how many of thread t's chunk each top digit has. */
static void codes(lbvh *b, unsigned t)
{
	struct quantiser q;
	uint32_t *h = b->hist[t], lo, hi;
	unsigned top = b->bits - TOP_BITS;

	quantiser_init(&q, b);
	memset(h, 0, TOP_RADIX * sizeof(*h));
	chunk(b, t, b->n, &lo, &hi);
	if (b->scratch_dirty) /* read from the bounds phase on */
		clear_counters(b, lo, hi);
	for (uint32_t i = lo; i < hi; i++) {
		uint64_t code = morton(&q, b->in->centroids + 3 * (size_t)i);
		b->codes[i] = code;
		h[code >> top]++;
	}
}

/* Where thread t's words of each top digit go: after every word of a
 * lower digit, and after the same digit's words of lower chunks. Thread
 * 0 also publishes where each bucket starts. */
static void offsets(lbvh *b, unsigned t, uint32_t off[TOP_RADIX])
{
	uint32_t sum = 0;

	for (unsigned d = 0; d < TOP_RADIX; d++) {
		if (t == 0)
			b->bucket[d] = sum;
		for (unsigned u = 0; u < b->threads; u++) {
			if (u == t)
				off[d] = sum;
			sum += b->hist[u][d];
		}
	}
	if (t == 0)
		b->bucket[TOP_RADIX] = sum;
}

static void scatter(lbvh *b, unsigned t, const struct packing *pk)
{
	uint32_t off[TOP_RADIX], lo, hi;
	uint64_t *dst = b->keys[0];

	offsets(b, t, off);
	chunk(b, t, b->n, &lo, &hi);
	for (uint32_t i = lo; i < hi; i++) {
		uint64_t w = pack(pk, b->codes[i], i);
		dst[off[w >> pk->top_shift]++] = w;
	}
}

static void insertion_sort(uint64_t *w, uint32_t m)
{
	for (uint32_t k = 1; k < m; k++) {
		uint64_t x = w[k];
		uint32_t j = k;

		for (; j > 0 && w[j - 1] > x; j--)
			w[j] = w[j - 1];
		w[j] = x;
	}
}

/* How many of the m words have each value of each digit from bit `from`
 * up; returns the bits that vary. Two sets of counts, one per half, so
 * that a digit that repeats (neighbours in id order are often neighbours
 * in space) does not chain every increment to the one before. */
static uint64_t count_digits(const uint64_t *w, uint32_t m, unsigned from, unsigned digits,
                             uint32_t count[][LOCAL_RADIX])
{
	uint32_t other[LOCAL_DIGITS][LOCAL_RADIX], half = m / 2;
	uint64_t any = 0, all = ~0ull;

	memset(count, 0, digits * sizeof(count[0]));
	memset(other, 0, digits * sizeof(other[0]));
	for (uint32_t k = 0; k < m - half; k++) {
		uint64_t x = w[k], y = w[m - 1 - k];

		any |= x | y;
		all &= x & y;
		for (unsigned d = 0; d < digits; d++) {
			count[d][DIGIT(x, from + d * LOCAL_BITS)]++;
			other[d][DIGIT(y, from + d * LOCAL_BITS)]++;
		}
	}
	if (m % 2) /* the middle word was counted twice */
		for (unsigned d = 0; d < digits; d++)
			other[d][DIGIT(w[half], from + d * LOCAL_BITS)]--;
	for (unsigned d = 0; d < digits; d++)
		for (unsigned v = 0; v < LOCAL_RADIX; v++)
			count[d][v] += other[d][v];
	return any ^ all;
}

/* One stable pass: the first half of the words goes forwards from the
 * start of each digit's range, the second half backwards from its end,
 * two independent chains of counter updates that meet in the middle. */
static void pass(const uint64_t *w, uint64_t *dst, uint32_t m, unsigned shift,
                 const uint32_t count[LOCAL_RADIX])
{
	uint32_t head[LOCAL_RADIX], tail[LOCAL_RADIX], sum = 0, half = m / 2;

	for (unsigned v = 0; v < LOCAL_RADIX; v++) {
		head[v] = sum;
		sum += count[v];
		tail[v] = sum;
	}
	for (uint32_t k = 0; k < half; k++) {
		uint64_t x = w[k], y = w[m - 1 - k];

		dst[head[DIGIT(x, shift)]++] = x;
		dst[--tail[DIGIT(y, shift)]] = y;
	}
	if (m % 2)
		dst[head[DIGIT(w[half], shift)]] = w[half];
}

/*
 * Stable LSD sort of m words on their bits [from, to), digits that are the
 * same in every word skipped; tmp is as large. The counts of every digit
 * are taken in one read. Returns where the sorted words are.
 */
static uint64_t *radix_sort(uint64_t *w, uint64_t *tmp, uint32_t m, unsigned from,
                            unsigned to)
{
	uint32_t count[LOCAL_DIGITS][LOCAL_RADIX];
	unsigned digits = (to - from + LOCAL_BITS - 1) / LOCAL_BITS;
	uint64_t varying = count_digits(w, m, from, digits, count);

	for (unsigned d = 0; d < digits; d++) {
		uint64_t *swap = w;

		if (!DIGIT(varying, from + d * LOCAL_BITS))
			continue;
		pass(w, tmp, m, from + d * LOCAL_BITS, count[d]);
		w = tmp;
		tmp = swap;
	}
	return w;
}

/* Sorts m words on their bits from `from` up (those above `to` are equal),
 * in place, with tmp as scratch. */
static void sort_words(uint64_t *w, uint64_t *tmp, uint32_t m, unsigned from, unsigned to)
{
	uint64_t *sorted;

	if (m <= SMALL_RUN) {
		insertion_sort(w, m);
		return;
	}
	sorted = radix_sort(w, tmp, m, from, to);
	if (sorted != w)
		memcpy(w, sorted, m * sizeof(*w));
}

/*
 * A run of m words with the same code bits, in id order: puts it in
 * (code, id) order. The left-out code bits and the id fit in one word
 * together (base < id_bits), so the run is sorted as such words, then
 * packed back.
 */
static void fix_run(const lbvh *b, const struct packing *pk, uint64_t *w, uint64_t *tmp,
                    uint32_t m)
{
	uint64_t id_mask = (1ull << pk->id_bits) - 1, low = (1ull << pk->base) - 1;
	uint64_t upper = w[0] & ~id_mask;

	for (uint32_t k = 0; k < m; k++) {
		uint32_t id = (uint32_t)(w[k] & id_mask);
		w[k] = (b->codes[id] & low) << pk->id_bits | id;
	}
	sort_words(w, tmp, m, pk->id_bits, pk->id_bits + pk->base);
	for (uint32_t k = 0; k < m; k++)
		w[k] = upper | (w[k] & id_mask);
}

/* Starts loading the full codes of the words in runs: they are random
 * reads, best all in flight before fix_ties() waits for the first.
 * Whether there is any run. */
static bool prefetch_ties(const lbvh *b, const struct packing *pk, const uint64_t *w,
                          uint32_t m)
{
	uint64_t id_mask = (1ull << pk->id_bits) - 1;
	bool any = false;

	for (uint32_t k = 0; k + 1 < m; k++)
		if ((w[k] ^ w[k + 1]) >> pk->id_bits == 0) {
			__builtin_prefetch(&b->codes[w[k] & id_mask]);
			__builtin_prefetch(&b->codes[w[k + 1] & id_mask]);
			any = true;
		}
	return any;
}

/* Only where base > 0: the runs of equal code bits, each in code order. */
static void fix_ties(const lbvh *b, const struct packing *pk, uint64_t *w, uint64_t *tmp,
                     uint32_t m)
{
	for (uint32_t k = 0; k + 1 < m;) {
		uint32_t j = k + 1;

		while (j < m && (w[j] ^ w[k]) >> pk->id_bits == 0)
			j++;
		if (j - k > 1)
			fix_run(b, pk, w + k, tmp, j - k);
		k = j;
	}
}

/* Sorts the bucket [s, e) in place, its ids to prim_index, and the common
 * prefixes of its neighbours (those across buckets come after). */
static void sort_bucket(lbvh *b, const struct packing *pk, uint32_t s, uint32_t e)
{
	uint64_t *w = b->keys[0] + s, *tmp = b->keys[1] + s;
	uint64_t id_mask = (1ull << pk->id_bits) - 1;

	sort_words(w, tmp, e - s, pk->id_bits, pk->top_shift);
	if (pk->base && prefetch_ties(b, pk, w, e - s))
		fix_ties(b, pk, w, tmp, e - s);
	for (uint32_t k = s; k + 1 < e; k++) {
		b->prim_index[k] = (uint32_t)(b->keys[0][k] & id_mask);
		b->lcp[k] = common_prefix(b, k, k + 1);
	}
	b->prim_index[e - 1] = (uint32_t)(b->keys[0][e - 1] & id_mask);
}

static void sort_buckets(lbvh *b, const struct packing *pk)
{
	uint32_t lo, hi;

	while (next_block(&b->blocks[2], TOP_RADIX, BUCKET_BLOCK, &lo, &hi))
		for (uint32_t d = lo; d < hi; d++)
			if (b->bucket[d + 1] > b->bucket[d])
				sort_bucket(b, pk, b->bucket[d], b->bucket[d + 1]);
}

/* The common prefixes across buckets: before the first word of every
 * bucket but the first non-empty one, and the zero padding. */
static void border_prefixes(lbvh *b, unsigned t)
{
	uint32_t lo, hi, n = b->n;

	chunk(b, t, TOP_RADIX, &lo, &hi);
	for (uint32_t d = lo; d < hi; d++) {
		uint32_t s = b->bucket[d];

		if (s > 0 && b->bucket[d + 1] > s)
			b->lcp[s - 1] = common_prefix(b, s - 1, s);
	}
	if (t == 0) {
		memset(b->lcp - LCP_PAD, 0, LCP_PAD);
		memset(b->lcp + n - 1, 0, LCP_PAD + 1);
	}
}

void lbvh_sort(lbvh *b, unsigned t)
{
	struct packing pk;

	packing_init(b, &pk);
	/* Every thread has the same packing; thread 0 publishes it, the
	 * others read it after the barriers below. */
	if (t == 0) {
		b->sorted.words = b->keys[0];
		b->sorted.base = pk.base;
		b->sorted.id_bits = pk.id_bits;
	}
	codes(b, t);
	team_sync(b);
	scatter(b, t, &pk);
	team_sync(b);
	sort_buckets(b, &pk);
	team_sync(b);
	border_prefixes(b, t);
	team_sync(b);
}
