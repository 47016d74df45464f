/*
 * lbvh phases 2 and 3: the hierarchy (Karras 2012, "Maximizing parallelism
 * in the construction of BVHs, octrees and k-d trees") and its boxes.
 *
 * Karras: every internal node i finds its range and split on its own, so
 * the n - 1 nodes are independent and the threads take them in blocks. With
 * delta(i, j) the common prefix length of sorted keys i and j (extended by
 * their positions where codes are equal, the paper's k_i ++ i, so that the
 * tree stays well formed even when every centroid coincides), node i
 * reaches from i towards the neighbour it shares more with, as long as
 * delta stays above delta_min, what i shares with its other neighbour; it
 * splits where delta(i, .) drops to delta(first, last) over its range.
 * Since the keys are sorted, delta(i, j) is the minimum of lcp[] between
 * i and j: the range's other end is the first lcp[] at or below
 * delta_min, and the split the one place in the range where lcp[] equals
 * delta(first, last). Both are 16-byte scans of lcp[] instead of the
 * paper's exponential and binary searches on the keys (same ranges, same
 * splits): most ranges are short, one compare settles them, and there are
 * no hard-to-predict branches. The scans' total length is bounded by n
 * times the tree depth, at most 97 levels (delta <= 95).
 *
 * Bounds: each thread takes blocks of leaves, writes their output slots
 * and climbs from each. At every parent the first arrival stops and the
 * second, which now has both children, writes the parent's slot and climbs
 * on. At a node shared by two threads the arrival counter's acq_rel
 * fetch_add is what hands the first child over: the first arrival releases
 * its writes, the second acquires them. The collapse decisions are made on
 * the way (lbvh_collapse.c).
 */
/* -DLBVH_NO_SIMD builds the portable scans on x86 too, to test them. */
#if defined(__SSE2__) && !defined(LBVH_NO_SIMD)
#include <emmintrin.h>
#endif

#include "lbvh.h"

#if defined(__SSE2__) && !defined(LBVH_NO_SIMD)

static inline __m128i load(const uint8_t *lcp, int64_t k)
{
	return _mm_loadu_si128((const __m128i *)(const void *)(lcp + k));
}

/* Bit j set where byte j of x is at most bound. */
static inline unsigned at_most(__m128i x, uint8_t bound)
{
	__m128i v = _mm_set1_epi32((int)(0x01010101u * bound));

	return (unsigned)_mm_movemask_epi8(_mm_cmpeq_epi8(_mm_min_epu8(x, v), x));
}

/*
 * The other end of the range of node i, growing upwards (from i + 1) or
 * downwards (from i - 2: lcp[i - 1] is the larger neighbour) until lcp[]
 * is at most bound. One 16-byte compare settles most nodes. The direction
 * is a coin toss per node, so it enters as arithmetic, never as a branch.
 */
static inline int64_t other_end(const uint8_t *lcp, int64_t i, bool up, uint8_t bound)
{
	int64_t base = i - 17 + 18 * (int64_t)up;
	unsigned m = at_most(load(lcp, base), bound);

	while (m == 0) {
		base += 32 * (int64_t)up - 16;
		m = at_most(load(lcp, base), bound);
	}
	int first_set = __builtin_ctz(m), after_last = 32 - __builtin_clz(m);
	return base + after_last + (int64_t)up * (first_set - after_last);
}

/* The first k >= from with lcp[k] == value. */
static inline int64_t first_equal(const uint8_t *lcp, int64_t from, uint8_t value)
{
	__m128i v = _mm_set1_epi32((int)(0x01010101u * value));
	unsigned eq;

	while (!(eq = (unsigned)_mm_movemask_epi8(_mm_cmpeq_epi8(load(lcp, from), v))))
		from += 16;
	return from + __builtin_ctz(eq);
}

#else /* the same scans, a byte at a time */

static int64_t other_end(const uint8_t *lcp, int64_t i, bool up, uint8_t bound)
{
	int64_t k = up ? i + 1 : i - 2;

	while (lcp[k] > bound)
		k += up ? 1 : -1;
	return up ? k : k + 1;
}

static inline int64_t first_equal(const uint8_t *lcp, int64_t from, uint8_t value)
{
	while (lcp[from] != value)
		from++;
	return from;
}

#endif

/*
 * lcp[i - 1] and lcp[i] are what i shares with its neighbours; the range
 * grows towards the larger one (they are never equal) until lcp[] drops to
 * the smaller one. The sentinels (0) stop the scans at both ends. The
 * split is where lcp[] is smallest in the range: the one place where it
 * equals the common prefix of the range's two ends. Whether a child is a
 * leaf is a coin toss too: it selects the parent slot by arithmetic
 * (leaves follow the internal nodes in parent[]).
 */
static void karras_node(lbvh *b, uint32_t i)
{
	const uint8_t *lcp = b->lcp;
	uint8_t left = lcp[(int64_t)i - 1], right = lcp[i];
	uint32_t end = (uint32_t)other_end(lcp, i, right > left, left < right ? left : right);
	uint32_t first = i < end ? i : end, last = i ^ end ^ first, leaves = b->n - 1;
	uint32_t split =
	        (uint32_t)first_equal(lcp, first, morton_common_prefix(&b->sort, first, last));

	b->end[i] = end;
	/* Each node is the child of exactly one parent: no two writes meet. */
	b->parent[split + (leaves & -(uint32_t)(split == first))] = 2 * i;
	b->parent[split + 1 + (leaves & -(uint32_t)(split + 1 == last))] = 2 * i + 1;
}

/* Nodes per block handed out: tens of microseconds of work. */
#define KARRAS_BLOCK 8192
/* Leaves per block of the bounds phase: their slots (512 KiB) are still
 * in L2 when the climbs from them read them back. */
#define BOUNDS_BLOCK 16384
/* How far ahead the leaves' boxes are fetched: a miss here is a page walk
 * and a memory access, some hundreds of nanoseconds, while a leaf takes a
 * few; 32 ahead was measured 0.6 ms slower on 1M leaves. */
#define LEAF_AHEAD 96

void lbvh_karras(lbvh *b, unsigned t)
{
	uint32_t lo, hi;

	while (team_next_block(&b->blocks[0], b->n - 1, KARRAS_BLOCK, &lo, &hi))
		for (uint32_t i = lo; i < hi; i++)
			karras_node(b, i);
	if (t == 0)
		b->parent[0] = NO_NODE;
	lbvh_sync(b);
}

/* Both children of internal node i are done: writes its slot and returns
 * its parent word. */
static uint32_t finish_node(lbvh *b, uint32_t i, uint32_t size)
{
	const bvhlab_node *l = kids_of(b, i), *r = l + 1;
	uint32_t word = b->parent[i];
	bvhlab_node *out = slot_of(b, word);

#if defined(__SSE2__) && !defined(LBVH_NO_SIMD)
	/* lo[3] and first, hi[3] and count: four lanes each, the fourth
	 * rewritten right after. */
	_mm_storeu_ps(out->lo, _mm_min_ps(_mm_loadu_ps(l->lo), _mm_loadu_ps(r->lo)));
	_mm_storeu_ps(out->hi, _mm_max_ps(_mm_loadu_ps(l->hi), _mm_loadu_ps(r->hi)));
#else
	/* Plain compares, not fminf: boxes hold no NaN, and these inline. */
	for (int k = 0; k < 3; k++) {
		out->lo[k] = bvhlab_minf(l->lo[k], r->lo[k]);
		out->hi[k] = bvhlab_maxf(l->hi[k], r->hi[k]);
	}
#endif
	out->first = 1 + 2 * i;
	out->count = 0;
	if (b->collapse)
		lbvh_collapse(b, i, size, out);
	return word;
}

/*
 * Is this the second arrival at node p, of `size` primitives from `first`,
 * coming from side `right`? A node whose range lies inside this thread's
 * block of leaves [lo, hi) is reached only by this thread, left child
 * first (the leaves go in order), so it needs no counter; only the nodes
 * on the paths from block borders to the root are shared, and they take
 * the atomic one (zeroed before the build's first barrier).
 */
static bool second_arrival(lbvh *b, uint32_t p, uint32_t first, uint32_t size, bool right,
                           uint32_t lo, uint32_t hi)
{
	if (first >= lo && first + size <= hi)
		return right;
	/* Acquire the other child's slot (and its subtree's flags); release
	 * ours for the thread that comes second. */
	return atomic_fetch_add_explicit(&b->visits[p], 1, memory_order_acq_rel) != 0;
}

/* Climbs from a leaf whose parent word is `word` while it arrives second. */
static void climb(lbvh *b, uint32_t word, uint32_t lo, uint32_t hi)
{
	while (word != NO_NODE) {
		/* min and max without a branch: p is either end of its range, a
		 * coin toss, and a compiler may turn the pair into one */
		uint32_t p = word >> 1, end = b->end[p];
		uint32_t first = p < end ? p : end, last = p ^ end ^ first, size = last - first + 1;

		if (!second_arrival(b, p, first, size, word & 1, lo, hi))
			return;
		word = finish_node(b, p, size);
	}
}

static void put_leaf(const lbvh *b, uint32_t k, bvhlab_node *out)
{
	const bvhlab_aabb *box = &b->in->prim_bounds[b->prim_index[k]];

	for (int a = 0; a < 3; a++) {
		out->lo[a] = box->lo[a];
		out->hi[a] = box->hi[a];
	}
	out->first = k;
	out->count = 1;
}

/*
 * By blocks of leaves, each taken whole by one thread: the leaves first,
 * in a loop of their own: their boxes are the one random read of the
 * build (input order to sorted order), and only a loop with nothing else
 * to wait for keeps many of those misses in flight. Then the climbs from
 * them, while their slots are still in cache.
 */
void lbvh_bounds(lbvh *b, unsigned t)
{
	uint32_t lo, hi;

	(void)t;
	while (team_next_block(&b->blocks[1], b->n, BOUNDS_BLOCK, &lo, &hi)) {
		for (uint32_t k = lo; k < hi; k++) {
			if (k + LEAF_AHEAD < hi)
				__builtin_prefetch(&b->in->prim_bounds[b->prim_index[k + LEAF_AHEAD]]);
			put_leaf(b, k, slot_of(b, b->parent[b->n - 1 + k]));
		}
		for (uint32_t k = lo; k < hi; k++)
			climb(b, b->parent[b->n - 1 + k], lo, hi);
	}
	lbvh_sync(b);
}
