/*
 * lbvh phase 1, around the sort that morton_build runs (Morton codes of
 * the centroids sorted into (code, primitive) order, plugins/common/morton,
 * shared with ploc and hploc): what the hierarchy needs from that order,
 * the ids into output->prim_index and the common prefix lengths of
 * neighbours, taken per bucket while the sort still has it in cache.
 * Karras compares the sorted words (morton_common_prefix()).
 */
#include <string.h>

#include "lbvh.h"
#include "morton_front.h"

/* Zeroes the arrival counters and flags of thread t's chunk (of n; n - 1
 * flags), which are left from the build before when the scratch is in the
 * output; they are read from the bounds phase on (apart from the sort's
 * buffers, so zeroed after it). */
static void clear_counters(lbvh *b, unsigned t)
{
	uint32_t lo, hi;

	if (!b->scratch_dirty)
		return;
	chunk(b, t, b->n, &lo, &hi);
	memset(b->visits + lo, 0, (hi - lo) * sizeof(*b->visits));
	if (b->node_flags)
		memset(b->node_flags + lo, 0, hi - lo);
}

/* A bucket [s, e) is sorted: its ids, and the common prefixes of its
 * neighbours (those across buckets come after). */
void lbvh_bucket_done(void *arg, uint32_t s, uint32_t e)
{
	lbvh *b = arg;

	for (uint32_t k = s; k + 1 < e; k++) {
		b->prim_index[k] = morton_id(&b->sort, k);
		b->lcp[k] = morton_common_prefix(&b->sort, k, k + 1);
	}
	b->prim_index[e - 1] = morton_id(&b->sort, e - 1);
}

/* The common prefixes across buckets: before the first word of every
 * bucket but the first non-empty one, and the zero padding. */
static void border_prefixes(lbvh *b, unsigned t)
{
	uint32_t lo, hi, n = b->n;

	chunk(b, t, MORTON_TOP_RADIX, &lo, &hi);
	for (uint32_t d = lo; d < hi; d++) {
		uint32_t s = b->sort.bucket[d];

		if (s > 0 && b->sort.bucket[d + 1] > s)
			b->lcp[s - 1] = morton_common_prefix(&b->sort, s - 1, s);
	}
	if (t == 0) {
		memset(b->lcp - LCP_PAD, 0, LCP_PAD);
		memset(b->lcp + n - 1, 0, LCP_PAD + 1);
	}
}

void lbvh_sorted(void *arg, unsigned t)
{
	lbvh *b = arg;

	clear_counters(b, t);
	border_prefixes(b, t);
}
