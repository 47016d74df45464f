/*
 * hploc phase 2: the climbs (see hploc.h). Threads take blocks of leaves;
 * from each leaf a climb goes up while it arrives second at a parent. At
 * a node, the clusters of its two children are merged by PLOC rounds
 * until at most `threshold` are left (one at the root).
 *
 * The exchange on meet[] is what hands a finished child over: its acq_rel
 * releases the first arrival's clusters, records and idx[] entries and
 * acquires them for the second. A parent's arithmetic (the keys, the
 * union, the SAH collapse) is ploc's, in the same order (ploc_cluster.c),
 * and cl_hploc.cl repeats it.
 */
#include <string.h>

#include <bvhlab/aabb.h>

#include "hploc.h"

/* Leaves per block handed out: each is a climb of a few nodes on average. */
#define CLIMB_BLOCK 4096

/* ploc's candidate keys (ploc_cluster.c): the distance's float bits with
 * the lowest 8 given up for how far apart the pair is, the parity of its
 * earlier cluster, and 1 when seen from the earlier one. */
#define TIE_MASK 0xffu

/* The key of the pair e (at list position e_at) and l, k + 1 positions
 * later, as l sees it. */
static uint32_t pair_key(const hploc_cluster *e, const hploc_cluster *l, uint32_t k,
                         uint32_t e_at)
{
	float dx = (l->hi[0] > e->hi[0] ? l->hi[0] : e->hi[0]) -
	           (l->lo[0] < e->lo[0] ? l->lo[0] : e->lo[0]);
	float dy = (l->hi[1] > e->hi[1] ? l->hi[1] : e->hi[1]) -
	           (l->lo[1] < e->lo[1] ? l->lo[1] : e->lo[1]);
	float dz = (l->hi[2] > e->hi[2] ? l->hi[2] : e->hi[2]) -
	           (l->lo[2] < e->lo[2] ? l->lo[2] : e->lo[2]);
	float d = hploc_half_area3(dx, dy, dz);
	uint32_t bits;

	d = d > 0 ? d : 0; /* -0 and NaN as 0 */
	memcpy(&bits, &d, sizeof(bits));
	return (bits & ~TIE_MASK) | k << 2 | (e_at & 1) << 1;
}

/* Each list position's nearest neighbour, into nn[]: every pair's key
 * once, offered to both. */
static void nearest(const hploc *h, const uint32_t *list, uint32_t m, uint32_t *nn)
{
	uint32_t best[HPLOC_MAX_LIST];

	for (uint32_t i = 0; i < m; i++)
		best[i] = UINT32_MAX;
	for (uint32_t i = 0; i < m; i++) {
		uint32_t count = m - 1 - i < h->radius ? m - 1 - i : h->radius;

		for (uint32_t k = 0; k < count; k++) {
			uint32_t key = pair_key(&h->cl[list[i]], &h->cl[list[i + 1 + k]], k, i);

			best[i + 1 + k] = key < best[i + 1 + k] ? key : best[i + 1 + k];
			best[i] = (key | 1) < best[i] ? key | 1 : best[i];
		}
	}
	for (uint32_t i = 0; i < m; i++) {
		uint32_t apart = 1 + ((best[i] & TIE_MASK) >> 2);

		nn[i] = best[i] & 1 ? i + apart : i - apart;
	}
}

/* Clusters a (earlier) and b merge: the record at b's slot, the union
 * kept at a; the SAH decision as ploc_cluster.c's merge_cost. */
static void merge(hploc *h, uint32_t a, uint32_t b)
{
	hploc_cluster *x = &h->cl[a], *y = &h->cl[b];
	hploc_rec *r = &h->rec[b];
	uint32_t prims = (x->info & HPLOC_PRIMS) + (y->info & HPLOC_PRIMS);

	for (int k = 0; k < 3; k++) {
		r->lo[k] = bvhlab_minf(x->lo[k], y->lo[k]);
		r->hi[k] = bvhlab_maxf(x->hi[k], y->hi[k]);
	}
	float area = hploc_half_area3(r->hi[0] - r->lo[0], r->hi[1] - r->lo[1],
	                              r->hi[2] - r->lo[2]);
	float split = h->c_trav * area + x->cost + y->cost;
	float leaf = h->c_isect * (float)prims * area;
	bool collapsed = h->collapse && prims <= h->max_leaf && leaf <= split;

	r->left = x->node;
	r->right = y->node;
	r->info = prims | (collapsed ? HPLOC_COLLAPSED : 0);
	r->desc = collapsed ? 0 : 2 + x->desc + y->desc;
	memcpy(x->lo, r->lo, sizeof(x->lo));
	memcpy(x->hi, r->hi, sizeof(x->hi));
	x->node = b;
	x->info = r->info;
	x->cost = collapsed ? leaf : split;
	x->desc = r->desc;
}

/* One PLOC round over the list of m clusters: mutual pairs merge, the
 * survivors stay in order. Returns how many are left (fewer than m: the
 * least pair is mutual). */
static uint32_t round_merge(hploc *h, uint32_t *list, uint32_t m)
{
	uint32_t nn[HPLOC_MAX_LIST], left = 0;

	nearest(h, list, m, nn);
	for (uint32_t i = 0; i < m; i++) {
		uint32_t j = nn[i];

		if (nn[j] != i) {
			list[left++] = list[i];
		} else if (i < j) {
			merge(h, list[i], list[j]);
			list[left++] = list[i];
		}
	}
	return left;
}

/* Node [first, last], its right child from `split`: the children's
 * clusters merged down to the threshold, written back from idx[first]. */
static void finish_node(hploc *h, uint32_t first, uint32_t split, uint32_t last)
{
	uint32_t list[HPLOC_MAX_LIST];
	uint32_t lm = h->count[first], rm = h->count[split], m = lm + rm;
	uint32_t cap = first == 0 && last == h->n - 1 ? 1 : h->threshold;

	memcpy(list, h->idx + first, 4 * (size_t)lm);
	memcpy(list + lm, h->idx + split, 4 * (size_t)rm);
	while (m > cap)
		m = round_merge(h, list, m);
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
