/*
 * The 8-lane traversal's kernel, included by trace_wide8.c once per
 * instruction set (portable, AVX2, AVX-512VL) under that set's target
 * pragma, with W8(name) naming its functions and W8_MAX, W8_MIN, W8_BITS
 * its lane max, min and sign gather. trace_wide.c's kernel at 8 lanes:
 * the same float operations lane by lane as box_enter() and isect(), so
 * the hits are the stack traversal's. No include guard: meant to be
 * included more than once.
 */

static inline vf8 W8(splat)(float x)
{
	return (vf8){x, x, x, x, x, x, x, x};
}

static void W8(ray_init)(struct w8_ray *r, ray_prep *p)
{
	r->p = p;
	r->sheared = false;
	for (int k = 0; k < 3; k++) {
		r->org[k] = W8(splat)(p->org[k]);
		r->inv[k] = W8(splat)(p->inv[k]);
		r->near[k] = p->near[k] < 4 ? k : 3 + k;
		r->far[k] = p->far[k] < 4 ? k : 3 + k;
	}
}

static void W8(ray_shear)(struct w8_ray *r)
{
	prep_shear(r->p);
	r->sx = W8(splat)(r->p->sx);
	r->sy = W8(splat)(r->p->sy);
	r->sheared = true;
}

/* Bit i set when the ray enters lane i's box before tmax; *t the entries. */
static inline unsigned W8(enter)(const struct w8_ray *r, const struct wide8_node *n, float tmax,
                                 vf8 *t)
{
	vf8 t0 = W8(splat)(r->p->tmin), t1 = W8(splat)(tmax);
	for (int k = 0; k < 3; k++) {
		vf8 tn = (*(const vf8 *)n->box[r->near[k]] - r->org[k]) * r->inv[k];
		vf8 tf = (*(const vf8 *)n->box[r->far[k]] - r->org[k]) * r->inv[k];
		t0 = W8_MAX(tn, t0);
		t1 = W8_MIN(tf, t1);
	}
	vi8 empty = (vi8)W8(splat)(0.0f) - 1;
	vi8 in = (t0 <= t1 * W8(splat)(FAR_SCALE)) & (*(const vi8 *)n->count != empty);
	*t = t0;
	return W8_BITS(in);
}

/* isect()'s shear and sign test on a group's eight triangles (see sign4
 * in trace_wide.c). */
static inline unsigned W8(sign)(const struct w8_ray *r, const struct wide8_tris *g)
{
	const ray_prep *p = r->p;
	vf8 x[3], y[3], zero = W8(splat)(0.0f);
	for (int j = 0; j < 3; j++) {
		vf8 z = *(const vf8 *)g->v[3 * j + p->kz] - r->org[p->kz];
		x[j] = (*(const vf8 *)g->v[3 * j + p->kx] - r->org[p->kx]) - r->sx * z;
		y[j] = (*(const vf8 *)g->v[3 * j + p->ky] - r->org[p->ky]) - r->sy * z;
	}
	vf8 e0 = x[2] * y[1] - y[2] * x[1];
	vf8 e1 = x[0] * y[2] - y[0] * x[2];
	vf8 e2 = x[1] * y[0] - y[1] * x[0];
	vi8 on_edge = (e0 == zero) | (e1 == zero) | (e2 == zero);
	vi8 neg = (e0 < zero) | (e1 < zero) | (e2 < zero);
	vi8 pos = (e0 > zero) | (e1 > zero) | (e2 > zero);
	return W8_BITS(on_edge | ~(neg & pos));
}

/* True when an any-hit ray is done. */
static bool W8(leaf)(struct w8_walk *w, struct w8_ray *r, const struct w8_entry *e)
{
	const struct wide8_tris *g = &w->bvh->tris[e->child];
	if (!r->sheared)
		W8(ray_shear)(r);
	for (uint32_t left = e->count; left > 0; g++) {
		uint32_t lanes = left < WIDE8 ? left : WIDE8;
		unsigned mask = W8(sign)(r, g) & ((1u << lanes) - 1);
		w->tris += lanes;
		left -= lanes;
		for (; mask; mask &= mask - 1)
			if (isect_lane8(r->p, g, (uint32_t)__builtin_ctz(mask), w->hit) && w->any)
				return true;
	}
	return false;
}

static void W8(walk)(struct w8_walk *w, struct w8_ray *r)
{
	const struct wide8_node *nodes = w->bvh->nodes;
	struct w8_entry stack[WIDE8_STACK], cur = {0, 0, r->p->tmin};
	uint32_t sp = 0;
	for (;;) {
		if (cur.count == 0) {
			const struct wide8_node *n = &nodes[cur.child];
			struct w8_entry e[WIDE8];
			vf8 t;
			w->nodes++;
			unsigned mask = W8(enter)(r, n, w->hit->t, &t);
			uint32_t m = sort_lanes8(n, mask, (const float *)&t, e);
			for (uint32_t i = m; i-- > 0;)
				prefetch8(w->bvh, &e[i]);
			for (uint32_t i = m; i-- > 1;)
				stack[sp++] = e[i];
			if (m) {
				cur = e[0];
				continue;
			}
		} else if (W8(leaf)(w, r, &cur)) {
			return;
		}
		do {
			if (sp == 0)
				return;
			cur = stack[--sp];
		} while (!(cur.t <= w->hit->t * FAR_SCALE));
	}
}

static void W8(trace)(struct w8_walk *w, ray_prep *p)
{
	struct w8_ray r;
	W8(ray_init)(&r, p);
	W8(walk)(w, &r);
}
