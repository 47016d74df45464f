/*
 * cl_hploc's kernel (after morton_sort.cl): H-PLOC (Benthin et al. 2024)
 * in one launch, as plugins/hploc does it (hploc_climb.c), so the merge
 * tree is the CPU builder's: the same climb of the radix tree (a range
 * joins the neighbour it shares the longer prefix with, the prefixes of
 * the full codes extended by the positions), the same PLOC rounds in each
 * node's list (the same candidate keys, with ploc's tie order), the same
 * union and SAH collapse arithmetic in the same order, the same record
 * slots (the merged-away cluster's representative).
 *
 * One work-item per leaf; the first arrival at a node stops, the second
 * (the atomic exchange of meet[], between fences, hands the first one's
 * clusters over) merges the node's list alone: the paper's warp-wide
 * merging is not done here.
 */
#define HPLOC_LEAF 0x80000000u
#define HPLOC_COLLAPSED 0x40000000u
#define HPLOC_PRIMS 0x3fffffffu
#define HPLOC_NONE 0xffffffffu
#define TIE_MASK 0xffu
#define MAX_LIST 64u /* hploc.h's HPLOC_MAX_LIST */

/* hploc.h's hploc_cluster. */
typedef struct cluster {
	float lo[3];
	uint node;
	float hi[3];
	uint info;
	float cost;
	uint desc;
} cluster;

/* hploc_tree.h's hploc_rec. */
typedef struct record {
	float lo[3];
	uint left;
	float hi[3];
	uint right;
	uint info;
	uint desc;
} record;

static float half_area3(float dx, float dy, float dz)
{
	return dx * dy + dy * dz + dz * dx;
}

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

static cluster load(volatile __global const cluster *p)
{
	cluster x;
	for (int k = 0; k < 3; k++) {
		x.lo[k] = p->lo[k];
		x.hi[k] = p->hi[k];
	}
	x.node = p->node;
	x.info = p->info;
	x.cost = p->cost;
	x.desc = p->desc;
	return x;
}

static void store(volatile __global cluster *p, const cluster *x)
{
	for (int k = 0; k < 3; k++) {
		p->lo[k] = x->lo[k];
		p->hi[k] = x->hi[k];
	}
	p->node = x->node;
	p->info = x->info;
	p->cost = x->cost;
	p->desc = x->desc;
}

/* hploc_climb.c's pair_key. */
static uint pair_key(const cluster *e, const cluster *l, uint k, uint e_at)
{
	float dx = (l->hi[0] > e->hi[0] ? l->hi[0] : e->hi[0]) -
	           (l->lo[0] < e->lo[0] ? l->lo[0] : e->lo[0]);
	float dy = (l->hi[1] > e->hi[1] ? l->hi[1] : e->hi[1]) -
	           (l->lo[1] < e->lo[1] ? l->lo[1] : e->lo[1]);
	float dz = (l->hi[2] > e->hi[2] ? l->hi[2] : e->hi[2]) -
	           (l->lo[2] < e->lo[2] ? l->lo[2] : e->lo[2]);
	float d = half_area3(dx, dy, dz);
	d = d > 0 ? d : 0; /* -0 and NaN as 0 */
	return (as_uint(d) & ~TIE_MASK) | k << 2 | (e_at & 1) << 1;
}

/* hploc_climb.c's nearest, over private copies of the list's clusters. */
static void nearest(const cluster *c, uint m, uint radius, uint *nn)
{
	uint best[MAX_LIST];
	for (uint i = 0; i < m; i++)
		best[i] = 0xffffffffu;
	for (uint i = 0; i < m; i++) {
		uint count = min(m - 1 - i, radius);
		for (uint k = 0; k < count; k++) {
			uint key = pair_key(c + i, c + i + 1 + k, k, i);
			best[i + 1 + k] = min(best[i + 1 + k], key);
			best[i] = min(best[i], key | 1);
		}
	}
	for (uint i = 0; i < m; i++) {
		uint apart = 1 + ((best[i] & TIE_MASK) >> 2);
		nn[i] = best[i] & 1 ? i + apart : i - apart;
	}
}

/* The SAH collapse's parameters. */
typedef struct sah {
	uint collapse, max_leaf;
	float c_trav, c_isect;
} sah;

/* hploc_climb.c's merge: x (earlier) and y, the record at y's slot. */
static void merge(cluster *x, const cluster *y, uint slot, __global record *rec, sah s)
{
	record r;
	uint prims = (x->info & HPLOC_PRIMS) + (y->info & HPLOC_PRIMS);
	for (int k = 0; k < 3; k++) {
		r.lo[k] = x->lo[k] < y->lo[k] ? x->lo[k] : y->lo[k];
		r.hi[k] = x->hi[k] > y->hi[k] ? x->hi[k] : y->hi[k];
	}
	float area = half_area3(r.hi[0] - r.lo[0], r.hi[1] - r.lo[1], r.hi[2] - r.lo[2]);
	float split = s.c_trav * area + x->cost + y->cost;
	float leaf = s.c_isect * (float)prims * area;
	bool collapsed = s.collapse && prims <= s.max_leaf && leaf <= split;
	r.left = x->node;
	r.right = y->node;
	r.info = prims | (collapsed ? HPLOC_COLLAPSED : 0);
	r.desc = collapsed ? 0 : 2 + x->desc + y->desc;
	rec[slot] = r;
	for (int k = 0; k < 3; k++) {
		x->lo[k] = r.lo[k];
		x->hi[k] = r.hi[k];
	}
	x->node = slot;
	x->info = r.info;
	x->cost = collapsed ? leaf : split;
	x->desc = r.desc;
}

/* One PLOC round: mutual pairs merge, survivors kept in order. */
static uint round_merge(cluster *c, uint *list, uint m, uint radius, __global record *rec,
	sah s)
{
	uint nn[MAX_LIST], left = 0;
	nearest(c, m, radius, nn);
	for (uint i = 0; i < m; i++) {
		uint j = nn[i];
		if (nn[j] != i) {
			c[left] = c[i];
			list[left++] = list[i];
		} else if (i < j) {
			merge(c + i, c + j, list[j], rec, s);
			c[left] = c[i];
			list[left++] = list[i];
		}
	}
	return left;
}

/* hploc_climb.c's finish_node: the children's clusters merged down to
 * cap; returns the first survivor's node word. */
static uint finish_node(volatile __global cluster *cl, volatile __global uint *idx,
	volatile __global uint *count, uint first, uint split, uint cap, uint radius,
	__global record *rec, sah s)
{
	uint list[MAX_LIST];
	cluster c[MAX_LIST];
	uint lm = count[first], rm = count[split], m = lm + rm;
	for (uint i = 0; i < lm; i++)
		list[i] = idx[first + i];
	for (uint i = 0; i < rm; i++)
		list[lm + i] = idx[split + i];
	if (m > cap) {
		for (uint i = 0; i < m; i++)
			c[i] = load(cl + list[i]);
		while (m > cap)
			m = round_merge(c, list, m, radius, rec, s);
		for (uint i = 0; i < m; i++)
			store(cl + list[i], c + i);
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
	uint max_leaf, float c_trav, float c_isect, volatile __global cluster *cl,
	volatile __global uint *idx, volatile __global uint *count,
	volatile __global uint *meet, __global record *rec, __global uint *root)
{
	uint k = get_global_id(0);
	if (k >= n)
		return;
	sah s = { collapse, max_leaf, c_trav, c_isect };
	uint id = order[k];
	__global const float *b = prim_bounds + 6 * (size_t)id;
	cluster x = { { b[0], b[1], b[2] }, HPLOC_LEAF | id, { b[3], b[4], b[5] }, 1, 0, 0 };
	x.cost = c_isect * half_area3(b[3] - b[0], b[4] - b[1], b[5] - b[2]);
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
		top = finish_node(cl, idx, count, first, split, cap, radius, rec, s);
	}
	root[0] = top;
}
