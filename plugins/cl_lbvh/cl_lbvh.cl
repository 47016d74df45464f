/*
 * cl_lbvh's kernels (after morton_sort.cl): Karras 2012's hierarchy from
 * the sorted codes, the boxes bottom-up with atomic counters and the SAH
 * collapse decided on the way, then which internal nodes stay inner. Each
 * mirrors plugins/lbvh (lbvh_emit.c, lbvh_collapse.c): the same ranges and
 * splits, the same output slots (node i's children at 1 + 2i and 2 + 2i,
 * a node's own slot 1 + its parent word), the same float arithmetic in the
 * same order, so the tree is the CPU builder's, bit for bit.
 */
#define NO_NODE 0xffffffffu
#define NODE_LEAF 1u

/* bvhlab_node: 32 bytes. */
typedef struct node {
	float lo[3];
	uint first;
	float hi[3];
	uint count;
} node;

/* 1 + the common prefix length of sorted keys i and j, extended by their
 * positions where the codes are equal (Karras's k_i ++ i); -1 outside. */
static int delta(__global const ulong *keys, long n, long i, long j)
{
	/* Without branches: the searches below compare deltas a coin toss
	 * apart, and a mispredicted branch costs more than the arithmetic. */
	bool inside = j >= 0 && j < n;
	ulong x = keys[i] ^ keys[inside ? j : i];
	int d = x ? 1 + (int)clz(x) : 1 + 64 + (int)clz((uint)(i ^ j));
	return inside ? d : -1;
}

/* Node i of range [i, j] (either way) split after `split`: its range end
 * and its children's parent words, as lbvh_emit.c's karras_node. */
static void emit_node(uint i, uint j, uint split, uint n, __global uint *parent,
	__global uint *end)
{
	uint first = min(i, j), last = max(i, j), leaves = n - 1;
	end[i] = j;
	parent[split + (split == first ? leaves : 0)] = 2 * i;
	parent[split + 1 + (split + 1 == last ? leaves : 0)] = 2 * i + 1;
	if (i == 0)
		parent[0] = NO_NODE;
}

/* Internal node i: its range's other end and its split (the paper's
 * searches; lbvh_emit.c finds the same by scanning prefix lengths). */
__kernel void karras(__global const ulong *keys, uint n, __global uint *parent,
	__global uint *end)
{
	long i = get_global_id(0), nn = n;
	if (i >= nn - 1)
		return;
	int d = delta(keys, nn, i, i + 1) > delta(keys, nn, i, i - 1) ? 1 : -1;
	int dmin = delta(keys, nn, i, i - d);
	long lmax = 2;
	while (delta(keys, nn, i, i + lmax * d) > dmin)
		lmax <<= 1;
	long l = 0;
	for (long t = lmax >> 1; t >= 1; t >>= 1)
		l += delta(keys, nn, i, i + (l + t) * d) > dmin ? t : 0;
	long j = i + l * d;
	int dnode = delta(keys, nn, i, j);
	long s = 0, t = l;
	do {
		t = (t + 1) >> 1;
		s += delta(keys, nn, i, i + (s + t) * d) > dnode ? t : 0;
	} while (t > 1);
	emit_node((uint)i, (uint)j, (uint)(i + s * d + min(d, 0)), n, parent, end);
}

/*
 * The same hierarchy by lbvh_emit.c's scans, for a CPU device, where the
 * searches' scattered reads and data-dependent steps cost more than a
 * short scan: lcp[k] = delta(k, k + 1) as bytes (prefixes), then node i's
 * range grows towards its larger neighbour until lcp[] drops to the
 * smaller one, and the split is the one place in the range where lcp[]
 * equals delta(first, last) (karras_scan). 16 bytes a step, the place
 * inside the 16 that hold the answer by the lanes' bits (a little-endian
 * device's, as every CPU PoCL runs on); LCP_PAD zero bytes on either side
 * stop the scans.
 */
#define LCP_PAD 32

__kernel void prefixes(__global const ulong *keys, uint n, __global uchar *lcp_buf)
{
	uint k = get_global_id(0);
	__global uchar *lcp = lcp_buf + LCP_PAD;
	if (k < n - 1)
		lcp[k] = (uchar)delta(keys, n, k, k + 1);
	if (k < LCP_PAD) {
		lcp[(long)k - LCP_PAD] = 0;
		lcp[n - 1 + k] = 0;
	}
}

/* The first and the last of 16 lanes that hold (-1), as lbvh_emit.c
 * finds them with movemask and ctz: by the two 64-bit halves, no loop
 * over the bytes (whose exit a CPU mispredicts). 16 or -1 when none. */
static int first_lane(char16 m)
{
	ulong2 w = as_ulong2(m);
	ulong x = w.s0 ? w.s0 : w.s1;
	return x ? (w.s0 ? 0 : 8) + (63 - (int)clz(x & -x)) / 8 : 16;
}

static int last_lane(char16 m)
{
	ulong2 w = as_ulong2(m);
	ulong x = w.s1 ? w.s1 : w.s0;
	return x ? (w.s1 ? 15 : 7) - (int)clz(x) / 8 : -1;
}

__kernel void karras_scan(__global const ulong *keys, uint n, __global const uchar *lcp_buf,
	__global uint *parent, __global uint *end)
{
	long i = get_global_id(0), k;
	__global const uchar *lcp = lcp_buf + LCP_PAD;
	if (i >= (long)n - 1)
		return;
	uchar left = lcp[i - 1], right = lcp[i], bound = min(left, right);
	int lane;
	if (right > left) {
		for (k = i + 1; (lane = first_lane(vload16(0, lcp + k) <= bound)) == 16; k += 16)
			;
		k += lane;
	} else {
		for (k = i - 2; (lane = last_lane(vload16(0, lcp + k - 15) <= bound)) < 0; k -= 16)
			;
		k += lane - 15 + 1;
	}
	long first = min(i, k), last = max(i, k);
	uchar value = (uchar)delta(keys, n, first, last);
	long split = first;
	for (; (lane = first_lane(vload16(0, lcp + split) == value)) == 16; split += 16)
		;
	emit_node((uint)i, (uint)k, (uint)(split + lane), n, parent, end);
}

static float half_area(float lx, float ly, float lz, float hx, float hy, float hz)
{
	float dx = hx - lx, dy = hy - ly, dz = hz - lz;
	return dx * dy + dy * dz + dz * dx;
}

static float node_area(const node *x)
{
	return half_area(x->lo[0], x->lo[1], x->lo[2], x->hi[0], x->hi[1], x->hi[2]);
}

/* A child's SAH cost, area-weighted: a leaf's c_isect * N * A, or the cost
 * an inner child chose (lbvh_collapse.c's child_cost). */
static float child_cost(const node *c, __global const float *cost, float c_isect)
{
	if (c->count)
		return c_isect * (float)c->count * node_area(c);
	return cost[(c->first - 1) / 2];
}

static node load_node(volatile __global const node *p)
{
	node x;
	box_load(x.lo, x.hi, p->lo, p->hi);
	x.first = p->first;
	x.count = p->count;
	return x;
}

/* Both children of node p are done: its box, and with collapse the SAH
 * choice (ties to the leaf), as lbvh_collapse(). */
static node finish(volatile __global node *nodes, uint p, uint size, uint first,
	__global float *cost, __global uchar *flags, uint collapse, uint max_leaf,
	float c_trav, float c_isect)
{
	node l = load_node(nodes + 1 + 2 * (size_t)p), r = load_node(nodes + 2 + 2 * (size_t)p);
	node out;
	for (int k = 0; k < 3; k++) {
		out.lo[k] = l.lo[k] < r.lo[k] ? l.lo[k] : r.lo[k];
		out.hi[k] = l.hi[k] > r.hi[k] ? l.hi[k] : r.hi[k];
	}
	out.first = 1 + 2 * p;
	out.count = 0;
	if (!collapse || size > max_leaf)
		return out;
	float area = node_area(&out);
	float split_cost = c_trav * area + child_cost(&l, cost, c_isect) +
	                   child_cost(&r, cost, c_isect);
	float leaf_cost = c_isect * (float)size * area;
	if (leaf_cost <= split_cost) {
		out.first = first;
		out.count = size;
		flags[p] = NODE_LEAF;
	} else {
		cost[p] = split_cost;
	}
	return out;
}

static void store_node(volatile __global node *p, const node *x)
{
	box_store(p->lo, p->hi, x->lo, x->hi);
	p->first = x->first;
	p->count = x->count;
}

/* How far ahead a block's leaf loop fetches the boxes (lbvh_emit.c's
 * LEAF_AHEAD): a miss is some hundreds of nanoseconds, a leaf a few. On a
 * CPU (PoCL's device is compiled for the host) by the compiler's prefetch
 * instruction; elsewhere nothing: a GPU hides the misses by its many
 * work-items. */
#define LEAF_AHEAD 96
#if defined(__x86_64__) || defined(__aarch64__)
#define PREFETCH(p) __builtin_prefetch((p))
#else
#define PREFETCH(p) ((void)(p))
#endif

/* Leaf k's slot: primitive order[k]'s box, and its id into prim_index.
 * The boxes are the one random read of the build (input order to sorted
 * order); the leaves of a block are put in a loop of their own, with
 * nothing else to wait for, so that many of those misses are in flight at
 * once (lbvh_emit.c's leaf loop, for the same reason). */
static void put_leaf(__global const float *prim_bounds, __global const uint *order,
	__global const uint *parent, uint n, uint k, volatile __global node *nodes,
	__global uint *prim_index)
{
	uint id = order[k];
	__global const float *b = prim_bounds + 6 * (size_t)id;
	node leaf = { { b[0], b[1], b[2] }, k, { b[3], b[4], b[5] }, 1 };
	store_node(nodes + 1 + (size_t)parent[n - 1 + k], &leaf);
	prim_index[k] = id;
}

/*
 * Work-item t takes the leaves [lo, hi) = [t * block, + block): their
 * slots, then a climb from each while it arrives second at a parent; the
 * first arrival stops. A parent whose range lies inside [lo, hi) is
 * reached by this work-item alone, left child first (leaves in order), so
 * it needs no counter; the others take the atomic one, whose fences hand
 * the first child's slot over. block is 1 on a GPU (a work-item per leaf),
 * larger on a CPU device, where it keeps the climbs in cache and off the
 * atomics (lbvh_emit.c's blocks). order[] is the sorted primitive ids;
 * visits[] and flags[] zeroed.
 */
__kernel void bounds(__global const float *prim_bounds, __global const uint *order,
	__global uint *prim_index, uint n, uint block,
	__global const uint *parent, __global const uint *end, volatile __global node *nodes,
	volatile __global uint *visits, __global float *cost, __global uchar *flags,
	uint collapse, uint max_leaf, float c_trav, float c_isect)
{
	size_t lo = get_global_id(0) * (size_t)block, hi = min((size_t)n, lo + block);
	for (size_t k = lo; k < hi; k++) {
		if (k + LEAF_AHEAD < hi)
			PREFETCH(prim_bounds + 6 * (size_t)order[k + LEAF_AHEAD]);
		put_leaf(prim_bounds, order, parent, n, (uint)k, nodes, prim_index);
	}
	for (size_t k = lo; k < hi; k++) {
		uint word = parent[n - 1 + k];
		while (word != NO_NODE) {
			uint p = word >> 1, e = end[p];
			uint first = min(p, e), size = max(p, e) - first + 1;
			if (first >= lo && first + size <= hi) {
				if (!(word & 1))
					break;
			} else {
				mem_fence(CLK_GLOBAL_MEM_FENCE);
				if (atomic_inc(&visits[p]) == 0)
					break;
				mem_fence(CLK_GLOBAL_MEM_FENCE);
			}
			node x = finish(nodes, p, size, first, cost, flags, collapse, max_leaf,
			                c_trav, c_isect);
			word = parent[p];
			store_node(nodes + (word == NO_NODE ? 0 : 1 + (size_t)word), &x);
		}
	}
}

/* inner[i]: internal node i stays inner in the output: it did not become
 * a leaf and no ancestor did. Only nodes of at most max_leaf primitives
 * can have, so the climb stops at the first larger one. */
__kernel void inner_nodes(__global const uint *parent, __global const uint *end,
	__global const uchar *flags, uint n, uint max_leaf, __global uchar *inner)
{
	uint i = get_global_id(0);
	if (i >= n - 1)
		return;
	uchar keep = flags[i] != NODE_LEAF;
	uint j = i;
	while (keep && parent[j] != NO_NODE) {
		uint p = parent[j] >> 1, e = end[p];
		if (max(p, e) - min(p, e) + 1 > max_leaf)
			break;
		keep = flags[p] != NODE_LEAF;
		j = p;
	}
	inner[i] = keep;
}
