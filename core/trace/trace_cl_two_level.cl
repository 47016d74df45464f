/*
 * The device traversals of a two-level scene (trace_cl_two_level.c;
 * docs/instances.md): trace_instances.c on the device, one work-item per
 * ray, closest hits. The top tree is walked as the CPU walks it (stack:
 * every child the ray enters pushed, nearest last, its box tested again
 * when popped; stackless: trace_stackless.c's walk with the parent
 * links); at a top leaf each instance's ray is carried into its space by
 * its inverse matrix in double, as local_ray() does, rounded to float,
 * and its bottom tree is walked by the one-level kernels' walks
 * (walk_stack, walk_stackless, walk_cw) with tmax one ulp past the best t
 * so far. The same rounding at every step as the CPU's, so a ray gets the
 * same instance, triangle, t, u and v bit for bit. Follows trace_cl.cl and
 * trace_cl_wide8.cl in the program.
 *
 * Needs doubles (cl_khr_fp64) for the matrix: on a device without them
 * the program has no two-level kernels, and the host says why.
 */
#ifdef cl_khr_fp64

#define TWO_LEVEL_STACK 0
#define TWO_LEVEL_STACKLESS 1
#define TWO_LEVEL_WIDE8 2

/* The bottom trees, every mesh's one after another, and the instances. */
typedef struct bottoms {
	__global const void *nodes; /* tree_node, or cw_node for wide8 */
	__global const float *tris;
	__global const uint *prim_index;
	__global const uint *links; /* parent links, or wide8's leaf ranges (uint2) */
	__global const uint *meshes;
	__global const double *inverse;
	__global const uint *inst_mesh;
	uint instance_count;
	int mode;
} bottoms;

typedef struct top_tree {
	__global const tree_node *nodes;
	__global const uint *index, *parents;
	uint count, index_count;
} top_tree;

/* The best hit so far and its instance. */
typedef struct best_hit {
	hit h;
	uint instance;
} best_hit;

/* offer(): a nearer hit, or one as near and earlier in (instance,
 * primitive) order, the flattened scene's primitive order. */
static void offer(best_hit *best, const hit *h, uint i)
{
	if (h->prim == NO_HIT || h->t > best->h.t)
		return;
	if (h->t == best->h.t && best->h.prim != NO_HIT &&
	    (i > best->instance || (i == best->instance && h->prim >= best->h.prim)))
		return;
	best->h = *h;
	best->instance = i;
}

/* local_ray(): the world ray (o, d) in the space of the instance whose
 * world-to-object matrix is m, prepared; false as prep_ray. */
static bool local_prep(float4 o, float4 d, __global const double *m, prep *p)
{
	double od[3] = {o.x, o.y, o.z}, dd[3] = {d.x, d.y, d.z};
	float lo[3], ld[3];
	for (int r = 0; r < 3; r++) {
		lo[r] = (float)(m[4 * r] * od[0] + m[4 * r + 1] * od[1] + m[4 * r + 2] * od[2] +
		                m[4 * r + 3] * 1.0);
		ld[r] = (float)(m[4 * r] * dd[0] + m[4 * r + 1] * dd[1] + m[4 * r + 2] * dd[2] +
		                m[4 * r + 3] * 0.0);
	}
	return prep_ray((float4)(lo[0], lo[1], lo[2], o.w), (float4)(ld[0], ld[1], ld[2], 0.0f), p);
}

/* enter_instance(): instance i's bottom tree with the ray in its space;
 * false when its walk overflowed the stack. */
static bool enter_instance(float4 o, float4 d, uint i, const bottoms *b, best_hit *best,
                           uint *visited, uint *tests)
{
	__global const uint *m = b->meshes + TRACE_MESH_FIELDS * (size_t)b->inst_mesh[i];
	uint count = m[TRACE_MESH_NODES], slots = m[TRACE_MESH_SLOTS], tris = m[TRACE_MESH_TRIS];
	uint seen = 0;
	bool ok = true;
	prep p;
	hit h = {nextafter(best->h.t, INFINITY), 0.0f, 0.0f, NO_HIT};
	if (count == 0 || !local_prep(o, d, b->inverse + 12 * (size_t)i, &p))
		return true;
	__global const float *v = b->tris + TRACE_SLOT_FLOATS * (size_t)m[TRACE_MESH_SLOT_BASE];
	__global const uint *ix = b->prim_index + m[TRACE_MESH_SLOT_BASE];
	__global const uint *links = b->links;
	if (b->mode == TWO_LEVEL_WIDE8) {
		__global const cw_node *cw = (__global const cw_node *)b->nodes + m[TRACE_MESH_NODE_BASE];
		__global const uint2 *ranges = (__global const uint2 *)links + m[TRACE_MESH_LINK_BASE];
		ok = walk_cw(&p, cw, ranges, v, ix, count, slots, tris, false, &h, &seen, tests);
	} else {
		NODES = (__global const tree_node *)b->nodes + m[TRACE_MESH_NODE_BASE];
		if (box_enter(&p, nodes, 0, h.t) == INFINITY)
			return true;
		if (b->mode == TWO_LEVEL_STACK)
			ok = walk_stack(&p, nodes, v, ix, count, slots, tris, false, &h, &seen, tests);
		else
			walk_stackless(&p, nodes, links + m[TRACE_MESH_LINK_BASE], v, ix, count, slots,
			               tris, false, &h, &seen, tests);
	}
	*visited += seen;
	offer(best, &h, i);
	return ok;
}

/* enter_leaf(): a top leaf's instances, each traced. */
static bool top_leaf(float4 o, float4 d, const top_tree *top, const __global tree_node *n,
                     const bottoms *b, best_hit *best, uint *visited, uint *tests)
{
	uint first = tree_leaf_first(n), end = first + tree_leaf_count(n);
	for (uint s = first; s < end && s < top->index_count; s++)
		if (top->index[s] < b->instance_count &&
		    !enter_instance(o, d, top->index[s], b, best, visited, tests))
			return false;
	return true;
}

/* push_children(): an inner top node's children the ray enters, pushed
 * farthest first; false past the stack the host sized. */
static bool top_push(const prep *p, const top_tree *top, const __global tree_node *n,
                     float tmax, uint *stack, uint *sp)
{
	uint k = tree_child_count(n), m = 0, node[TREE_MAX_WIDTH];
	float t[TREE_MAX_WIDTH];
	for (uint c = 0; c < k && c < TREE_MAX_WIDTH; c++) {
		uint child = tree_child(n, c);
		float tc = child < top->count ? box_enter(p, top->nodes, child, tmax) : INFINITY;
		if (tc == INFINITY)
			continue;
		uint j = m++; /* insertion by entry distance, nearest last */
		for (; j > 0 && t[j - 1] < tc; j--) {
			t[j] = t[j - 1];
			node[j] = node[j - 1];
		}
		t[j] = tc;
		node[j] = child;
	}
	for (uint j = 0; j < m; j++) {
		if (*sp == STACK_SIZE)
			return false;
		stack[(*sp)++] = node[j];
	}
	return true;
}

/* walk_stack() of trace_instances.c; false when a stack overflowed. A
 * node is popped at most once on a tree: past top->count pops the links
 * are not one, and the walk ends. */
static bool top_walk_stack(const prep *p, float4 o, float4 d, const top_tree *top,
                           const bottoms *b, best_hit *best, uint *visited, uint *tests)
{
	uint stack[STACK_SIZE], sp = 0, pops = 0;
	if (box_enter(p, top->nodes, 0, best->h.t) == INFINITY)
		return true;
	stack[sp++] = 0;
	while (sp > 0 && pops++ < top->count) {
		uint node = stack[--sp];
		const __global tree_node *n = &top->nodes[node];
		++*visited;
		if (box_enter(p, top->nodes, node, best->h.t) == INFINITY)
			continue; /* a nearer hit came since it was pushed */
		bool ok = !tree_is_leaf(n) ? top_push(p, top, n, best->h.t, stack, &sp)
		                           : top_leaf(o, d, top, n, b, best, visited, tests);
		if (!ok)
			return false;
	}
	return true;
}

/* trace_walk_stackless() over the top tree, its leaves' instances traced. */
static bool top_walk_stackless(const prep *p, float4 o, float4 d, const top_tree *top,
                               const bottoms *b, best_hit *best, uint *visited, uint *tests)
{
	uint node = 0, seen = 0;
	if (box_enter(p, top->nodes, 0, best->h.t) == INFINITY)
		return true;
	for (;;) {
		const __global tree_node *n = &top->nodes[node];
		++*visited;
		if (++seen > top->count)
			return true;
		if (!tree_is_leaf(n)) {
			if (enter_next(p, top->nodes, n, NO_HIT, best->h.t, &node))
				continue;
		} else if (!top_leaf(o, d, top, n, b, best, visited, tests)) {
			return false;
		}
		if (!climb(p, top->nodes, top->parents, best->h.t, &node))
			return true;
	}
}

/* Ray i through both levels: its hit into hits, its instance into
 * hit_inst, the nodes of both levels and the triangles into counts. */
static void two_level_ray(const top_tree *top, const bottoms *b, __global const float4 *rays,
                          uint ray_count, __global uint4 *hits, __global uint2 *counts,
                          __global uint *hit_inst)
{
	uint i = get_global_id(0), visited = 0, tests = 0;
	best_hit best = {{0.0f, 0.0f, 0.0f, NO_HIT}, NO_HIT};
	bool ok = true;
	prep p;
	if (i >= ray_count)
		return;
	float4 o = rays[2 * i], d = rays[2 * i + 1];
	if (ray_load(rays, i, &p, &best.h) && top->count != 0)
		ok = b->mode == TWO_LEVEL_STACKLESS
		             ? top_walk_stackless(&p, o, d, top, b, &best, &visited, &tests)
		             : top_walk_stack(&p, o, d, top, b, &best, &visited, &tests);
	store(hits, counts, i, &best.h, ok ? visited : TRACE_OVERFLOW, tests);
	hit_inst[i] = best.instance;
}

/* The arguments of the two-level kernels: enum trace_arg's, then enum
 * trace_arg_two_level's. */
#define TWO_LEVEL_KERNEL_ARGS                                                              \
	TRACE_KERNEL_ARGS, __global const tree_node *top, __global const uint *top_index,  \
	__global const uint *top_parents, uint top_count, uint top_index_count,            \
	__global const uint *meshes, __global const double *inverse,                       \
	__global const uint *inst_mesh, uint instance_count, __global uint *hit_inst

#define TWO_LEVEL_BODY(mode)                                                               \
	top_tree top_ = {top, top_index, top_parents, top_count, top_index_count};         \
	bottoms b_ = {nodes, tris, prim_index, parents, meshes, inverse, inst_mesh,        \
	              instance_count, mode};                                               \
	(void)node_total, (void)index_count, (void)tri_count, (void)any;                   \
	two_level_ray(&top_, &b_, rays, ray_count, hits, counts, hit_inst)

__kernel void trace_two_level_stack(TWO_LEVEL_KERNEL_ARGS)
{
	TWO_LEVEL_BODY(TWO_LEVEL_STACK);
}

__kernel void trace_two_level_stackless(TWO_LEVEL_KERNEL_ARGS)
{
	TWO_LEVEL_BODY(TWO_LEVEL_STACKLESS);
}

__kernel void trace_two_level_wide8(TWO_LEVEL_KERNEL_ARGS)
{
	TWO_LEVEL_BODY(TWO_LEVEL_WIDE8);
}

#endif /* cl_khr_fp64 */
