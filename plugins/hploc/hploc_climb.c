/*
 * hploc phase 2: the climbs (see hploc.h). Threads take blocks of leaves;
 * from each leaf a climb goes up while it arrives second at a parent. At
 * a node, the clusters of its two children are merged by PLOC rounds
 * until at most `threshold` are left (one at the root).
 *
 * The exchange on meet[] is what hands a finished child over: its acq_rel
 * releases the first arrival's clusters, records and idx[] entries and
 * acquires them for the second. A node's merging is hploc_merge.h, which
 * the device kernel (cl_hploc.cl) is built with too.
 */
#include <string.h>

#include "hploc.h"

/* Leaves per block handed out: each is a climb of a few nodes on average. */
#define CLIMB_BLOCK 4096

/* Node [first, last], its right child from `split`: the children's
 * clusters merged down to the threshold (hploc_merge.h, on copies, as
 * the device does), written back from idx[first], the records to their
 * slots. */
static void finish_node(hploc *h, uint32_t first, uint32_t split, uint32_t last)
{
	hploc_cluster c[HPLOC_MAX_LIST];
	hploc_rec rec[HPLOC_MAX_LIST];
	uint32_t list[HPLOC_MAX_LIST], slot[HPLOC_MAX_LIST], records;
	uint32_t lm = h->count[first], rm = h->count[split], m = lm + rm;
	uint32_t cap = first == 0 && last == h->n - 1 ? 1 : h->threshold;

	memcpy(list, h->idx + first, 4 * (size_t)lm);
	memcpy(list + lm, h->idx + split, 4 * (size_t)rm);
	if (m > cap) {
		for (uint32_t i = 0; i < m; i++)
			c[i] = h->cl[list[i]];
		m = hploc_merge_list(c, list, m, cap, &h->merge, rec, slot, &records);
		for (uint32_t i = 0; i < m; i++)
			h->cl[list[i]] = c[i];
		for (uint32_t i = 0; i < records; i++)
			h->rec[slot[i]] = rec[i];
	}
	memcpy(h->idx + first, list, 4 * (size_t)m);
	h->count[first] = m;
}

/* Whether the range [first, last] joins its right neighbour: it shares
 * more with it than with its left one (Apetrei 2014; never equal). */
static bool joins_right(const hploc *h, uint32_t first, uint32_t last)
{
	if (first == 0)
		return true;
	if (last == h->n - 1)
		return false;
	return morton_common_prefix(&h->sort, last, last + 1) >
	       morton_common_prefix(&h->sort, first - 1, first);
}

/* From leaf k up, while this climb arrives second. */
static void climb(hploc *h, uint32_t k)
{
	uint32_t first = k, last = k, other, split;

	while (first > 0 || last < h->n - 1) {
		if (joins_right(h, first, last)) {
			other = atomic_exchange_explicit(&h->meet[last], first, memory_order_acq_rel);
			split = last + 1;
			last = other;
		} else {
			other = atomic_exchange_explicit(&h->meet[first - 1], last,
			                                 memory_order_acq_rel);
			split = first;
			first = other;
		}
		if (other == HPLOC_NONE)
			return;
		finish_node(h, first, split, last);
	}
	h->root = h->cl[h->idx[0]].node;
}

void hploc_climb(hploc *h, unsigned t)
{
	uint32_t lo, hi;

	(void)t;
	while (team_next_block(&h->blocks, h->n, CLIMB_BLOCK, &lo, &hi))
		for (uint32_t k = lo; k < hi; k++)
			climb(h, k);
	team_sync(&h->team);
}
