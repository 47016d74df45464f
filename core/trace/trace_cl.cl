/*
 * The device traversals (rays.traversal "cl_stack" and "cl_stackless"):
 * one work-item per ray, closest or any hit, the same arithmetic as the
 * CPU kernel (core/trace/trace_kernel.h) operation for operation, so a ray
 * gets the same triangle at the same t, u and v bit for bit. For that the
 * host builds this with -cl-fp32-correctly-rounded-divide-sqrt (OpenCL's
 * default float division may be off by 2.5 ulp) and never with
 * -cl-mad-enable or -cl-fast-relaxed-math, and contraction into fused
 * multiply-adds is off here, as it is in the CPU build (ISO C mode).
 *
 * Buffers: nodes as two float4 each (lo + first, hi + count: bvhlab_node's
 * layout), the triangles' vertices in leaf-slot order (9 floats a slot,
 * as the CPU batch tracer's copy), prim_index, the parent links
 * (stackless), rays as two float4 (org + tmin, dir + tmax), hits as uint4
 * (t, u, v bits, prim) and per ray the nodes entered and triangles tested.
 * STACK_SIZE (the stack traversal's private stack) comes from the host:
 * at least the tree's depth.
 */
#pragma OPENCL FP_CONTRACT OFF

#ifdef cl_khr_fp64
#pragma OPENCL EXTENSION cl_khr_fp64 : enable
#endif

#ifndef STACK_SIZE
#define STACK_SIZE 64
#endif

#define NO_HIT 0xffffffffu
#define FAR_SCALE (1.0f + 32.0f * FLT_EPSILON)

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

/* box_enter(): entry distance, or INFINITY for a miss in (tmin, tmax). */
static float box_enter(const prep *p, __global const float4 *nodes, uint node, float tmax)
{
	float4 lo = nodes[2 * node], hi = nodes[2 * node + 1];
	float f[8] = {lo.x, lo.y, lo.z, lo.w, hi.x, hi.y, hi.z, hi.w};
	float t0 = p->tmin, t1 = tmax;
	for (int k = 0; k < 3; k++) {
		float tn = (f[p->near[k]] - p->org[k]) * p->inv[k];
		float tf = (f[p->far[k]] - p->org[k]) * p->inv[k];
		t0 = tn > t0 ? tn : t0;
		t1 = tf < t1 ? tf : t1;
	}
	return t0 <= t1 * FAR_SCALE ? t0 : INFINITY;
}

static uint node_first(__global const float4 *nodes, uint node)
{
	return as_uint(nodes[2 * node].w);
}

static uint node_count(__global const float4 *nodes, uint node)
{
	return as_uint(nodes[2 * node + 1].w);
}

/* A leaf's triangles; true when an any-hit ray may stop. */
static bool leaf(const prep *p, __global const float *tris, __global const uint *prim_index,
                 uint first, uint count, uint index_count, uint tri_count, bool any, hit *h,
                 uint *tests)
{
	float out[3];
	if (first > index_count || count > index_count - first)
		return false;
	for (uint i = first; i < first + count; i++) {
		uint prim = prim_index[i];
		if (prim >= tri_count)
			continue;
		++*tests;
		if (isect(p, tris + 9 * (size_t)i, h->t, out) && take_hit(h, prim, out) && any)
			return true;
	}
	return false;
}

static void store(__global uint4 *hits, __global uint2 *counts, uint i, const hit *h,
                  uint nodes, uint tests)
{
	hits[i] = (uint4)(as_uint(h->t), as_uint(h->u), as_uint(h->v), h->prim);
	counts[i] = (uint2)(nodes, tests);
}

/* The arguments of both traversal kernels, in the order the host sets them. */
#define TRACE_KERNEL_ARGS                                                                  \
	__global const float4 *nodes, __global const float *tris,                          \
	__global const uint *prim_index, __global const uint *parents, uint node_total,    \
	uint index_count, uint tri_count, __global const float4 *rays, uint ray_count,     \
	uint any, __global uint4 *hits, __global uint2 *counts

/* Enters `node`: its first and count, counted in *visited; false past
 * node_total entries (a cycle in a broken tree: the walk ends). */
static bool enter_node(__global const float4 *nodes, uint node, uint node_total, uint *visited,
                       uint *first, uint *count)
{
	if (++*visited > node_total)
		return false;
	*first = node_first(nodes, node);
	*count = node_count(nodes, node);
	return true;
}

/* The start of both traversals for ray i: no hit yet, the ray prepared;
 * false when there is nothing to trace (past the last ray, or a ray that
 * misses the root box, whose miss is stored). */
static bool ray_begin(__global const float4 *nodes, uint node_total,
                      __global const float4 *rays, uint ray_count, uint i,
                      __global uint4 *hits, __global uint2 *counts, prep *p, hit *h)
{
	if (i >= ray_count)
		return false;
	float4 o = rays[2 * i], d = rays[2 * i + 1];
	h->t = d.w;
	h->u = 0.0f;
	h->v = 0.0f;
	h->prim = NO_HIT;
	if (prep_ray(o, d, p) && node_total != 0 && box_enter(p, nodes, 0, h->t) != INFINITY)
		return true;
	store(hits, counts, i, h, 0, 0);
	return false;
}

/* trace.c's traverse(): near child first, far ones on a stack with their
 * entry distance, popped only while it still beats the closest hit. */
__kernel void trace_stack(TRACE_KERNEL_ARGS)
{
	uint i = get_global_id(0), visited = 0, tests = 0, sp = 0, node = 0, first, count;
	uint st_node[STACK_SIZE];
	float st_t[STACK_SIZE];
	hit h;
	prep p;
	(void)parents;
	if (!ray_begin(nodes, node_total, rays, ray_count, i, hits, counts, &p, &h))
		return;
	while (enter_node(nodes, node, node_total, &visited, &first, &count)) {
		if (count) {
			if (leaf(&p, tris, prim_index, first, count, index_count, tri_count, any, &h,
			         &tests))
				break;
		} else if (first < node_total - 1) {
			uint near = first, far = first + 1;
			float tn = box_enter(&p, nodes, near, h.t), tf = box_enter(&p, nodes, far, h.t);
			if (tf < tn) {
				float t = tn;
				tn = tf;
				tf = t;
				near = far;
				far = first;
			}
			if (tn != INFINITY) {
				if (tf != INFINITY) {
					if (sp == STACK_SIZE) { /* deeper than the host said: flag it */
						visited = 0xffffffffu;
						break;
					}
					st_node[sp] = far;
					st_t[sp++] = tf;
				}
				node = near;
				continue;
			}
		}
		bool popped = false;
		while (sp) {
			--sp;
			if (st_t[sp] <= h.t * FAR_SCALE) {
				node = st_node[sp];
				popped = true;
				break;
			}
		}
		if (!popped)
			break;
	}
	store(hits, counts, i, &h, visited, tests);
}

/* trace_stackless.c's near_child(): decided from the box centres along the
 * ray, the same going down and coming back up. */
static uint near_child(const prep *p, __global const float4 *nodes, uint first)
{
	float4 alo = nodes[2 * first], ahi = nodes[2 * first + 1];
	float4 blo = nodes[2 * first + 2], bhi = nodes[2 * first + 3];
	float a[3] = {alo.x + ahi.x, alo.y + ahi.y, alo.z + ahi.z};
	float b[3] = {blo.x + bhi.x, blo.y + bhi.y, blo.z + bhi.z};
	float d = 0.0f;
	for (int k = 0; k < 3; k++)
		d += (b[k] - a[k]) * p->dir[k];
	return d < 0.0f ? first + 1 : first;
}

/* trace_stackless.c's walk(): down into the near child, up through the
 * parent links (Hapala et al. 2011). */
__kernel void trace_stackless(TRACE_KERNEL_ARGS)
{
	uint i = get_global_id(0), visited = 0, tests = 0, node = 0, first, count;
	hit h;
	prep p;
	if (!ray_begin(nodes, node_total, rays, ray_count, i, hits, counts, &p, &h))
		return;
	while (enter_node(nodes, node, node_total, &visited, &first, &count)) {
		if (count == 0) {
			uint near = near_child(&p, nodes, first);
			uint far = near == first ? first + 1 : first;
			if (box_enter(&p, nodes, near, h.t) != INFINITY) {
				node = near;
				continue;
			}
			if (box_enter(&p, nodes, far, h.t) != INFINITY) {
				node = far;
				continue;
			}
		} else if (leaf(&p, tris, prim_index, first, count, index_count, tri_count, any, &h,
		                &tests)) {
			break;
		}
		/* climb(): up to the next far child to enter, or out at the root */
		uint at = node;
		bool found = false;
		while (at != 0) {
			uint parent = parents[at], pf = node_first(nodes, parent);
			uint near = near_child(&p, nodes, pf);
			uint far = near == pf ? pf + 1 : pf;
			if (at == near && box_enter(&p, nodes, far, h.t) != INFINITY) {
				node = far;
				found = true;
				break;
			}
			at = parent;
		}
		if (!found)
			break;
	}
	store(hits, counts, i, &h, visited, tests);
}
