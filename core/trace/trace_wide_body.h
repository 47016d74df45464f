/*
 * The wide traversals' kernel at any lane count: one slab test of all a
 * node's child boxes per visit, the children entered nearest first and
 * the others kept on a stack with their entry distances, and a leaf's
 * triangles through isect()'s shear and sign test a group at a time, then
 * isect() itself for the lanes that pass. Each lane performs
 * box_enter()'s and isect()'s float operations, operation for operation,
 * so the hits are those of the stack traversal; only the order of the
 * visits differs, which take_hit() makes irrelevant.
 *
 * Included by trace_wide.c (4 lanes, once) and trace_wide8.c (8 lanes,
 * once per instruction set under that set's target pragma), which define
 * first:
 *   WB_LANES         lanes per node
 *   WB_TRI_LANES     lanes per triangle group (TRI_LANES at both widths)
 *   WB_NODE, WB_TRIS the node and group types at those widths, WB_BVH the
 *                    tree (trace_wide.h's layout)
 *   WB_STACK         a ray's stack entries; deeper trees go to the stack
 *                    traversal, so no ray allocates
 *   WB(name)         the names of this inclusion's functions
 *   WB_MAX, WB_MIN, WB_BITS (optional) the lane max, min and sign gather
 *                    in one instruction each, WB_TBITS the sign gather at
 *                    the group's width; the generic selects below
 *                    otherwise (GCC does not find MAXPS/MINPS/MOVMSKPS
 *                    from them).
 * The types and the scalar helpers come once per file, the vector
 * functions once per inclusion. GCC's vector extensions rather than
 * intrinsics: the same source gives SSE, AVX or NEON.
 */

#ifndef TRACE_WIDE_BODY_TYPES
#define TRACE_WIDE_BODY_TYPES

typedef float vf __attribute__((vector_size(4 * WB_LANES)));
typedef int32_t vi __attribute__((vector_size(4 * WB_LANES)));
/* A triangle group's lanes. */
typedef float vt __attribute__((vector_size(4 * WB_TRI_LANES)));
typedef int32_t vti __attribute__((vector_size(4 * WB_TRI_LANES)));

struct wide_entry {
	uint32_t child, count; /* a lane: count 0 inner, else a leaf's triangles */
	float t;               /* where the ray enters its box */
};

struct wide_ray {
	ray_prep *p;
	bool sheared; /* p's triangle constants and sx, sy are set */
	vf org[3], inv[3];
	vt torg[3], sx, sy; /* the origin and shear of ray_prep, for the triangle lanes */
	int near[3], far[3]; /* rows of the node's box */
};

struct wide_walk {
	const WB_NODE *nodes;
	const WB_TRIS *tris;
	bvhlab_hit *hit;
	uint64_t nodes_visited, tris_tested;
	bool any;
};

/* The generic sign gather of n lanes. */
static inline unsigned lane_bits(const int32_t *m, int n)
{
	unsigned bits = 0;
	for (int i = 0; i < n; i++)
		bits |= (unsigned)(m[i] & 1) << i;
	return bits;
}

/* isect() and take_hit() on lane i of a group. */
static bool isect_lane(const ray_prep *p, const WB_TRIS *g, uint32_t i, bvhlab_hit *hit)
{
	float v[3][3], out[3];
	for (int j = 0; j < 3; j++)
		for (int k = 0; k < 3; k++)
			v[j][k] = g->v[3 * j + k][i];
	return isect(p, v[0], v[1], v[2], hit->t, out) && take_hit(hit, g->prim[i], out);
}

/* The entered lanes (mask), nearest first, in e; how many. t points at the
 * entry distances (a pointer, so that vectors wider than the caller's
 * instruction set allows never pass by value). */
static uint32_t sort_lanes(const WB_NODE *n, unsigned mask, const float *t,
                           struct wide_entry e[WB_LANES])
{
	uint32_t m = 0;
	for (; mask; mask &= mask - 1) {
		uint32_t i = (uint32_t)__builtin_ctz(mask);
		struct wide_entry x = {n->child[i], n->count[i], t[i]};
		uint32_t j = m++;
		for (; j > 0 && e[j - 1].t > x.t; j--)
			e[j] = e[j - 1];
		e[j] = x;
	}
	return m;
}

static inline void prefetch_entry(const struct wide_walk *w, const struct wide_entry *e)
{
	const char *p = e->count == 0 ? (const char *)&w->nodes[e->child]
	                              : (const char *)&w->tris[e->child];
	size_t size = e->count == 0 ? sizeof(WB_NODE) : sizeof(WB_TRIS);
	for (size_t line = 0; line < size; line += 64)
		__builtin_prefetch(p + line);
}

typedef void wide_trace_fn(struct wide_walk *w, ray_prep *p);

/* Stats: nodes_visited counts wide nodes entered, tris_tested the
 * triangle tests. Without b, or with a tree too deep for the ray's stack,
 * the stack traversal traces the ray instead (its stats are then binary
 * ones). */
static void wide_trace_ray(const WB_BVH *b, wide_trace_fn *trace, const bvhlab_tree *tree,
                           const bvhlab_scene *scene, const struct trace_view *view,
                           const bvhlab_ray *ray, bool any, bvhlab_hit *hit,
                           bvhlab_trace_stats *stats)
{
	if (!b || b->depth * (WB_LANES - 1) + 1 > WB_STACK) {
		trace_ray_stack(tree, scene, view, ray, any, hit, stats);
		return;
	}
	struct wide_walk w = {b->nodes, b->tris, hit, 0, 0, any};
	ray_prep p;
	hit->t = ray->tmax;
	hit->u = hit->v = 0.0f;
	hit->prim = BVHLAB_NO_HIT;
	/* The root's box first, as the stack traversal does: a ray that misses
	 * the scene then costs one scalar box test, not a wide node. */
	if (prep_box(ray, &p) && box_enter(&p, &view->nodes[0], hit->t) != INFINITY)
		trace(&w, &p);
	if (stats) {
		stats->rays++;
		stats->nodes_visited += w.nodes_visited;
		stats->tris_tested += w.tris_tested;
	}
}

#endif

static inline vf WB(splat)(float x)
{
	vf v;
	for (int i = 0; i < WB_LANES; i++)
		v[i] = x;
	return v;
}

/* a > b ? a : b and a < b ? a : b lane by lane, as box_enter() writes
 * them: a NaN in a leaves b. */
static inline vf WB(max)(vf a, vf b)
{
#ifdef WB_MAX
	return WB_MAX(a, b);
#else
	vi m = a > b;
	return (vf)((m & (vi)a) | (~m & (vi)b));
#endif
}

static inline vf WB(min)(vf a, vf b)
{
#ifdef WB_MIN
	return WB_MIN(a, b);
#else
	vi m = a < b;
	return (vf)((m & (vi)a) | (~m & (vi)b));
#endif
}

/* Bit i set when lane i of m is all ones. */
static inline unsigned WB(bits)(vi m)
{
#ifdef WB_BITS
	return WB_BITS(m);
#else
	return lane_bits((const int32_t *)&m, WB_LANES);
#endif
}

/* The same at a group's width. */
static inline unsigned WB(tbits)(vti m)
{
#ifdef WB_TBITS
	return WB_TBITS(m);
#else
	return lane_bits((const int32_t *)&m, WB_TRI_LANES);
#endif
}

static void WB(ray_init)(struct wide_ray *r, ray_prep *p)
{
	r->p = p;
	r->sheared = false;
	for (int k = 0; k < 3; k++) {
		r->org[k] = WB(splat)(p->org[k]);
		r->inv[k] = WB(splat)(p->inv[k]);
		r->near[k] = p->near[k] < 4 ? k : 3 + k;
		r->far[k] = p->far[k] < 4 ? k : 3 + k;
	}
}

/* The triangle constants, at the first leaf: most primary rays of a
 * scene that does not fill the image never reach one, and they would pay
 * three divisions for nothing. */
static void WB(ray_shear)(struct wide_ray *r)
{
	prep_shear(r->p);
	for (int i = 0; i < WB_TRI_LANES; i++) {
		for (int k = 0; k < 3; k++)
			r->torg[k][i] = r->p->org[k];
		r->sx[i] = r->p->sx;
		r->sy[i] = r->p->sy;
	}
	r->sheared = true;
}

/* Bit i set when the ray enters lane i's box before tmax; *t the entries. */
static inline unsigned WB(enter)(const struct wide_ray *r, const WB_NODE *n, float tmax, vf *t)
{
	vf t0 = WB(splat)(r->p->tmin), t1 = WB(splat)(tmax);
	for (int k = 0; k < 3; k++) {
		vf tn = (*(const vf *)n->box[r->near[k]] - r->org[k]) * r->inv[k];
		vf tf = (*(const vf *)n->box[r->far[k]] - r->org[k]) * r->inv[k];
		t0 = WB(max)(tn, t0);
		t1 = WB(min)(tf, t1);
	}
	vi empty = (vi)WB(splat)(0.0f) - 1; /* WIDE_EMPTY in every lane */
	vi in = (t0 <= t1 * WB(splat)(FAR_SCALE)) & (*(const vi *)n->count != empty);
	*t = t0;
	return WB(bits)(in);
}

/*
 * isect()'s shear and sign test on a group's triangles: bit i set when
 * lane i may be hit. Only triangles isect() rejects are dropped; a zero
 * edge passes, for isect()'s double fallback to decide.
 */
static inline unsigned WB(sign)(const struct wide_ray *r, const WB_TRIS *g)
{
	const ray_prep *p = r->p;
	vt x[3], y[3], zero = {0};
	for (int j = 0; j < 3; j++) {
		vt z = *(const vt *)g->v[3 * j + p->kz] - r->torg[p->kz];
		x[j] = (*(const vt *)g->v[3 * j + p->kx] - r->torg[p->kx]) - r->sx * z;
		y[j] = (*(const vt *)g->v[3 * j + p->ky] - r->torg[p->ky]) - r->sy * z;
	}
	vt e0 = x[2] * y[1] - y[2] * x[1];
	vt e1 = x[0] * y[2] - y[0] * x[2];
	vt e2 = x[1] * y[0] - y[1] * x[0];
	vti on_edge = (e0 == zero) | (e1 == zero) | (e2 == zero);
	vti neg = (e0 < zero) | (e1 < zero) | (e2 < zero);
	vti pos = (e0 > zero) | (e1 > zero) | (e2 > zero);
	return WB(tbits)(on_edge | ~(neg & pos));
}

/* True when an any-hit ray is done. */
static bool WB(leaf)(struct wide_walk *w, struct wide_ray *r, const struct wide_entry *e)
{
	const WB_TRIS *g = &w->tris[e->child];
	if (!r->sheared)
		WB(ray_shear)(r);
	for (uint32_t left = e->count; left > 0; g++) {
		uint32_t lanes = left < WB_TRI_LANES ? left : WB_TRI_LANES;
		unsigned mask = WB(sign)(r, g) & ((1u << lanes) - 1);
		w->tris_tested += lanes;
		left -= lanes;
		for (; mask; mask &= mask - 1)
			if (isect_lane(r->p, g, (uint32_t)__builtin_ctz(mask), w->hit) && w->any)
				return true;
	}
	return false;
}

static void WB(walk)(struct wide_walk *w, struct wide_ray *r)
{
	struct wide_entry stack[WB_STACK], cur = {0, 0, r->p->tmin};
	uint32_t sp = 0;
	for (;;) {
		if (cur.count == 0) {
			const WB_NODE *n = &w->nodes[cur.child];
			struct wide_entry e[WB_LANES];
			vf t;
			w->nodes_visited++;
			unsigned mask = WB(enter)(r, n, w->hit->t, &t);
			uint32_t m = sort_lanes(n, mask, (const float *)&t, e);
			for (uint32_t i = m; i-- > 0;)
				prefetch_entry(w, &e[i]);
			for (uint32_t i = m; i-- > 1;)
				stack[sp++] = e[i];
			if (m) {
				cur = e[0];
				continue;
			}
		} else if (WB(leaf)(w, r, &cur)) {
			return;
		}
		do {
			if (sp == 0)
				return;
			cur = stack[--sp];
		} while (!(cur.t <= w->hit->t * FAR_SCALE));
	}
}

static void WB(trace)(struct wide_walk *w, ray_prep *p)
{
	struct wide_ray r;
	WB(ray_init)(&r, p);
	WB(walk)(w, &r);
}
