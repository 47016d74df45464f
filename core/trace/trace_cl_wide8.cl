/*
 * The compressed 8-wide device traversal ({"name": "wide8", "device":
 * true}, results' device_wide8): the tree as cwbvh_node.h's 80-byte nodes
 * (cwbvh.c), traced as Ylitie, Karras and Laine (HPG 2017) trace them, one
 * work-item per ray, closest or any hit. Follows trace_cl.cl in the
 * program and uses its ray, slab and triangle code, so a leaf's triangles
 * are tested as the stack kernel tests them (the same hit, t, u and v);
 * only the box tests differ, on the quantised boxes, which hold the exact
 * ones.
 *
 * A node's hit children form a group (the paper's node group): the first
 * inner child's node, and a bit mask whose bits 24..31 are the inner slots
 * still to visit, slot s at bit 24 + (s ^ oinv), so that taking the
 * highest bit first visits the slots in the ray's octant order (the slot
 * on the side the ray comes from first), and whose bits 0..7 are the
 * node's imask (an inner child's node is the first plus the inner slots
 * before its own). A group with slots left waits on the stack while the
 * next child is entered; there is no entry distance to cull it by, the
 * child's own box tests use the closest hit so far. The hit leaves of a
 * node are tested as soon as it is entered (the paper's triangle group;
 * a ray of this kernel has no warp to wait for).
 */

/* The slots of node n that the ray enters before tmax: the inner ones as
 * the next group, the leaves as bits (range offsets) of *leaf_bits. */
static uint2 cw_visit(const prep *p, const __global cw_node *n, float tmax, uint oinv,
                      uint *leaf_bits)
{
	uint inner = 0, leaves = 0;
	for (uint s = 0; s < CW_WIDTH; s++) {
		uchar meta = n->meta[s];
		float f[8] = {0, 0, 0, 0, 0, 0, 0, 0};
		if (meta == 0)
			continue;
		for (int k = 0; k < 3; k++) {
			f[k] = cw_plane(n, k, n->qlo[k][s]);
			f[4 + k] = cw_plane(n, k, n->qhi[k][s]);
		}
		if (slab(p, f, tmax) == INFINITY)
			continue;
		if (cw_is_inner(meta))
			inner |= 1u << (CW_META_INNER_BASE + (s ^ oinv));
		else
			leaves |= 1u << (meta & 31u);
	}
	*leaf_bits = leaves;
	return (uint2)(n->child_base, inner | n->imask);
}

/* The leaf ranges base + each bit of bits; true when an any-hit ray may
 * stop. */
static bool cw_leaves(const prep *p, __global const float *tris,
                      __global const uint *prim_index, __global const uint2 *ranges, uint base,
                      uint bits, uint index_count, uint tri_count, bool any, hit *h,
                      uint *tests)
{
	for (; bits; bits &= bits - 1) {
		uint2 r = ranges[base + 31 - clz(bits & (0u - bits))];
		if (leaf_range(p, tris, prim_index, r.x, r.y, index_count, tri_count, any, h, tests))
			return true;
	}
	return false;
}

/* The ray's octant as the slot order's flip: the slot of the octant the
 * ray comes from (each axis the side against its direction) is visited
 * first. */
static uint cw_octant_flip(const prep *p)
{
	uint from = 0;
	for (int k = 0; k < 3; k++)
		from |= (uint)(p->near[k] >= 4) << k; /* negative direction: enters at +k */
	return 7u ^ from;
}

/* The walk of one compressed tree (node_total nodes, its leaf ranges)
 * from its root; counted as walk_stack; false when the stack overflowed
 * (deeper than the host said). */
static bool walk_cw(const prep *p, __global const cw_node *cw, __global const uint2 *ranges,
                    __global const float *tris, __global const uint *prim_index,
                    uint node_total, uint index_count, uint tri_count, bool any, hit *h,
                    uint *visited, uint *tests)
{
	uint sp = 0;
	uint2 stack[STACK_SIZE];
	uint oinv = cw_octant_flip(p);
	/* the root as the one inner child (slot 0) of a group with node 0 first */
	uint2 group = (uint2)(0, 1u << (CW_META_INNER_BASE + oinv) | 1u);
	for (;;) {
		uint inner = group.y & 0xff000000u;
		if (!inner) {
			if (sp == 0)
				return true;
			group = stack[--sp];
			continue;
		}
		uint bit = 31 - clz(inner);
		group.y &= ~(1u << bit);
		uint slot = (bit - CW_META_INNER_BASE) ^ oinv;
		uint node = group.x + popcount(group.y & 0xffu & ((1u << slot) - 1u));
		if (group.y & 0xff000000u) {
			if (sp == STACK_SIZE)
				return false;
			stack[sp++] = group;
		}
		if (node >= node_total || !enter_node(node_total, visited))
			return true;
		uint leaf_bits;
		group = cw_visit(p, &cw[node], h->t, oinv, &leaf_bits);
		if (cw_leaves(p, tris, prim_index, ranges, cw[node].leaf_base, leaf_bits, index_count,
		              tri_count, any, h, tests))
			return true;
	}
}

/* The arguments in enum trace_arg's order: nodes the compressed nodes
 * (node_total of them), and in the parents' place the leaf ranges. */
__kernel void trace_wide8(__global const cw_node *cw, __global const float *tris,
                          __global const uint *prim_index, __global const uint2 *ranges,
                          uint node_total, uint index_count, uint tri_count,
                          __global const float4 *rays, uint ray_count, uint any,
                          __global uint4 *hits, __global uint2 *counts)
{
	uint i = get_global_id(0), visited = 0, tests = 0;
	hit h;
	prep p;
	if (i >= ray_count)
		return;
	if (ray_load(rays, i, &p, &h) && node_total != 0 &&
	    !walk_cw(&p, cw, ranges, tris, prim_index, node_total, index_count, tri_count, any, &h,
	             &visited, &tests))
		visited = TRACE_OVERFLOW;
	store(hits, counts, i, &h, visited, tests);
}
