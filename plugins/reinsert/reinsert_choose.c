/*
 * reinsert: the choice of each iteration's candidates, on the team.
 *
 * Every node but the root gets a key: its measure's float bits (a
 * non-negative float orders as an integer) above the complement of its
 * slot, so keys are unique and ties go to the lower slot. The batch is
 * the k largest keys. A histogram of the top 16 bits finds the bucket
 * where the k-th largest lies: keys of higher buckets are taken whole,
 * that bucket's own are sorted to take what is left.
 *
 * The keys and histograms are made on the team, in blocks handed out to
 * whoever asks (each member adds to a histogram of its own), and each
 * block is partitioned in place, so the work does not depend on the team
 * size; the candidates come out in slot order, then the split bucket's
 * by decreasing key, as one thread would give them. One thread did all
 * of it before: 3.7 ms an iteration on sponza subdivided twice (950,000
 * nodes), as long as a whole search without children moves at batch
 * 0.02 on 2 threads.
 */
#include <stdlib.h>
#include <string.h>

#include "reinsert.h"

#define BUCKETS 65536u

/* Bittner et al.'s measure of how badly a node holds its children: its
 * area, times its area over their mean and over the least of theirs; a
 * leaf's is its cost. As the batch's key it beat the cost alone (lbvh on
 * igea subdivided once, 2 threads, batch 0.02 / 0.05 / 0.1 over 30 / 20 /
 * 10 iterations: SAH 47.66 / 46.91 / 46.33 against 48.38 / 47.57 / 46.83
 * in about the same time). A full batch takes every node either way. */
static double inefficiency(const reinsert *r, uint32_t x)
{
	const bvhlab_node *n = &r->nodes[x];
	double a, l, h;

	if (r->measure == MEASURE_AREA)
		return node_area(n);
	if (n->count)
		return node_cost(n);
	a = node_area(n);
	l = node_area(&r->nodes[n->first]);
	h = node_area(&r->nodes[n->first + 1]);
	return a * (a / (0.5 * (l + h) + 1e-30)) * (a / ((l < h ? l : h) + 1e-30));
}

static uint64_t key_of(const reinsert *r, uint32_t x)
{
	float c = (float)inefficiency(r, x);
	uint32_t bits;

	memcpy(&bits, &c, sizeof(bits));
	return (uint64_t)bits << 32 | (UINT32_MAX - x);
}

/* Keys of blocks [lo, hi) of node 1 .. node_count - 1, counted in t's own
 * histogram. */
static void keys_member(void *arg, unsigned t)
{
	reinsert *r = arg;
	uint32_t *hist = r->hist + (size_t)t * BUCKETS, n = r->node_count - 1, lo, hi;

	while (team_next_block(&r->next, n, CHOOSE_BLOCK, &lo, &hi))
		for (uint32_t j = lo; j < hi; j++) {
			uint64_t key = key_of(r, j + 1);

			r->keys[j] = key;
			hist[key >> 48]++;
		}
}

/* Moves the keys of bucket > b (of bucket b when `equal`) to the front of
 * keys[0 .. n), in their order; returns how many. */
static uint32_t take(uint64_t *keys, uint32_t n, uint32_t b, bool equal)
{
	uint32_t at = 0;

	for (uint32_t j = 0; j < n; j++)
		if (equal ? keys[j] >> 48 == b : keys[j] >> 48 > b) {
			uint64_t tmp = keys[at];
			keys[at++] = keys[j];
			keys[j] = tmp;
		}
	return at;
}

/* Each block: the keys above the split bucket first, then the bucket's. */
static void partition_member(void *arg, unsigned t)
{
	reinsert *r = arg;
	uint32_t n = r->node_count - 1, lo, hi;

	(void)t;
	while (team_next_block(&r->next, n, CHOOSE_BLOCK, &lo, &hi)) {
		uint32_t b = lo / CHOOSE_BLOCK, above = take(r->keys + lo, hi - lo, r->split, false);

		r->above[b] = above;
		r->equal[b] = take(r->keys + lo + above, hi - lo - above, r->split, true);
	}
}

static int descending(const void *a, const void *b)
{
	uint64_t x = *(const uint64_t *)a, y = *(const uint64_t *)b;

	return (x < y) - (x > y);
}

/* Sums the members' histograms into the first; sets r->split. */
static void find_split(reinsert *r, unsigned members, uint32_t k)
{
	uint32_t above = 0;

	for (unsigned t = 1; t < members; t++)
		for (uint32_t b = 0; b < BUCKETS; b++)
			r->hist[b] += r->hist[(size_t)t * BUCKETS + b];
	for (r->split = BUCKETS - 1; above + r->hist[r->split] < k; r->split--)
		above += r->hist[r->split];
}

/* The blocks' keys above the split to the candidates, in block order;
 * the split bucket's moved down to keys[0 ..), sorted, the largest taken.
 * The move never reaches a block not yet read: block b's bucket keys go
 * below the end of block b, after its keys above were taken. */
static void gather(reinsert *r, uint32_t k)
{
	uint32_t n = r->node_count - 1, blocks = (n + CHOOSE_BLOCK - 1) / CHOOSE_BLOCK, eq = 0;

	r->cand_count = 0;
	for (uint32_t b = 0; b < blocks; b++) {
		const uint64_t *block = r->keys + (size_t)b * CHOOSE_BLOCK;

		for (uint32_t j = 0; j < r->above[b]; j++)
			r->cand[r->cand_count++] = UINT32_MAX - (uint32_t)block[j];
		memmove(r->keys + eq, block + r->above[b], r->equal[b] * sizeof(*r->keys));
		eq += r->equal[b];
	}
	qsort(r->keys, eq, sizeof(*r->keys), descending);
	for (uint32_t j = 0; r->cand_count < k; j++)
		r->cand[r->cand_count++] = UINT32_MAX - (uint32_t)r->keys[j];
}

int reinsert_choose(reinsert *r, double batch, unsigned threads, const team_host *th)
{
	uint32_t n = r->node_count - 1, k = (uint32_t)(batch * n);
	int rc;

	k = k < 1 ? 1 : k > n ? n : k;
	memset(r->hist, 0, (size_t)threads * BUCKETS * sizeof(*r->hist));
	atomic_store_explicit(&r->next, 0, memory_order_relaxed);
	if ((rc = team_run_on(&r->team, th, threads, keys_member, r)) < 0)
		return rc;
	find_split(r, threads, k);
	atomic_store_explicit(&r->next, 0, memory_order_relaxed);
	if ((rc = team_run_on(&r->team, th, threads, partition_member, r)) < 0)
		return rc;
	gather(r, k);
	return 0;
}
