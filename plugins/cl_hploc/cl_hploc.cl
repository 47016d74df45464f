/*
 * cl_hploc's kernel (after morton_sort.cl and plugins/hploc/hploc_merge.h):
 * H-PLOC (Benthin et al. 2024) in one launch, as plugins/hploc does it
 * (hploc_climb.c), so the merge tree is the CPU builder's: the same climb
 * of the radix tree (a range joins the neighbour it shares the longer
 * prefix with, the prefixes of the full codes extended by the positions,
 * as morton_common_prefix), and each node's merging by the same code
 * (hploc_merge.h: PLOC rounds with ploc's keys and ties, the union and
 * the SAH collapse, the record slots).
 *
 * One work-item per leaf; the first arrival at a node stops, the second
 * (the atomic exchange of meet[], between fences, hands the first one's
 * clusters over) merges the node's list alone: the paper's warp-wide
 * merging is not done here.
 */
#define HPLOC_NONE 0xffffffffu

/* morton_common_prefix of sorted positions k and k + 1. */
static uint prefix_after(__global const ulong *keys, uint k)
{
	ulong x = keys[k] ^ keys[k + 1];
	return x ? 1 + (uint)clz(x) : 1 + 64 + (uint)clz(k ^ (k + 1));
}

static bool joins_right(__global const ulong *keys, uint n, uint first, uint last)
{
	if (first == 0)
		return true;
	if (last == n - 1)
		return false;
	return prefix_after(keys, last) > prefix_after(keys, first - 1);
}

static hploc_cluster load(volatile __global const hploc_cluster *p)
{
	hploc_cluster x;
	box_load(x.lo, x.hi, p->lo, p->hi);
	x.node = p->node;
	x.info = p->info;
	x.cost = p->cost;
	x.desc = p->desc;
	return x;
}

static void store(volatile __global hploc_cluster *p, const hploc_cluster *x)
{
	box_store(p->lo, p->hi, x->lo, x->hi);
	p->node = x->node;
	p->info = x->info;
	p->cost = x->cost;
	p->desc = x->desc;
}

/* hploc_climb.c's finish_node: the children's clusters merged down to
 * cap on private copies; returns the first survivor's node word. */
static uint finish_node(volatile __global hploc_cluster *cl, volatile __global uint *idx,
	volatile __global uint *count, uint first, uint split, uint cap,
	__global hploc_rec *rec, const hploc_params *p)
{
	uint list[HPLOC_MAX_LIST], slot[HPLOC_MAX_LIST], records;
	hploc_cluster c[HPLOC_MAX_LIST];
	hploc_rec made[HPLOC_MAX_LIST];
	uint lm = count[first], rm = count[split], m = lm + rm;
	for (uint i = 0; i < lm; i++)
		list[i] = idx[first + i];
	for (uint i = 0; i < rm; i++)
		list[lm + i] = idx[split + i];
	if (m > cap) {
		for (uint i = 0; i < m; i++)
			c[i] = load(cl + list[i]);
		m = hploc_merge_list(c, list, m, cap, p, made, slot, &records);
		for (uint i = 0; i < m; i++)
			store(cl + list[i], c + i);
		for (uint i = 0; i < records; i++)
			rec[slot[i]] = made[i];
	}
	for (uint i = 0; i < m; i++)
		idx[first + i] = list[i];
	count[first] = m;
	return cl[list[0]].node;
}

/* A work-item per leaf k: its cluster, then the climb while it arrives
 * second. meet[] holds HPLOC_NONE; root[0] gets the root's node word. */
__kernel void hploc_climb(__global const float *prim_bounds, __global const uint *order,
	__global const ulong *keys, uint n, uint radius, uint threshold, uint collapse,
	uint max_leaf, float c_trav, float c_isect, volatile __global hploc_cluster *cl,
	volatile __global uint *idx, volatile __global uint *count,
	volatile __global uint *meet, __global hploc_rec *rec, __global uint *root)
{
	uint k = get_global_id(0);
	if (k >= n)
		return;
	hploc_params p = { radius, collapse, max_leaf, c_trav, c_isect };
	uint id = order[k];
	__global const float *b = prim_bounds + 6 * (size_t)id;
	hploc_cluster x = { { b[0], b[1], b[2] }, HPLOC_LEAF | id, { b[3], b[4], b[5] }, 1, 0, 0 };
	x.cost = c_isect * hploc_half_area(x.lo, x.hi);
	store(cl + k, &x);
	idx[k] = k;
	count[k] = 1;
	uint first = k, last = k, top = 0;
	while (first > 0 || last < n - 1) {
		uint other, split;
		mem_fence(CLK_GLOBAL_MEM_FENCE);
		if (joins_right(keys, n, first, last)) {
			other = atomic_xchg(&meet[last], first);
			split = last + 1;
			last = other;
		} else {
			other = atomic_xchg(&meet[first - 1], last);
			split = first;
			first = other;
		}
		if (other == HPLOC_NONE)
			return;
		mem_fence(CLK_GLOBAL_MEM_FENCE);
		uint cap = first == 0 && last == n - 1 ? 1 : threshold;
		top = finish_node(cl, idx, count, first, split, cap, rec, &p);
	}
	root[0] = top;
}
