/*
 * cl_ploc's kernels (after morton_sort.cl): PLOC's iterations (Meister &
 * Bittner 2018) as plugins/ploc does them (ploc_cluster.c), so the merge
 * tree is the CPU builder's: the same distance, the same candidate keys
 * (the distance's float bits with the lowest 8 given up for the tie
 * order), the same merges, positions and records, the same SAH collapse
 * arithmetic. Per iteration over m clusters: nearest (one work-item per
 * cluster, its `radius` neighbours on either side), count and write (one
 * work-item per chunk of clusters, in order), with a prefix over the
 * chunks between them (prefix, one work-item).
 *
 * The cluster count lives on the device, by iteration parity cur: state[cur]
 * clusters now, state[2 + cur] the top of the record pairs; prefix writes
 * the next ones at 1 - cur and 3 - cur. So the host may queue several
 * iterations without reading the count back, launching for a bound on it:
 * work-items past the count do nothing, and an iteration queued after one
 * cluster is left only carries it to the other buffer.
 */
#define REC_PRIM 0x80000000u
#define REC_COLLAPSED 0x40000000u
#define REC_PRIMS 0x3fffffffu
#define TIE_MASK 0xffu

/* A cluster: its box and ploc.h's struct cluster_meta. */
typedef struct cluster {
	float lo[3];
	uint first; /* its record's first: the pair of an inner one, a primitive's id */
	float hi[3];
	uint info;  /* REC_* | primitives */
	float cost; /* the subtree's SAH cost, area-weighted */
	uint desc;  /* output nodes below the cluster's own */
} cluster;

/* A record of the merge tree: bvhlab_node's layout, count = info. */
typedef struct record {
	float lo[3];
	uint first;
	float hi[3];
	uint count;
} record;

static float half_area3(float dx, float dy, float dz)
{
	return dx * dy + dy * dz + dz * dx;
}

/* One cluster per primitive, in sorted order. */
__kernel void first_clusters(__global const float *prim_bounds, __global const uint *order,
	uint n, float c_isect, __global cluster *c)
{
	uint k = get_global_id(0);
	if (k >= n)
		return;
	uint id = order[k];
	__global const float *b = prim_bounds + 6 * (size_t)id;
	cluster x = { { b[0], b[1], b[2] }, id, { b[3], b[4], b[5] }, 1 | REC_PRIM, 0, 0 };
	x.cost = c_isect * half_area3(b[3] - b[0], b[4] - b[1], b[5] - b[2]);
	c[k] = x;
}

/* The key of the pair (e, l), e earlier by k + 1 positions, as the later
 * cluster sees it (ploc_cluster.c's key_row). */
static uint pair_key(__global const cluster *e, __global const cluster *l, uint k, uint e_index)
{
	float dx = (l->hi[0] > e->hi[0] ? l->hi[0] : e->hi[0]) -
	           (l->lo[0] < e->lo[0] ? l->lo[0] : e->lo[0]);
	float dy = (l->hi[1] > e->hi[1] ? l->hi[1] : e->hi[1]) -
	           (l->lo[1] < e->lo[1] ? l->lo[1] : e->lo[1]);
	float dz = (l->hi[2] > e->hi[2] ? l->hi[2] : e->hi[2]) -
	           (l->lo[2] < e->lo[2] ? l->lo[2] : e->lo[2]);
	float d = half_area3(dx, dy, dz);
	d = d > 0 ? d : 0; /* -0 and NaN as 0 */
	return (as_uint(d) & ~TIE_MASK) | k << 2 | (e_index & 1) << 1;
}

__kernel void nearest(__global const cluster *c, __global const uint *state, uint cur,
	uint radius, __global uint *nn)
{
	uint i = get_global_id(0), best = 0xffffffffu, m = state[cur];
	if (i >= m || m < 2)
		return;
	for (uint k = 0; k < radius && k < i; k++)
		best = min(best, pair_key(c + i - 1 - k, c + i, k, i - 1 - k));
	for (uint k = 0; k < radius && i + 1 + k < m; k++)
		best = min(best, pair_key(c + i, c + i + 1 + k, k, i) | 1);
	uint apart = 1 + ((best & TIE_MASK) >> 2);
	nn[i] = best & 1 ? i + apart : i - apart;
}

/*
 * The same nearest neighbours by blocks, for a CPU device: work-item t
 * takes clusters [lo, hi) = [t * block, + block) and computes each pair's
 * key once, in the row of its earlier cluster, offering it to both
 * (ploc_cluster.c's nearest_block, rows from lo - radius on): half the
 * distances of nearest(), read in order. block <= NN_BLOCK_MAX.
 */
#define NN_BLOCK_MAX 256u
#define NN_RADIUS_MAX 64u

__kernel void nearest_blocks(__global const cluster *c, __global const uint *state,
	uint cur, uint radius, uint block, __global uint *nn)
{
	uint best[NN_BLOCK_MAX + 2 * NN_RADIUS_MAX];
	uint lo = get_global_id(0) * block, m = state[cur];
	if (lo >= m || m < 2)
		return;
	uint hi = min(m, lo + block), from = lo > radius ? lo - radius : 0;
	for (uint k = 0; k < hi + radius - from; k++)
		best[k] = 0xffffffffu;
	for (uint i = from; i < hi; i++) {
		uint count = min(m - 1 - i, radius), least = 0xffffffffu;
		for (uint k = 0; k < count; k++) {
			uint key = pair_key(c + i, c + i + 1 + k, k, i);
			least = min(least, key);
			best[i + 1 + k - from] = min(best[i + 1 + k - from], key);
		}
		best[i - from] = min(best[i - from], least | 1);
	}
	for (uint i = lo; i < hi; i++) {
		uint w = best[i - from], apart = 1 + ((w & TIE_MASK) >> 2);
		nn[i] = w & 1 ? i + apart : i - apart;
	}
}

/* Merges (counted at the earlier cluster) and survivors of each chunk. */
__kernel void count_chunks(__global const uint *nn, __global const uint *state, uint cur,
	uint chunk, uint chunks, __global uint *counts)
{
	uint c = get_global_id(0), merges = 0, survivors = 0, m = state[cur];
	if (c >= chunks)
		return;
	uint lo = c * chunk, hi = m < 2 ? lo : min(m, lo + chunk);
	if (m < 2 && c == 0) /* done: the last cluster survives */
		survivors = m;
	for (uint i = lo; i < hi; i++) {
		uint j = nn[i];
		bool pair = nn[j] == i;
		merges += pair && i < j;
		survivors += !pair || i < j;
	}
	counts[2 * c] = merges;
	counts[2 * c + 1] = survivors;
}

/* Each chunk's first survivor position and the top of its record pairs
 * (pairs go downwards from the top, state[2 + cur]); the clusters left
 * and the new top go to the other parity's state[1 - cur], state[3 - cur].
 * One work-item. */
__kernel void prefix(__global uint *counts, uint chunks, __global uint *state, uint cur)
{
	uint merges = 0, survivors = 0, base = state[2 + cur];
	if (get_global_id(0) != 0)
		return;
	for (uint c = 0; c < chunks; c++) {
		uint mc = counts[2 * c], sc = counts[2 * c + 1];
		counts[2 * c] = base - 2 * merges;
		counts[2 * c + 1] = survivors;
		merges += mc;
		survivors += sc;
	}
	state[1 - cur] = survivors;
	state[3 - cur] = base - 2 * merges;
}

static void put_record(__global const cluster *c, __global record *tree, __global uint *desc,
	uint x)
{
	record r = { { c->lo[0], c->lo[1], c->lo[2] }, c->first,
	             { c->hi[0], c->hi[1], c->hi[2] }, c->info };
	tree[x] = r;
	desc[x] = c->desc;
}

/* Clusters a < b merge: records at x, x + 1, the union (ploc_cluster.c's
 * merge and merge_cost). */
static cluster merged(__global const cluster *a, __global const cluster *b, uint x,
	uint collapse, uint max_leaf, float c_trav, float c_isect)
{
	cluster u;
	for (int k = 0; k < 3; k++) {
		u.lo[k] = a->lo[k] < b->lo[k] ? a->lo[k] : b->lo[k];
		u.hi[k] = a->hi[k] > b->hi[k] ? a->hi[k] : b->hi[k];
	}
	u.first = x;
	uint prims = (a->info & REC_PRIMS) + (b->info & REC_PRIMS);
	float area = half_area3(u.hi[0] - u.lo[0], u.hi[1] - u.lo[1], u.hi[2] - u.lo[2]);
	float split = c_trav * area + a->cost + b->cost;
	float leaf = c_isect * (float)prims * area;
	if (collapse && prims <= max_leaf && leaf <= split) {
		u.info = prims | REC_COLLAPSED;
		u.cost = leaf;
		u.desc = 0;
	} else {
		u.info = prims;
		u.cost = split;
		u.desc = 2 + a->desc + b->desc;
	}
	return u;
}

__kernel void write_chunks(__global const cluster *c, __global const uint *nn,
	__global const uint *state, uint cur, uint chunk, uint chunks,
	__global const uint *counts, __global cluster *to, __global record *tree,
	__global uint *desc, uint collapse, uint max_leaf, float c_trav, float c_isect)
{
	uint ch = get_global_id(0), m = state[cur];
	if (ch >= chunks)
		return;
	if (m < 2) { /* done: the last cluster moves along with the parity */
		if (ch == 0 && m == 1)
			to[0] = c[0];
		return;
	}
	uint lo = ch * chunk, hi = min(m, lo + chunk);
	uint pair = counts[2 * ch], k = counts[2 * ch + 1];
	for (uint i = lo; i < hi; i++) {
		uint j = nn[i];
		if (nn[j] != i) {
			to[k++] = c[i];
		} else if (i < j) {
			pair -= 2;
			put_record(c + i, tree, desc, pair);
			put_record(c + j, tree, desc, pair + 1);
			to[k++] = merged(c + i, c + j, pair, collapse, max_leaf, c_trav, c_isect);
		}
	}
}
