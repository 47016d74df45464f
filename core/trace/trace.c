/*
 * bvhlab — the core's ray traversal: the watertight ray/triangle test, a
 * closest-hit traversal of the standard layout and a brute-force reference.
 *
 * Every builder's tree is measured with this traverser, so it has to be
 * correct on any valid tree (any depth, any node order) and reasonably fast:
 * per-ray constants are computed once, the stack lives on the C stack and
 * nothing is allocated unless a tree is deeper than that stack.
 *
 * The triangle test is Woop, Benthin and Wald, "Watertight Ray/Triangle
 * Intersection", JCGT 2(1), 2013: vertices are translated to the ray origin,
 * sheared so the ray runs along +z, and the 2D edge functions decide the hit.
 * Neighbouring triangles evaluate a shared edge with bit-identical inputs,
 * so a ray through an edge or a vertex cannot slip between them.
 */
#include <float.h>
#include <math.h>
#include <stdlib.h>
#include <string.h>

#include <bvhlab/trace.h>
#include <bvhlab/tree.h>

/* The blocked brute force relies on its vector pass computing the very same
 * floats as the scalar test; a fused multiply-add in one and not the other
 * would break that. GCC does not contract in ISO C mode; clang needs telling. */
#if defined(__clang__)
#pragma STDC FP_CONTRACT OFF
#endif

/*
 * The slab test rounds; Ize ("Robust BVH Ray Traversal", JCGT 2013) shows
 * scaling the far distance by 1 + 2 gamma(3) keeps it conservative. The
 * sheared triangle test has rounding of its own (a hit it reports may lie a
 * few ulps outside the triangle's exact box), so the margin is wider: a few
 * extra boxes visited cost nothing, a missed hit makes validation lie.
 */
#define FAR_SCALE (1.0f + 32.0f * FLT_EPSILON)

#define LOCAL_STACK 64
#define BRUTE_BLOCK 16

/* Per-ray constants of the triangle and slab tests. */
typedef struct ray_prep {
	float org[3];
	float tmin;
	int kx, ky, kz;  /* kz: dominant direction axis */
	float sx, sy, sz; /* shear and scale to ray space */
	float inv[3];     /* 1 / dir: +-inf for +-0 components */
	int near[3], far[3]; /* the planes a ray enters and leaves each slab by, as
	                      * float offsets into a node: lo[k] is k, hi[k] is 4 + k */
} ray_prep;

typedef struct stack_entry {
	uint32_t node;
	float t; /* entry distance of the node's box, to skip it once beaten */
} stack_entry;

typedef struct trace_state {
	const bvhlab_tree *tree;
	const bvhlab_scene *scene;
	const ray_prep *p;
	bvhlab_hit *hit;
	uint64_t nodes, tris;
	bool any;  /* any-hit: the first hit ends the traversal */
	bool done;
} trace_state;

/* False for a zero, infinite or NaN direction: such a ray hits nothing. */
static bool prep_ray(const bvhlab_ray *ray, ray_prep *p)
{
	const float *d = ray->dir;
	float ax = fabsf(d[0]), ay = fabsf(d[1]), az = fabsf(d[2]);
	int k;

	if (!isfinite(ax) || !isfinite(ay) || !isfinite(az) || ax + ay + az == 0.0f)
		return false;
	p->kz = ax >= ay ? (ax >= az ? 0 : 2) : (ay >= az ? 1 : 2);
	p->kx = (p->kz + 1) % 3;
	p->ky = (p->kx + 1) % 3;
	if (d[p->kz] < 0.0f) { /* keep the winding, so the sign of det means a side */
		k = p->kx;
		p->kx = p->ky;
		p->ky = k;
	}
	p->sx = d[p->kx] / d[p->kz];
	p->sy = d[p->ky] / d[p->kz];
	p->sz = 1.0f / d[p->kz];
	for (k = 0; k < 3; k++) {
		p->org[k] = ray->org[k];
		p->inv[k] = 1.0f / d[k];
		p->near[k] = signbit(p->inv[k]) ? 4 + k : k;
		p->far[k] = signbit(p->inv[k]) ? k : 4 + k;
	}
	p->tmin = ray->tmin;
	return true;
}

/* Edge functions in double, for the case where float rounding gave exactly 0
 * and the sign that decides between two neighbours would be lost. */
static void edges_double(const float a[2], const float b[2], const float c[2], float uvw[3])
{
	uvw[0] = (float)((double)c[0] * b[1] - (double)c[1] * b[0]);
	uvw[1] = (float)((double)a[0] * c[1] - (double)a[1] * c[0]);
	uvw[2] = (float)((double)b[0] * a[1] - (double)b[1] * a[0]);
}

/* Watertight, two-sided test; on a hit with tmin < t < tmax fills t, u, v. */
static inline bool isect(const ray_prep *p, const float *v0, const float *v1,
                         const float *v2, float tmax, float out[3])
{
	const int kx = p->kx, ky = p->ky, kz = p->kz;
	float az = v0[kz] - p->org[kz], bz = v1[kz] - p->org[kz], cz = v2[kz] - p->org[kz];
	float a[2] = { v0[kx] - p->org[kx] - p->sx * az, v0[ky] - p->org[ky] - p->sy * az };
	float b[2] = { v1[kx] - p->org[kx] - p->sx * bz, v1[ky] - p->org[ky] - p->sy * bz };
	float c[2] = { v2[kx] - p->org[kx] - p->sx * cz, v2[ky] - p->org[ky] - p->sy * cz };
	float e[3] = { c[0] * b[1] - c[1] * b[0], a[0] * c[1] - a[1] * c[0],
	               b[0] * a[1] - b[1] * a[0] };
	float det, t;

	if (e[0] == 0.0f || e[1] == 0.0f || e[2] == 0.0f)
		edges_double(a, b, c, e);
	if ((e[0] < 0.0f || e[1] < 0.0f || e[2] < 0.0f) &&
	    (e[0] > 0.0f || e[1] > 0.0f || e[2] > 0.0f))
		return false;
	det = e[0] + e[1] + e[2];
	if (det == 0.0f)
		return false;
	t = p->sz * (e[0] * az + e[1] * bz + e[2] * cz) / det;
	if (!(t > p->tmin && t < tmax)) /* NaN from bad vertices fails here too */
		return false;
	out[0] = t;
	out[1] = e[1] / det; /* weight of v1 */
	out[2] = e[2] / det; /* weight of v2 */
	return true;
}

static inline bool isect_prim(const ray_prep *p, const bvhlab_scene *scene, uint32_t prim,
                              bvhlab_hit *hit)
{
	const uint32_t *idx = scene->indices + 3 * (size_t)prim;
	const float *vtx = scene->vertices;
	float out[3];

	if (!isect(p, vtx + 3 * (size_t)idx[0], vtx + 3 * (size_t)idx[1],
	           vtx + 3 * (size_t)idx[2], hit->t, out))
		return false;
	hit->t = out[0];
	hit->u = out[1];
	hit->v = out[2];
	hit->prim = prim;
	return true;
}

/*
 * Entry distance of the ray into a box, or INFINITY when it misses within
 * (tmin, tmax). Planes are picked by the direction's sign, so a zero
 * component gives (plane - org) * inf: +-inf when the origin is outside the
 * slab, NaN when it lies exactly on a plane. The comparisons are written so
 * a NaN leaves the running interval unchanged: a ray running inside a face
 * of the box is inside the slab.
 */
static inline float box_enter(const ray_prep *p, const bvhlab_node *n, float tmax)
{
	const float *f = (const float *)(const void *)n; /* lo at 0..2, hi at 4..6 */
	float t0 = p->tmin, t1 = tmax;
	int k;

	for (k = 0; k < 3; k++) {
		float tn = (f[p->near[k]] - p->org[k]) * p->inv[k];
		float tf = (f[p->far[k]] - p->org[k]) * p->inv[k];

		t0 = tn > t0 ? tn : t0;
		t1 = tf < t1 ? tf : t1;
	}
	return t0 <= t1 * FAR_SCALE ? t0 : INFINITY;
}

/* Ray-space 2D vertices of a block of triangles, structure of arrays. */
typedef struct sheared_block {
	float x[3][BRUTE_BLOCK], y[3][BRUTE_BLOCK];
	int pass[BRUTE_BLOCK];
} sheared_block;

static void shear_block(const ray_prep *p, const bvhlab_scene *scene, uint32_t base,
                        uint32_t m, sheared_block *b)
{
	const uint32_t *idx = scene->indices + 3 * (size_t)base;
	uint32_t i;
	int j;

	for (i = 0; i < m; i++) {
		for (j = 0; j < 3; j++) {
			const float *v = scene->vertices + 3 * (size_t)idx[3 * i + j];
			float z = v[p->kz] - p->org[p->kz];

			b->x[j][i] = v[p->kx] - p->org[p->kx] - p->sx * z;
			b->y[j][i] = v[p->ky] - p->org[p->ky] - p->sy * z;
		}
	}
}

/*
 * The sign test of isect() over a block, branch-free so the compiler
 * vectorises it. It performs exactly isect()'s float operations, so it only
 * drops triangles isect() would drop; any zero edge goes to isect(), whose
 * double fallback may change the decision.
 */
static void sign_block(sheared_block *b)
{
	int i;

	for (i = 0; i < BRUTE_BLOCK; i++) {
		float e0 = b->x[2][i] * b->y[1][i] - b->y[2][i] * b->x[1][i];
		float e1 = b->x[0][i] * b->y[2][i] - b->y[0][i] * b->x[2][i];
		float e2 = b->x[1][i] * b->y[0][i] - b->y[1][i] * b->x[0][i];
		int zero = (e0 == 0.0f) | (e1 == 0.0f) | (e2 == 0.0f);
		int neg = (e0 < 0.0f) | (e1 < 0.0f) | (e2 < 0.0f);
		int pos = (e0 > 0.0f) | (e1 > 0.0f) | (e2 > 0.0f);

		b->pass[i] = zero | !(neg & pos);
	}
}

/* Brute force is the reference the validation trusts, and over a few
 * million triangles it dominates validation time: hence the blocking. */
static void brute_all(const bvhlab_scene *scene, const ray_prep *p, bvhlab_hit *hit)
{
	sheared_block b;
	uint32_t base, i, m;

	memset(&b, 0, sizeof(b));
	for (base = 0; base < scene->triangle_count; base += m) {
		m = scene->triangle_count - base;
		m = m < BRUTE_BLOCK ? m : BRUTE_BLOCK;
		shear_block(p, scene, base, m, &b);
		sign_block(&b);
		for (i = 0; i < m; i++)
			if (b.pass[i])
				isect_prim(p, scene, base + i, hit);
	}
}

static void leaf(trace_state *s, const bvhlab_node *n)
{
	const bvhlab_tree *tree = s->tree;
	uint32_t i;

	/* An invalid tree must not make the traverser read out of bounds; what
	 * it skips shows up as a mismatch in bvhlab_validate_rays. */
	if (n->first > tree->index_count || n->count > tree->index_count - n->first)
		return;
	for (i = n->first; i < n->first + n->count; i++) {
		uint32_t prim = tree->prim_index[i];

		if (prim >= s->scene->triangle_count)
			continue;
		s->tris++;
		if (isect_prim(s->p, s->scene, prim, s->hit) && s->any) {
			s->done = true;
			return;
		}
	}
}

/* Why a traversal ended early. */
enum { TRACE_OK, TRACE_INVALID, TRACE_NOMEM };

/* Moves the stack to the heap, twice as large. A valid tree never has more
 * pending nodes than nodes, so more means a cycle: give up. */
static int grow_stack(stack_entry **stack, uint32_t *cap, uint32_t node_count)
{
	uint32_t new_cap = *cap * 2;
	stack_entry *grown;

	if (*cap > node_count)
		return TRACE_INVALID;
	grown = malloc((size_t)new_cap * sizeof(*grown));
	if (!grown)
		return TRACE_NOMEM;
	memcpy(grown, *stack, (size_t)*cap * sizeof(*grown));
	if (*cap != LOCAL_STACK)
		free(*stack);
	*stack = grown;
	*cap = new_cap;
	return TRACE_OK;
}

/*
 * Picks the next node below an inner node: the nearer child, pushing the
 * farther one. Returns false when neither child is hit, or when the pushed
 * entry could not be stored (*fail says why).
 */
static bool descend(trace_state *s, const bvhlab_node *n, uint32_t *node, stack_entry **stack,
                    uint32_t *sp, uint32_t *cap, int *fail)
{
	const bvhlab_node *nodes = s->tree->nodes;
	uint32_t near = n->first, far = n->first + 1;
	float tn, tf;

	if (n->first >= s->tree->node_count - 1)
		return false;
	tn = box_enter(s->p, &nodes[near], s->hit->t);
	tf = box_enter(s->p, &nodes[far], s->hit->t);
	if (tf < tn) {
		float t = tn;

		tn = tf;
		tf = t;
		near = far;
		far = n->first;
	}
	if (tn == INFINITY)
		return false;
	if (tf != INFINITY) {
		if (*sp == *cap) {
			*fail = grow_stack(stack, cap, s->tree->node_count);
			if (*fail != TRACE_OK)
				return false;
		}
		(*stack)[(*sp)++] = (stack_entry){ far, tf };
	}
	*node = near;
	return true;
}

static bool pop(trace_state *s, const stack_entry *stack, uint32_t *sp, uint32_t *node)
{
	while (*sp) {
		const stack_entry *e = &stack[--*sp];

		if (e->t <= s->hit->t * FAR_SCALE) {
			*node = e->node;
			return true;
		}
	}
	return false;
}

static void traverse(trace_state *s)
{
	const bvhlab_tree *tree = s->tree;
	stack_entry local[LOCAL_STACK], *stack = local;
	uint32_t sp = 0, cap = LOCAL_STACK, node = 0;
	int fail = TRACE_OK;

	if (box_enter(s->p, &tree->nodes[0], s->hit->t) == INFINITY)
		return;
	for (;;) {
		const bvhlab_node *n = &tree->nodes[node];

		/* A valid tree visits each node at most once per ray; more means a
		 * cycle, and stopping keeps an invalid tree from hanging us. */
		if (++s->nodes > tree->node_count)
			break;
		if (n->count) {
			leaf(s, n);
			if (s->done)
				break;
		} else if (descend(s, n, &node, &stack, &sp, &cap, &fail)) {
			continue;
		} else if (fail == TRACE_NOMEM) {
			brute_all(s->scene, s->p, s->hit); /* slow, but still exact */
			break;
		} else if (fail == TRACE_INVALID) {
			break;
		}
		if (!pop(s, stack, &sp, &node))
			break;
	}
	if (stack != local)
		free(stack);
}

bool bvhlab_intersect_triangle(const bvhlab_ray *ray, const bvhlab_scene *scene,
                               uint32_t prim, bvhlab_hit *hit)
{
	ray_prep p;

	if (!prep_ray(ray, &p))
		return false;
	return isect_prim(&p, scene, prim, hit);
}

static void hit_init(const bvhlab_ray *ray, bvhlab_hit *hit)
{
	hit->t = ray->tmax;
	hit->u = hit->v = 0.0f;
	hit->prim = BVHLAB_NO_HIT;
}

/* Stats: nodes_visited counts the nodes entered (root included, each inner
 * node's two child boxes are tested from it), tris_tested the triangle tests. */
static void trace(const bvhlab_tree *tree, const bvhlab_scene *scene, const bvhlab_ray *ray,
                  bvhlab_hit *hit, bvhlab_trace_stats *stats, bool any)
{
	trace_state s = { tree, scene, NULL, hit, 0, 0, any, false };
	ray_prep p;

	hit_init(ray, hit);
	if (prep_ray(ray, &p) && tree->node_count > 0) {
		s.p = &p;
		traverse(&s);
	}
	if (stats) {
		stats->rays++;
		stats->nodes_visited += s.nodes;
		stats->tris_tested += s.tris;
	}
}

void bvhlab_trace_closest(const bvhlab_tree *tree, const bvhlab_scene *scene,
                          const bvhlab_ray *ray, bvhlab_hit *hit, bvhlab_trace_stats *stats)
{
	trace(tree, scene, ray, hit, stats, false);
}

/* Occlusion rays only need to know that something is in the way, so the
 * first triangle hit ends the walk (the hit is not the closest one). */
bool bvhlab_trace_any(const bvhlab_tree *tree, const bvhlab_scene *scene,
                      const bvhlab_ray *ray, bvhlab_hit *hit, bvhlab_trace_stats *stats)
{
	trace(tree, scene, ray, hit, stats, true);
	return hit->prim != BVHLAB_NO_HIT;
}

void bvhlab_trace_brute(const bvhlab_scene *scene, const bvhlab_ray *ray, bvhlab_hit *hit)
{
	ray_prep p;

	hit_init(ray, hit);
	if (prep_ray(ray, &p))
		brute_all(scene, &p, hit);
}
