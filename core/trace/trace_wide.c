/*
 * The wide traversal: the tree collapsed into 4-child nodes
 * (wide_bvh.c), four slab tests per node in one vector pass, the
 * children entered nearest first and the others kept on a stack with their
 * entry distances. Each slab test performs box_enter()'s float operations
 * lane by lane, and a leaf's triangles go through isect()'s shear and sign
 * test four at a time, then isect() itself for the lanes that pass, so the
 * hits are those of the stack traversal; only the order of the visits
 * differs, which take_hit() makes irrelevant.
 *
 * GCC's vector extensions rather than intrinsics: the same source gives
 * SSE on x86-64 and NEON on arm64 (x86 gets three SSE builtins besides).
 */
#include "trace/trace_kernel.h"
#include "trace/trace_wide.h"

/* A ray's stack holds at most 3 entries per wide level: deeper trees go to
 * the stack traversal, so no ray allocates. */
#define WIDE_STACK 256

/* SSE's MAXPS/MINPS are exactly the selects below and MOVMSKPS gathers
 * lane signs; GCC does not find them from the generic code. */
#if defined(__SSE__) && WIDE == 4 && defined(__GNUC__) && !defined(__clang__)
#define X86_LANES 1
#else
#define X86_LANES 0
#endif

/* One lane per child box and per triangle of a group. (8 lanes were
 * tried: no faster, see README.) */
_Static_assert(WIDE == TRI_LANES, "node and triangle lanes share one vector type");
typedef float vf __attribute__((vector_size(4 * WIDE)));
typedef int32_t vi __attribute__((vector_size(4 * WIDE)));

struct wide_entry {
	uint32_t child, count; /* a lane: count 0 inner, else a leaf */
	float t;               /* where the ray enters its box */
};

struct wide_ray {
	ray_prep *p;
	bool sheared; /* p's triangle constants and sx, sy are set */
	vf org[3], inv[3];
	vf sx, sy; /* the shear of ray_prep, for the triangle lanes */
	int near[3], far[3]; /* rows of wide_node.box */
};

static inline vf splat(float x)
{
	vf v;
	for (int i = 0; i < WIDE; i++)
		v[i] = x;
	return v;
}

/* a > b ? a : b and a < b ? a : b lane by lane, as box_enter() writes
 * them: a NaN in a leaves b. */
static inline vf pick_max(vf a, vf b)
{
#if X86_LANES
	return __builtin_ia32_maxps(a, b); /* the same select, one instruction */
#else
	vi m = a > b;
	return (vf)((m & (vi)a) | (~m & (vi)b));
#endif
}

static inline vf pick_min(vf a, vf b)
{
#if X86_LANES
	return __builtin_ia32_minps(a, b);
#else
	vi m = a < b;
	return (vf)((m & (vi)a) | (~m & (vi)b));
#endif
}

static void wide_ray_init(struct wide_ray *r, ray_prep *p)
{
	r->p = p;
	r->sheared = false;
	for (int k = 0; k < 3; k++) {
		r->org[k] = splat(p->org[k]);
		r->inv[k] = splat(p->inv[k]);
		r->near[k] = p->near[k] < 4 ? k : 3 + k;
		r->far[k] = p->far[k] < 4 ? k : 3 + k;
	}
}

/* The triangle constants, at the first leaf: most primary rays of a
 * scene that does not fill the image never reach one, and they would pay
 * three divisions for nothing. */
static void wide_ray_shear(struct wide_ray *r)
{
	prep_shear(r->p);
	r->sx = splat(r->p->sx);
	r->sy = splat(r->p->sy);
	r->sheared = true;
}

static inline unsigned lane_bits(vi m)
{
#if X86_LANES
	return (unsigned)__builtin_ia32_movmskps((vf)m);
#else
	unsigned bits = 0;
	for (int i = 0; i < WIDE; i++)
		bits |= (unsigned)(m[i] & 1) << i;
	return bits;
#endif
}

/* Bit i set when the ray enters lane i's box before tmax; *t the entries. */
static inline unsigned enter_lanes(const struct wide_ray *r, const struct wide_node *n,
                                   float tmax, vf *t)
{
	vf t0 = splat(r->p->tmin), t1 = splat(tmax);
	for (int k = 0; k < 3; k++) {
		vf tn = (*(const vf *)n->box[r->near[k]] - r->org[k]) * r->inv[k];
		vf tf = (*(const vf *)n->box[r->far[k]] - r->org[k]) * r->inv[k];
		t0 = pick_max(tn, t0);
		t1 = pick_min(tf, t1);
	}
	vi empty = (vi)splat(0.0f) - 1; /* WIDE_EMPTY in every lane */
	vi in = (t0 <= t1 * splat(FAR_SCALE)) & (*(const vi *)n->count != empty);
	*t = t0;
	return lane_bits(in);
}

/*
 * isect()'s shear and sign test on a group's four triangles: bit i set
 * when lane i may be hit. The floats are isect()'s, operation for
 * operation, so only triangles isect() rejects are dropped; a zero edge
 * passes, for isect()'s double fallback to decide.
 */
static inline unsigned sign4(const struct wide_ray *r, const struct wide_tris *g)
{
	const ray_prep *p = r->p;
	vf x[3], y[3], zero = splat(0.0f);
	for (int j = 0; j < 3; j++) {
		vf z = *(const vf *)g->v[3 * j + p->kz] - r->org[p->kz];
		x[j] = (*(const vf *)g->v[3 * j + p->kx] - r->org[p->kx]) - r->sx * z;
		y[j] = (*(const vf *)g->v[3 * j + p->ky] - r->org[p->ky]) - r->sy * z;
	}
	vf e0 = x[2] * y[1] - y[2] * x[1];
	vf e1 = x[0] * y[2] - y[0] * x[2];
	vf e2 = x[1] * y[0] - y[1] * x[0];
	vi on_edge = (e0 == zero) | (e1 == zero) | (e2 == zero);
	vi neg = (e0 < zero) | (e1 < zero) | (e2 < zero);
	vi pos = (e0 > zero) | (e1 > zero) | (e2 > zero);
	return lane_bits(on_edge | ~(neg & pos));
}

/* isect() and take_hit() on lane i of a group. */
static bool isect_lane(const ray_prep *p, const struct wide_tris *g, uint32_t i, bvhlab_hit *hit)
{
	float v[3][3], out[3];
	for (int j = 0; j < 3; j++)
		for (int k = 0; k < 3; k++)
			v[j][k] = g->v[3 * j + k][i];
	return isect(p, v[0], v[1], v[2], hit->t, out) && take_hit(hit, g->prim[i], out);
}

/* The entered lanes, nearest first, in e; how many. (A version without a
 * loop for one or two lanes measured slower.) */
static uint32_t sort_lanes(const struct wide_node *n, unsigned mask, vf t,
                           struct wide_entry e[WIDE])
{
	uint32_t m = 0;
	for (uint32_t i = 0; i < WIDE; i++) {
		if (!(mask & (1u << i)))
			continue;
		struct wide_entry x = {n->child[i], n->count[i], t[i]};
		uint32_t j = m++;
		for (; j > 0 && e[j - 1].t > x.t; j--)
			e[j] = e[j - 1];
		e[j] = x;
	}
	return m;
}

static inline void prefetch_entry(const struct trace_view *v, const struct wide_entry *e)
{
	if (e->count == 0) {
		const char *node = (const char *)&v->wide->nodes[e->child];
		for (size_t line = 0; line < sizeof(struct wide_node); line += 64)
			__builtin_prefetch(node + line);
	} else {
		const char *g = (const char *)&v->wide->tris[e->child];
		for (size_t line = 0; line < sizeof(struct wide_tris); line += 64)
			__builtin_prefetch(g + line);
	}
}

struct wide_walk {
	const struct trace_view *v;
	bvhlab_hit *hit;
	uint64_t nodes, tris;
	bool any;
};

/* True when an any-hit ray is done. */
static bool wide_leaf(struct wide_walk *w, struct wide_ray *r, const struct wide_entry *e)
{
	const struct wide_tris *g = &w->v->wide->tris[e->child];
	if (!r->sheared)
		wide_ray_shear(r);
	for (uint32_t left = e->count; left > 0; g++) {
		uint32_t lanes = left < TRI_LANES ? left : TRI_LANES;
		unsigned mask = sign4(r, g) & ((1u << lanes) - 1);
		w->tris += lanes;
		left -= lanes;
		for (uint32_t i = 0; mask; i++, mask >>= 1)
			if ((mask & 1) && isect_lane(r->p, g, i, w->hit) && w->any)
				return true;
	}
	return false;
}

static void wide_walk(struct wide_walk *w, struct wide_ray *r)
{
	const struct wide_node *nodes = w->v->wide->nodes;
	struct wide_entry stack[WIDE_STACK], cur = {0, 0, r->p->tmin};
	uint32_t sp = 0;
	for (;;) {
		if (cur.count == 0) {
			const struct wide_node *n = &nodes[cur.child];
			struct wide_entry e[WIDE];
			vf t;
			w->nodes++;
			unsigned mask = enter_lanes(r, n, w->hit->t, &t);
			uint32_t m = sort_lanes(n, mask, t, e);
			for (uint32_t i = m; i-- > 0;)
				prefetch_entry(w->v, &e[i]);
			for (uint32_t i = m; i-- > 1;)
				stack[sp++] = e[i];
			if (m) {
				cur = e[0];
				continue;
			}
		} else if (wide_leaf(w, r, &cur)) {
			return;
		}
		do {
			if (sp == 0)
				return;
			cur = stack[--sp];
		} while (!(cur.t <= w->hit->t * FAR_SCALE));
	}
}

/* Stats: nodes_visited counts wide nodes entered, tris_tested the
 * triangle tests. A tree too deep for the ray's stack is traced by the
 * stack traversal instead (its stats are then binary ones). */
void trace_ray_wide(const bvhlab_tree *tree, const bvhlab_scene *scene,
                    const struct trace_view *view, const bvhlab_ray *ray, bool any,
                    bvhlab_hit *hit, bvhlab_trace_stats *stats)
{
	if (!view->wide || view->wide->depth * (WIDE - 1) + 1 > WIDE_STACK) {
		trace_ray_stack(tree, scene, view, ray, any, hit, stats);
		return;
	}
	struct wide_walk w = {view, hit, 0, 0, any};
	ray_prep p;
	struct wide_ray r;
	hit->t = ray->tmax;
	hit->u = hit->v = 0.0f;
	hit->prim = BVHLAB_NO_HIT;
	/* The root's box first, as the stack traversal does: a ray that misses
	 * the scene then costs one scalar box test, not a wide node. */
	if (prep_box(ray, &p) && box_enter(&p, &view->nodes[0], hit->t) != INFINITY) {
		wide_ray_init(&r, &p);
		wide_walk(&w, &r);
	}
	if (stats) {
		stats->rays++;
		stats->nodes_visited += w.nodes;
		stats->tris_tested += w.tris;
	}
}
