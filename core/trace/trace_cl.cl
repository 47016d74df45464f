/*
 * The device traversals (rays.traversal "device_stack" and "device_stackless"):
 * one work-item per ray, closest or any hit, the same arithmetic as the
 * CPU kernel (core/trace/trace_kernel.h) operation for operation, so a ray
 * gets the same triangle at the same t, u and v bit for bit. For that the
 * host builds this with -cl-fp32-correctly-rounded-divide-sqrt (OpenCL's
 * default float division may be off by 2.5 ulp) and never with
 * -cl-mad-enable or -cl-fast-relaxed-math, and contraction into fused
 * multiply-adds is off here, as it is in the CPU build (ISO C mode).
 *
 * The program is tree_node.h (the tree interface's node reads, shared with
 * the host), trace_layout.h (the buffers' layouts and the constants, also
 * shared) and this file, so the kernels walk trees of any width (ABI 1.5)
 * the way the CPU traversals do, in the same order: the same nodes
 * entered, not only the same hits. STACK_SIZE (the stack traversal's
 * private stack) comes from the host: at least the most far children a
 * walk of the tree holds at once.
 */
#pragma OPENCL FP_CONTRACT OFF

#ifdef cl_khr_fp64
#pragma OPENCL EXTENSION cl_khr_fp64 : enable
#endif

#ifndef STACK_SIZE
#define STACK_SIZE TRACE_MIN_STACK
#endif

#define NO_HIT TRACE_NO_HIT
#define NODES __global const tree_node *nodes

typedef struct prep {
	float org[3];
	float tmin;
	float dir[3];
	float inv[3];
	int near[3], far[3]; /* offsets into a node's 8 floats: lo k, hi 4 + k */
	int kx, ky, kz;
	float sx, sy, sz;
} prep;

typedef struct hit {
	float t, u, v;
	uint prim;
} hit;

/* prep_box and prep_shear of trace_kernel.h. */
static bool prep_ray(float4 o, float4 d, prep *p)
{
	float dd[3] = {d.x, d.y, d.z};
	float ax = fabs(d.x), ay = fabs(d.y), az = fabs(d.z);
	if (!isfinite(ax) || !isfinite(ay) || !isfinite(az) || ax + ay + az == 0.0f)
		return false;
	p->org[0] = o.x;
	p->org[1] = o.y;
	p->org[2] = o.z;
	for (int k = 0; k < 3; k++) {
		p->dir[k] = dd[k];
		p->inv[k] = 1.0f / dd[k];
		p->near[k] = signbit(p->inv[k]) ? 4 + k : k;
		p->far[k] = signbit(p->inv[k]) ? k : 4 + k;
	}
	p->tmin = o.w;
	p->kz = ax >= ay ? (ax >= az ? 0 : 2) : (ay >= az ? 1 : 2);
	p->kx = (p->kz + 1) % 3;
	p->ky = (p->kx + 1) % 3;
	if (dd[p->kz] < 0.0f) {
		int k = p->kx;
		p->kx = p->ky;
		p->ky = k;
	}
	p->sx = dd[p->kx] / dd[p->kz];
	p->sy = dd[p->ky] / dd[p->kz];
	p->sz = 1.0f / dd[p->kz];
	return true;
}

/* Edge functions in double when float rounding gave exactly 0 (as the CPU
 * does). A device without doubles keeps the float zero: the one place its
 * hits could differ, on rays through an edge or a vertex. */
static void edges_double(const float *a, const float *b, const float *c, float *e)
{
#ifdef cl_khr_fp64
	e[0] = (float)((double)c[0] * b[1] - (double)c[1] * b[0]);
	e[1] = (float)((double)a[0] * c[1] - (double)a[1] * c[0]);
	e[2] = (float)((double)b[0] * a[1] - (double)b[1] * a[0]);
#else
	(void)a, (void)b, (void)c, (void)e;
#endif
}

/* isect() of trace_kernel.h on the 9 floats of one slot. */
static bool isect(const prep *p, __global const float *v, float tmax, float *out)
{
	const int kx = p->kx, ky = p->ky, kz = p->kz;
	float az = v[kz] - p->org[kz], bz = v[3 + kz] - p->org[kz], cz = v[6 + kz] - p->org[kz];
	float a[2] = {v[kx] - p->org[kx] - p->sx * az, v[ky] - p->org[ky] - p->sy * az};
	float b[2] = {v[3 + kx] - p->org[kx] - p->sx * bz, v[3 + ky] - p->org[ky] - p->sy * bz};
	float c[2] = {v[6 + kx] - p->org[kx] - p->sx * cz, v[6 + ky] - p->org[ky] - p->sy * cz};
	float e[3] = {c[0] * b[1] - c[1] * b[0], a[0] * c[1] - a[1] * c[0],
	              b[0] * a[1] - b[1] * a[0]};
	if (e[0] == 0.0f || e[1] == 0.0f || e[2] == 0.0f)
		edges_double(a, b, c, e);
	if ((e[0] < 0.0f || e[1] < 0.0f || e[2] < 0.0f) &&
	    (e[0] > 0.0f || e[1] > 0.0f || e[2] > 0.0f))
		return false;
	float det = e[0] + e[1] + e[2];
	if (det == 0.0f)
		return false;
	float t = p->sz * (e[0] * az + e[1] * bz + e[2] * cz) / det;
	if (!(t > p->tmin && t <= tmax))
		return false;
	out[0] = t;
	out[1] = e[1] / det;
	out[2] = e[2] / det;
	return true;
}

/* take_hit(): an exact tie in t goes to the smaller triangle id. */
static bool take_hit(hit *h, uint prim, const float *out)
{
	if (out[0] == h->t && (h->prim == NO_HIT || prim >= h->prim))
		return false;
	h->t = out[0];
	h->u = out[1];
	h->v = out[2];
	h->prim = prim;
	return true;
}

/* box_enter() on a box as 8 floats (lo k at k, hi k at 4 + k): entry
 * distance, or INFINITY for a miss in (tmin, tmax). */
static float slab(const prep *p, const float *f, float tmax)
{
	float t0 = p->tmin, t1 = tmax;
	for (int k = 0; k < 3; k++) {
		float tn = (f[p->near[k]] - p->org[k]) * p->inv[k];
		float tf = (f[p->far[k]] - p->org[k]) * p->inv[k];
		t0 = tn > t0 ? tn : t0;
		t1 = tf < t1 ? tf : t1;
	}
	return t0 <= t1 * FAR_SCALE ? t0 : INFINITY;
}

/* box_enter(): slab() on node's box. */
static float box_enter(const prep *p, NODES, uint node, float tmax)
{
	float f[8];
	vstore8(vload8(0, tree_box(&nodes[node])), 0, f);
	return slab(p, f, tmax);
}

/* The triangles of leaf slots first .. first + count; true when an
 * any-hit ray may stop. */
static bool leaf_range(const prep *p, __global const float *tris,
                       __global const uint *prim_index, uint first, uint count,
                       uint index_count, uint tri_count, bool any, hit *h, uint *tests)
{
	float out[3];
	if (first > index_count || count > index_count - first)
		return false;
	for (uint i = first; i < first + count; i++) {
		uint prim = prim_index[i];
		if (prim >= tri_count)
			continue;
		++*tests;
		if (isect(p, tris + TRACE_SLOT_FLOATS * (size_t)i, h->t, out) &&
		    take_hit(h, prim, out) && any)
			return true;
	}
	return false;
}

/* A leaf node's triangles (leaf_range). */
static bool leaf(const prep *p, __global const float *tris, __global const uint *prim_index,
                 const __global tree_node *n, uint index_count, uint tri_count, bool any,
                 hit *h, uint *tests)
{
	return leaf_range(p, tris, prim_index, tree_leaf_first(n), tree_leaf_count(n), index_count,
	                  tri_count, any, h, tests);
}

static void store(__global uint4 *hits, __global uint2 *counts, uint i, const hit *h,
                  uint nodes, uint tests)
{
	hits[i] = (uint4)(as_uint(h->t), as_uint(h->u), as_uint(h->v), h->prim);
	counts[i] = (uint2)(nodes, tests);
}

/* The arguments of both traversal kernels, in enum trace_arg's order. */
#define TRACE_KERNEL_ARGS                                                                  \
	NODES, __global const float *tris, __global const uint *prim_index,                \
	__global const uint *parents, uint node_total, uint index_count, uint tri_count,   \
	__global const float4 *rays, uint ray_count, uint any, __global uint4 *hits,       \
	__global uint2 *counts

/* Counts entering a node in *visited; false past node_total entries (a
 * cycle in a broken tree: the walk ends). */
static bool enter_node(uint node_total, uint *visited)
{
	return ++*visited <= node_total;
}

/* Whether an inner node's children lie inside the node array (the CPU
 * traversals' tree_children_end check). */
static bool children_inside(const __global tree_node *n, uint node_total)
{
	return tree_child_count(n) <= TREE_MAX_WIDTH && tree_children_end(n) <= node_total;
}

/* Ray i (< ray_count) prepared, no hit yet; false for a ray with no
 * direction to trace. */
static bool ray_load(__global const float4 *rays, uint i, prep *p, hit *h)
{
	float4 o = rays[2 * i], d = rays[2 * i + 1];
	h->t = d.w;
	h->u = 0.0f;
	h->v = 0.0f;
	h->prim = NO_HIT;
	return prep_ray(o, d, p);
}

/* The start of both traversals for ray i: no hit yet, the ray prepared;
 * false when there is nothing to trace (past the last ray, or a ray that
 * misses the root box, whose miss is stored). */
static bool ray_begin(NODES, uint node_total, __global const float4 *rays, uint ray_count,
                      uint i, __global uint4 *hits, __global uint2 *counts, prep *p, hit *h)
{
	if (i >= ray_count)
		return false;
	if (ray_load(rays, i, p, h) && node_total != 0 && box_enter(p, nodes, 0, h->t) != INFINITY)
		return true;
	store(hits, counts, i, h, 0, 0);
	return false;
}

/* A child on the stack: its node and entry distance. */
typedef struct entry {
	uint node;
	float t;
} entry;

/* trace.c's descend() and descend_wide(): the children the ray enters,
 * far to near, into e; how many. Two children: the second is near only
 * when strictly nearer. More: sorted by insertion, a tie keeping the child
 * list's order with the later one nearer. */
static uint children_hit(const prep *p, NODES, const __global tree_node *n, float tmax,
                         entry *e)
{
	uint m = 0, k = tree_child_count(n);
	if (tree_is_binary_inner(n)) {
		entry a = {tree_child(n, 0), box_enter(p, nodes, tree_child(n, 0), tmax)};
		entry b = {tree_child(n, 1), box_enter(p, nodes, tree_child(n, 1), tmax)};
		entry near = b.t < a.t ? b : a, far = b.t < a.t ? a : b;
		if (near.t == INFINITY)
			return 0;
		if (far.t != INFINITY)
			e[m++] = far;
		e[m++] = near;
		return m;
	}
	for (uint i = 0; i < k; i++) {
		entry c = {tree_child(n, i), box_enter(p, nodes, tree_child(n, i), tmax)};
		if (c.t == INFINITY)
			continue;
		uint j = m++;
		for (; j > 0 && e[j - 1].t < c.t; j--)
			e[j] = e[j - 1];
		e[j] = c;
	}
	return m;
}

/* trace.c's traverse() of one tree whose root box the ray enters: nearest
 * child next, the others on a stack with their entry distance, popped only
 * while it still beats the closest hit. *visited counts the nodes entered
 * (ending the walk past node_total: a cycle), *tests the triangles; false
 * when the stack overflowed (deeper than the host said). */
static bool walk_stack(const prep *p, NODES, __global const float *tris,
                       __global const uint *prim_index, uint node_total, uint index_count,
                       uint tri_count, bool any, hit *h, uint *visited, uint *tests)
{
	uint sp = 0, node = 0;
	uint st_node[STACK_SIZE];
	float st_t[STACK_SIZE];
	entry e[TREE_MAX_WIDTH];
	while (enter_node(node_total, visited)) {
		const __global tree_node *n = &nodes[node];
		if (tree_is_leaf(n)) {
			if (leaf(p, tris, prim_index, n, index_count, tri_count, any, h, tests))
				return true;
		} else if (children_inside(n, node_total)) {
			uint m = children_hit(p, nodes, n, h->t, e);
			if (m > 0) {
				if (sp + m - 1 > STACK_SIZE)
					return false;
				for (uint k = 0; k + 1 < m; k++) {
					st_node[sp] = e[k].node;
					st_t[sp++] = e[k].t;
				}
				node = e[m - 1].node;
				continue;
			}
		}
		bool popped = false;
		while (sp) {
			--sp;
			if (st_t[sp] <= h->t * FAR_SCALE) {
				node = st_node[sp];
				popped = true;
				break;
			}
		}
		if (!popped)
			return true;
	}
	return true;
}

__kernel void trace_stack(TRACE_KERNEL_ARGS)
{
	uint i = get_global_id(0), visited = 0, tests = 0;
	hit h;
	prep p;
	(void)parents;
	if (!ray_begin(nodes, node_total, rays, ray_count, i, hits, counts, &p, &h))
		return;
	if (!walk_stack(&p, nodes, tris, prim_index, node_total, index_count, tri_count, any, &h,
	                &visited, &tests))
		visited = TRACE_OVERFLOW;
	store(hits, counts, i, &h, visited, tests);
}

/* trace_stackless.c's centre_key(): twice a box centre along the ray. */
static float centre_key(const prep *p, NODES, uint node)
{
	const __global float *f = tree_box(&nodes[node]);
	float d = 0.0f;
	for (int k = 0; k < 3; k++)
		d += (f[k] + f[4 + k]) * p->dir[k];
	return d;
}

/* trace_stackless.c's near_child(): decided from the box centres along the
 * ray, the same going down and coming back up. */
static uint near_child(const prep *p, NODES, const __global tree_node *n)
{
	uint a = tree_child(n, 0), b = tree_child(n, 1);
	const __global float *fa = tree_box(&nodes[a]), *fb = tree_box(&nodes[b]);
	float d = 0.0f;
	for (int k = 0; k < 3; k++)
		d += ((fb[k] + fb[4 + k]) - (fa[k] + fa[4 + k])) * p->dir[k];
	return d < 0.0f ? b : a;
}

/* trace_stackless.c's next_wide(): the child of wide node n after `after`
 * in the ray order (by key, then by index), the first for NO_HIT; NO_HIT
 * past the last. */
static uint next_wide(const prep *p, NODES, const __global tree_node *n, uint after)
{
	float ka = after == NO_HIT ? 0.0f : centre_key(p, nodes, after), kb = 0.0f;
	uint best = NO_HIT;
	for (uint i = 0; i < tree_child_count(n); i++) {
		uint c = tree_child(n, i);
		float k = centre_key(p, nodes, c);
		if (after != NO_HIT && !(k > ka || (k == ka && c > after)))
			continue;
		if (best == NO_HIT || k < kb || (k == kb && c < best)) {
			best = c;
			kb = k;
		}
	}
	return best;
}

/* trace_stackless.c's enter_next(): the first child of inner node n after
 * `after` (NO_HIT: from the start) in the ray order that the ray enters,
 * into *node; false when none is left. */
static bool enter_next(const prep *p, NODES, const __global tree_node *n, uint after,
                       float tmax, uint *node)
{
	if (tree_is_binary_inner(n)) {
		uint near = near_child(p, nodes, n);
		uint far = near == tree_child(n, 0) ? tree_child(n, 1) : tree_child(n, 0);
		if (after == NO_HIT && box_enter(p, nodes, near, tmax) != INFINITY) {
			*node = near;
			return true;
		}
		if ((after == NO_HIT || after == near) && box_enter(p, nodes, far, tmax) != INFINITY) {
			*node = far;
			return true;
		}
		return false;
	}
	for (uint c = next_wide(p, nodes, n, after); c != NO_HIT; c = next_wide(p, nodes, n, c))
		if (box_enter(p, nodes, c, tmax) != INFINITY) {
			*node = c;
			return true;
		}
	return false;
}

/* trace_stackless.c's climb(): from a node whose subtree is done, up to
 * the next sibling to enter, into *node; false back at the root. */
static bool climb(const prep *p, NODES, __global const uint *parents, float tmax, uint *node)
{
	uint at = *node;
	while (at != 0) {
		uint parent = parents[at];
		if (enter_next(p, nodes, &nodes[parent], at, tmax, node))
			return true;
		at = parent;
	}
	return false;
}

/* trace_stackless.c's walk() of one tree whose root box the ray enters:
 * down into the near child, up through the parent links (Hapala et al.
 * 2011), a wide node's children in the ray order; counted as walk_stack. */
static void walk_stackless(const prep *p, NODES, __global const uint *parents,
                           __global const float *tris, __global const uint *prim_index,
                           uint node_total, uint index_count, uint tri_count, bool any, hit *h,
                           uint *visited, uint *tests)
{
	uint node = 0;
	while (enter_node(node_total, visited)) {
		const __global tree_node *n = &nodes[node];
		if (!tree_is_leaf(n)) {
			if (enter_next(p, nodes, n, NO_HIT, h->t, &node))
				continue;
		} else if (leaf(p, tris, prim_index, n, index_count, tri_count, any, h, tests)) {
			return;
		}
		if (!climb(p, nodes, parents, h->t, &node))
			return;
	}
}

__kernel void trace_stackless(TRACE_KERNEL_ARGS)
{
	uint i = get_global_id(0), visited = 0, tests = 0;
	hit h;
	prep p;
	if (!ray_begin(nodes, node_total, rays, ray_count, i, hits, counts, &p, &h))
		return;
	walk_stackless(&p, nodes, parents, tris, prim_index, node_total, index_count, tri_count, any,
	               &h, &visited, &tests);
	store(hits, counts, i, &h, visited, tests);
}
