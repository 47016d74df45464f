/*
 * Morton codes and their parallel sort (see morton.h): the codes by table,
 * the scatter into buckets by the top digit, each bucket sorted in cache
 * by LSD passes that skip constant digits, and the runs of words whose
 * kept code bits tie put in full-code order.
 */
#include <string.h>

#include "morton.h"
#include "morton_spread.h"
#include "team.h"

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

#define SPREAD_BITS 11

void morton_cells_init(morton_cells *q, const bvhlab_aabb *cb, unsigned bits)
{
	unsigned axis_bits = bits / 3;

	q->top = (float)((1u << axis_bits) - 1);
	for (int k = 0; k < 3; k++) {
		float extent = cb->hi[k] - cb->lo[k];
		float s = (float)(1u << axis_bits) / extent;
		q->lo[k] = cb->lo[k];
		q->scale[k] = extent > 0 && s < 1e30f ? s : 0.0f;
	}
}

/* The cells, and morton_spread21 by table, 11 bits at a time: two loads
 * instead of fifteen operations per axis, from 16 KiB that stay in L1. */
struct quantiser {
	morton_cells c;
	uint64_t spread[1u << SPREAD_BITS];
};

static void quantiser_init(struct quantiser *q, const morton_sort *s)
{
	morton_cells_init(&q->c, &s->centroid_bounds, s->bits);
	for (uint32_t v = 0; v < (1u << SPREAD_BITS); v++)
		q->spread[v] = morton_spread21(v);
}

/* Clamped because c - lo can round up to the top edge; a NaN goes to
 * cell 0 rather than into an undefined conversion. Cells fit in int32_t,
 * whose conversion is one instruction (uint64_t's is a branch). */
static inline uint64_t axis(const struct quantiser *q, const float *c, int k)
{
	float x = (c[k] - q->c.lo[k]) * q->c.scale[k];
	uint32_t cell;

	x = x > 0 ? x : 0;
	x = x < q->c.top ? x : q->c.top;
	cell = (uint32_t)(int32_t)x;
	return q->spread[cell & ((1u << SPREAD_BITS) - 1)] |
	       q->spread[cell >> SPREAD_BITS] << (3 * SPREAD_BITS);
}

static inline uint64_t morton(const struct quantiser *q, const float *c)
{
	return axis(q, c, 0) << 2 | axis(q, c, 1) << 1 | axis(q, c, 2);
}

void morton_sort_init(morton_sort *s)
{
	unsigned id_bits = 32 - (unsigned)__builtin_clz(s->n - 1);
	unsigned kept = s->bits < 64 - id_bits ? s->bits : 64 - id_bits;

	s->id_bits = id_bits;
	s->base = s->bits - kept;
	s->top_shift = id_bits + kept - MORTON_TOP_BITS;
}

static inline uint64_t pack(const morton_sort *s, uint64_t code, uint32_t id)
{
	return (code >> s->base) << s->id_bits | id;
}

void morton_codes(morton_sort *s, unsigned threads, unsigned t)
{
	struct quantiser q;
	uint32_t *h = s->hist[t], lo, hi;
	unsigned top = s->bits - MORTON_TOP_BITS;

	quantiser_init(&q, s);
	memset(h, 0, MORTON_TOP_RADIX * sizeof(*h));
	team_chunk(threads, t, s->n, &lo, &hi);
	for (uint32_t i = lo; i < hi; i++) {
		uint64_t code = morton(&q, s->centroids + 3 * (size_t)i);
		s->codes[i] = code;
		h[code >> top]++;
	}
}

/* Where member t's words of each top digit go: after every word of a
 * lower digit, and after the same digit's words of lower chunks. Member
 * 0 also publishes where each bucket starts. */
static void offsets(morton_sort *s, unsigned threads, unsigned t,
                    uint32_t off[MORTON_TOP_RADIX])
{
	uint32_t sum = 0;

	for (unsigned d = 0; d < MORTON_TOP_RADIX; d++) {
		if (t == 0)
			s->bucket[d] = sum;
		for (unsigned u = 0; u < threads; u++) {
			if (u == t)
				off[d] = sum;
			sum += s->hist[u][d];
		}
	}
	if (t == 0)
		s->bucket[MORTON_TOP_RADIX] = sum;
}

void morton_scatter(morton_sort *s, unsigned threads, unsigned t)
{
	uint32_t off[MORTON_TOP_RADIX], lo, hi;
	uint64_t *dst = s->keys[0];

	offsets(s, threads, t, off);
	team_chunk(threads, t, s->n, &lo, &hi);
	for (uint32_t i = lo; i < hi; i++) {
		uint64_t w = pack(s, s->codes[i], i);
		dst[off[w >> s->top_shift]++] = w;
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
static void fix_run(const morton_sort *s, uint64_t *w, uint64_t *tmp,
                    uint32_t m)
{
	uint64_t id_mask = (1ull << s->id_bits) - 1, low = (1ull << s->base) - 1;
	uint64_t upper = w[0] & ~id_mask;

	for (uint32_t k = 0; k < m; k++) {
		uint32_t id = (uint32_t)(w[k] & id_mask);
		w[k] = (s->codes[id] & low) << s->id_bits | id;
	}
	sort_words(w, tmp, m, s->id_bits, s->id_bits + s->base);
	for (uint32_t k = 0; k < m; k++)
		w[k] = upper | (w[k] & id_mask);
}

/* Starts loading the full codes of the words in runs: they are random
 * reads, best all in flight before fix_ties() waits for the first.
 * Whether there is any run. */
static bool prefetch_ties(const morton_sort *s, const uint64_t *w,
                          uint32_t m)
{
	uint64_t id_mask = (1ull << s->id_bits) - 1;
	bool any = false;

	for (uint32_t k = 0; k + 1 < m; k++)
		if ((w[k] ^ w[k + 1]) >> s->id_bits == 0) {
			__builtin_prefetch(&s->codes[w[k] & id_mask]);
			__builtin_prefetch(&s->codes[w[k + 1] & id_mask]);
			any = true;
		}
	return any;
}

/* Only where base > 0: the runs of equal code bits, each in code order. */
static void fix_ties(const morton_sort *s, uint64_t *w, uint64_t *tmp,
                     uint32_t m)
{
	for (uint32_t k = 0; k + 1 < m;) {
		uint32_t j = k + 1;

		while (j < m && (w[j] ^ w[k]) >> s->id_bits == 0)
			j++;
		if (j - k > 1)
			fix_run(s, w + k, tmp, j - k);
		k = j;
	}
}

/* Sorts the bucket [first, end) in place. */
static void sort_bucket(const morton_sort *s, uint32_t first, uint32_t end)
{
	uint64_t *w = s->keys[0] + first, *tmp = s->keys[1] + first;

	sort_words(w, tmp, end - first, s->id_bits, s->top_shift);
	if (s->base && prefetch_ties(s, w, end - first))
		fix_ties(s, w, tmp, end - first);
}

void morton_sort_buckets(morton_sort *s, void (*done)(void *arg, uint32_t first, uint32_t end),
                         void *arg)
{
	uint32_t lo, hi;

	while (team_next_block(&s->next_bucket, MORTON_TOP_RADIX, BUCKET_BLOCK, &lo, &hi))
		for (uint32_t d = lo; d < hi; d++) {
			if (s->bucket[d + 1] <= s->bucket[d])
				continue;
			sort_bucket(s, s->bucket[d], s->bucket[d + 1]);
			if (done)
				done(arg, s->bucket[d], s->bucket[d + 1]);
		}
}
