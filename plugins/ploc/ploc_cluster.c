/*
 * ploc phase 2: the clustering iterations (see ploc.h). Each iteration,
 * over the m clusters in Morton order:
 *
 *   nearest  by blocks handed out to whichever thread is free: every
 *            cluster's nearest neighbour within `radius` positions. Each
 *            distance is computed once, in the row of the earlier cluster
 *            (a vector loop over its `radius` successors), and offered to
 *            both; a block recomputes the `radius` rows before it.
 *   count    by chunks: merges (mutual pairs, counted at the earlier
 *            cluster) and survivors (everything but the later cluster of
 *            a pair)
 *   write    by chunks, after a prefix over the chunks' counts: each
 *            merge writes its two clusters as a pair of records of the
 *            merge tree and the merged cluster into the next iteration's
 *            arrays; other clusters are copied there. Positions depend
 *            only on the order, never on the chunks.
 *
 * The SAH collapse is decided at each merge, from the two clusters'
 * costs, as lbvh decides it bottom-up; ploc_emit.c applies it.
 */
#include <string.h>

#include <bvhlab/aabb.h>

#include "ploc.h"

/* Clusters per block of the nearest-neighbour search: a block repeats
 * `radius` rows, 1.5 % of 1024 at the default radius. */
#define NN_BLOCK 1024

/*
 * A candidate's place in the total order of ploc.h, as one word: the
 * distance's float bits (non-negative floats order as integers) with the
 * lowest 8 of its 23 mantissa bits (a relative 3e-5) given up for, in
 * order: how far apart the pair is (6 bits), the parity of its earlier
 * cluster, and 1 when the candidate comes after the cluster choosing.
 */
#define TIE_BITS 8u
#define TIE_MASK ((1u << TIE_BITS) - 1)

/* The row loops are inlined into nearest_block so that its AVX2 clone
 * compiles them 8 lanes wide: called, they ran at the default target's 4
 * lanes (igea subdivided once, one thread: 199 ms a build, 163 inlined). */
#if defined(__GNUC__)
#define ROW_INLINE static inline __attribute__((always_inline))
#else
#define ROW_INLINE static inline
#endif

/*
 * key[k]: the pair of cluster i and cluster i + 1 + k, k < count, as its
 * later cluster sees it (the earlier one adds 1): one row, in loops the
 * compiler vectorises. The distance is half the surface area of the
 * union of the two boxes.
 */
ROW_INLINE void key_row(const struct clusters *c, uint32_t i, uint32_t count, uint32_t *key)
{
	const float *l0 = c->lo[0] + i + 1, *l1 = c->lo[1] + i + 1, *l2 = c->lo[2] + i + 1;
	const float *h0 = c->hi[0] + i + 1, *h1 = c->hi[1] + i + 1, *h2 = c->hi[2] + i + 1;
	float a0 = c->lo[0][i], a1 = c->lo[1][i], a2 = c->lo[2][i];
	float b0 = c->hi[0][i], b1 = c->hi[1][i], b2 = c->hi[2][i];
	uint32_t parity = (i & 1) << 1;

	for (uint32_t k = 0; k < count; k++) {
		float dx = (h0[k] > b0 ? h0[k] : b0) - (l0[k] < a0 ? l0[k] : a0);
		float dy = (h1[k] > b1 ? h1[k] : b1) - (l1[k] < a1 ? l1[k] : a1);
		float dz = (h2[k] > b2 ? h2[k] : b2) - (l2[k] < a2 ? l2[k] : a2);
		float d = half_area3(dx, dy, dz);
		uint32_t bits;

		d = d > 0 ? d : 0; /* -0 and NaN as 0 */
		memcpy(&bits, &d, sizeof(bits));
		key[k] = (bits & ~TIE_MASK) | k << 2 | parity;
	}
}

/* The least of the row's keys, and each offered to its later cluster. */
ROW_INLINE uint32_t offer_row(const uint32_t *key, uint32_t count, uint32_t *best)
{
	uint32_t least = UINT32_MAX;

	for (uint32_t k = 0; k < count; k++) {
		least = key[k] < least ? key[k] : least;
		best[k] = key[k] < best[k] ? key[k] : best[k];
	}
	return least | 1;
}

/* best[] covers [from, hi + radius): rows update it without bounds tests. */
#if defined(__x86_64__) && defined(__GNUC__) && !defined(__clang__)
/* Eight lanes where the CPU has AVX2 (chosen when the plugin loads): the
 * same operations in the same order, so the same keys. */
__attribute__((target_clones("avx2", "default")))
#endif
static void nearest_block(ploc *p, const struct clusters *c, uint32_t m, uint32_t lo,
                          uint32_t hi)
{
	uint32_t best[NN_BLOCK + 2 * PLOC_MAX_RADIUS], key[PLOC_MAX_RADIUS];
	uint32_t r = p->radius, from = lo > r ? lo - r : 0;

	for (uint32_t k = 0; k < hi + r - from; k++)
		best[k] = UINT32_MAX;
	for (uint32_t i = from; i < hi; i++) {
		uint32_t count = m - 1 - i < r ? m - 1 - i : r;
		uint32_t least;

		key_row(c, i, count, key);
		least = offer_row(key, count, best + (i + 1 - from));
		best[i - from] = least < best[i - from] ? least : best[i - from];
	}
	for (uint32_t i = lo; i < hi; i++) {
		uint32_t w = best[i - from], apart = 1 + ((w & TIE_MASK) >> 2);

		p->nn[i] = w & 1 ? i + apart : i - apart;
	}
}

static void nearest(ploc *p, const struct clusters *c, uint32_t m, atomic_uint *blocks)
{
	uint32_t lo, hi;

	while (team_next_block(blocks, m, NN_BLOCK, &lo, &hi))
		nearest_block(p, c, m, lo, hi);
}

static inline bool mutual(const ploc *p, uint32_t i)
{
	return p->nn[p->nn[i]] == i;
}

/* Merges and survivors of chunk [lo, hi), into count[t] and count[T + t]. */
static void count_chunk(ploc *p, unsigned chunks, unsigned t, uint32_t lo, uint32_t hi)
{
	uint32_t merges = 0, survivors = 0;

	for (uint32_t i = lo; i < hi; i++) {
		bool pair = mutual(p, i);

		merges += pair && i < p->nn[i];
		survivors += !pair || i < p->nn[i];
	}
	p->count[t] = merges;
	p->count[chunks + t] = survivors;
}

/* Sum of count[base + u] over the chunks before t, and over all. */
static uint32_t prefix(const ploc *p, unsigned chunks, unsigned t, unsigned base,
                       uint32_t *total)
{
	uint32_t before = 0;

	*total = 0;
	for (unsigned u = 0; u < chunks; u++) {
		before += u < t ? p->count[base + u] : 0;
		*total += p->count[base + u];
	}
	return before;
}

static void copy_cluster(const struct clusters *c, uint32_t i, struct clusters *to, uint32_t k)
{
	for (int a = 0; a < 3; a++) {
		to->lo[a][k] = c->lo[a][i];
		to->hi[a][k] = c->hi[a][i];
	}
	to->meta[k] = c->meta[i];
}

/* Cluster i of c as record x of the merge tree. */
static void put_record(ploc *p, const struct clusters *c, uint32_t i, uint32_t x)
{
	bvhlab_node *rec = &p->tree[x];

	for (int a = 0; a < 3; a++) {
		rec->lo[a] = c->lo[a][i];
		rec->hi[a] = c->hi[a][i];
	}
	rec->first = c->meta[i].first;
	rec->count = c->meta[i].info;
	p->desc[x] = c->meta[i].desc;
}

/*
 * The SAH decision of lbvh's collapse: a merged cluster of at most
 * max_leaf primitives becomes one leaf when c_isect * N * A is no more
 * than c_trav * A plus its children's costs (ties to the leaf).
 */
static void merge_cost(const ploc *p, const struct clusters *c, uint32_t i, uint32_t j,
                       struct clusters *to, uint32_t k)
{
	const struct cluster_meta *a = &c->meta[i], *b = &c->meta[j];
	uint32_t prims = (a->info & REC_PRIMS) + (b->info & REC_PRIMS);
	float area = half_area3(to->hi[0][k] - to->lo[0][k], to->hi[1][k] - to->lo[1][k],
	                        to->hi[2][k] - to->lo[2][k]);
	float split = p->c_trav * area + a->cost + b->cost;
	float leaf = p->c_isect * (float)prims * area;
	struct cluster_meta *m = &to->meta[k];

	if (p->collapse && prims <= p->max_leaf && leaf <= split) {
		m->info = prims | REC_COLLAPSED;
		m->cost = leaf;
		m->desc = 0;
		return;
	}
	m->info = prims;
	m->cost = split;
	m->desc = 2 + a->desc + b->desc;
}

/* Clusters i < j merge: their records at x and x + 1, the union at k. */
static void merge(ploc *p, const struct clusters *c, uint32_t i, uint32_t j, uint32_t x,
                  struct clusters *to, uint32_t k)
{
	put_record(p, c, i, x);
	put_record(p, c, j, x + 1);
	for (int a = 0; a < 3; a++) {
		to->lo[a][k] = bvhlab_minf(c->lo[a][i], c->lo[a][j]);
		to->hi[a][k] = bvhlab_maxf(c->hi[a][i], c->hi[a][j]);
	}
	to->meta[k].first = x;
	merge_cost(p, c, i, j, to, k);
}

/* Chunk [lo, hi): merges take the pairs below `base` in order. Returns
 * the survivors of all chunks; *merges gets the merges of all. */
static uint32_t write_chunk(ploc *p, unsigned chunks, unsigned t, const struct clusters *c,
                            struct clusters *to, uint32_t lo, uint32_t hi, uint32_t base,
                            uint32_t *merges)
{
	uint32_t survivors, k = prefix(p, chunks, t, chunks, &survivors);
	uint32_t pair = base - 2 * prefix(p, chunks, t, 0, merges);

	for (uint32_t i = lo; i < hi; i++) {
		uint32_t j = p->nn[i];

		if (!mutual(p, i)) {
			copy_cluster(c, i, to, k++);
		} else if (i < j) {
			pair -= 2;
			merge(p, c, i, j, pair, to, k++);
		}
	}
	return survivors;
}

/* Barriers only while there is work for the team (team false: thread 0
 * alone, no barrier). */
static void sync_if(ploc *p, bool team)
{
	if (team)
		team_sync(&p->team);
}

/* One iteration over *m clusters, by `chunks` members (1: thread 0 alone);
 * every member keeps the same *m and *base. */
static void iteration(ploc *p, unsigned t, unsigned chunks, uint32_t it, uint32_t *m,
                      uint32_t *base)
{
	const struct clusters *c = &p->cl[it & 1];
	struct clusters *to = &p->cl[(it + 1) & 1];
	uint32_t lo, hi, merges;
	bool team = chunks > 1;

	nearest(p, c, *m, &p->blocks[it & 1]);
	sync_if(p, team);
	team_chunk(chunks, t, *m, &lo, &hi);
	count_chunk(p, chunks, t, lo, hi);
	sync_if(p, team);
	if (t == 0) /* last used an iteration ago; next used after the sync below */
		atomic_store_explicit(&p->blocks[(it + 1) & 1], 0, memory_order_relaxed);
	*m = write_chunk(p, chunks, t, c, to, lo, hi, *base, &merges);
	*base -= 2 * merges;
	sync_if(p, team);
}

/*
 * The iterations: by the team while there are many clusters, then by
 * thread 0 alone, the others done: the last few dozen iterations have
 * little work each, and three barriers apiece would cost more than they
 * share out (on a busy machine, a barrier waits for a descheduled thread).
 */
void ploc_cluster(ploc *p, unsigned t)
{
	uint32_t m = p->n, base = 2 * p->n - 1, it = 0;

	for (; m > PLOC_SOLO_BELOW; it++)
		iteration(p, t, p->team.threads, it, &m, &base);
	if (t == 0) {
		for (; m > 1; it++)
			iteration(p, 0, 1, it, &m, &base);
		put_record(p, &p->cl[it & 1], 0, 0);
		p->iterations = it;
	}
	team_sync(&p->team);
}
