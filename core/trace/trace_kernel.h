/*
 * The traversal kernel shared by the stack and stackless traversals and the
 * brute force (trace.c, trace_stackless.c): per-ray constants, the
 * watertight ray/triangle test and the slab test. Static inline: both
 * traversals' inner loops need them inlined.
 *
 * The triangle test is Woop, Benthin and Wald, "Watertight Ray/Triangle
 * Intersection", JCGT 2(1), 2013: vertices are translated to the ray origin,
 * sheared so the ray runs along +z, and the 2D edge functions decide the hit.
 * Neighbouring triangles evaluate a shared edge with bit-identical inputs,
 * so a ray through an edge or a vertex cannot slip between them.
 */
#ifndef BVHLAB_CORE_TRACE_KERNEL_H
#define BVHLAB_CORE_TRACE_KERNEL_H

#include <float.h>
#include <math.h>
#include <stdbool.h>
#include <stdint.h>

#include <bvhlab/trace.h>
#include <bvhlab/tree.h>

#include "trace/trace_layout.h"

/* The blocked brute force (trace.c) relies on its vector pass computing the very same
 * floats as the scalar test; a fused multiply-add in one and not the other
 * would break that. GCC does not contract in ISO C mode; clang needs telling. */
#if defined(__clang__)
#pragma STDC FP_CONTRACT OFF
#endif

/* FAR_SCALE, the slab test's margin, is trace_layout.h's (shared with
 * the device kernels). */

/* Per-ray constants of the triangle and slab tests. */
typedef struct ray_prep {
	float org[3];
	float tmin;
	float dir[3];     /* the stackless traversal orders children along it */
	int kx, ky, kz;  /* kz: dominant direction axis */
	float sx, sy, sz; /* shear and scale to ray space */
	float inv[3];     /* 1 / dir: +-inf for +-0 components */
	int near[3], far[3]; /* the planes a ray enters and leaves each slab by, as
	                      * float offsets into a node: lo[k] is k, hi[k] is 4 + k */
} ray_prep;


/* The slab test's constants. False for a zero, infinite or NaN direction:
 * such a ray hits nothing. */
static inline bool prep_box(const bvhlab_ray *ray, ray_prep *p)
{
	const float *d = ray->dir;
	float ax = fabsf(d[0]), ay = fabsf(d[1]), az = fabsf(d[2]);

	if (!isfinite(ax) || !isfinite(ay) || !isfinite(az) || ax + ay + az == 0.0f)
		return false;
	for (int k = 0; k < 3; k++) {
		p->org[k] = ray->org[k];
		p->dir[k] = d[k];
		p->inv[k] = 1.0f / d[k];
		p->near[k] = signbit(p->inv[k]) ? 4 + k : k;
		p->far[k] = signbit(p->inv[k]) ? k : 4 + k;
	}
	p->tmin = ray->tmin;
	return true;
}

/* The triangle test's constants, after prep_box(): a traversal may leave
 * them until its first leaf. */
static inline void prep_shear(ray_prep *p)
{
	const float *d = p->dir;
	float ax = fabsf(d[0]), ay = fabsf(d[1]), az = fabsf(d[2]);
	int k;

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
}

/* Both. */
static inline bool prep_ray(const bvhlab_ray *ray, ray_prep *p)
{
	if (!prep_box(ray, p))
		return false;
	prep_shear(p);
	return true;
}

/* Edge functions in double, for the case where float rounding gave exactly 0
 * and the sign that decides between two neighbours would be lost. */
static inline void edges_double(const float a[2], const float b[2], const float c[2], float uvw[3])
{
	uvw[0] = (float)((double)c[0] * b[1] - (double)c[1] * b[0]);
	uvw[1] = (float)((double)a[0] * c[1] - (double)a[1] * c[0]);
	uvw[2] = (float)((double)b[0] * a[1] - (double)b[1] * a[0]);
}

/* Watertight, two-sided test; on a hit with tmin < t <= tmax fills t, u, v. */
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
	/* t == tmax passes: isect_prim settles ties. NaN from bad vertices fails. */
	if (!(t > p->tmin && t <= tmax))
		return false;
	out[0] = t;
	out[1] = e[1] / det; /* weight of v1 */
	out[2] = e[2] / det; /* weight of v2 */
	return true;
}

/* Triangle prim's hit out (t, u, v) from isect() into hit, unless it
 * only ties with hit's: an exact tie in t goes to the smaller id, so every
 * visiting order (stack, stackless, brute force) picks the same triangle. */
static inline bool take_hit(bvhlab_hit *hit, uint32_t prim, const float out[3])
{
	if (out[0] == hit->t && (hit->prim == BVHLAB_NO_HIT || prim >= hit->prim))
		return false;
	hit->t = out[0];
	hit->u = out[1];
	hit->v = out[2];
	hit->prim = prim;
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
	return take_hit(hit, prim, out);
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


/*
 * One triangle reference of a leaf: prim_index[slot]'s triangle tested
 * either through the scene (tris NULL) or from a copy of the vertices in
 * slot order (9 floats per slot, trace_view_copy). The copy turns a leaf's
 * two dependent random reads per triangle (its indices, then three
 * vertices) into one sequential read; the floats, and so the hits, are the
 * same. Out-of-range ids are skipped (an invalid tree must not make the
 * traverser read out of bounds); false also for a miss.
 */
static inline bool isect_slot(const ray_prep *p, const bvhlab_tree *tree,
                              const bvhlab_scene *scene, const float *tris, uint32_t slot,
                              bvhlab_hit *hit)
{
	uint32_t prim = tree->prim_index[slot];
	float out[3];
	if (!tris)
		return isect_prim(p, scene, prim, hit);
	const float *v = tris + 9 * (size_t)slot;
	if (!isect(p, v, v + 3, v + 6, hit->t, out))
		return false;
	return take_hit(hit, prim, out);
}

/*
 * What a traversal reads: the tree's nodes or a copy placed so sibling
 * pairs share a cache line, and optionally the vertex copy (tris) and the
 * parent links (parents, stackless only). trace_view_init makes the plain
 * view of a tree; trace_view_copy the batch tracer's copies.
 */
struct wide_bvh; /* trace_wide.h */
struct wide8_bvh; /* trace_wide8.h */

struct trace_view {
	const bvhlab_node *nodes;
	const float *tris;
	const uint32_t *parents;
	const struct wide_bvh *wide;   /* the 4-lane traversals' nodes (wide, wide4, and
	                                * wide8 on a tree of width 4 or less) */
	const struct wide8_bvh *wide8; /* wide8's nodes of a tree of width 5 to 8 */
	int wide8_isa;                 /* trace_wide8.c's code path for them */
	void *owned; /* what trace_view_free releases */
	float *owned_tris;
	struct wide_bvh *owned_wide;
	struct wide8_bvh *owned_wide8;
};

static inline struct trace_view trace_view_plain(const bvhlab_tree *tree)
{
	return (struct trace_view){.nodes = tree->nodes};
}

/* Node copy aligned for sibling pairs, plus the vertex copy. 0 or -ENOMEM. */
int trace_view_copy(const bvhlab_tree *tree, const bvhlab_scene *scene, struct trace_view *v);
/* Adds the wide nodes of `traversal` (wide, wide4, wide8: trace_view.c
 * says which layout each gets) to a view: 0, -EINVAL (links that do not
 * make a tree), -ENOMEM. */
int trace_view_wide(const bvhlab_tree *tree, const bvhlab_scene *scene, int traversal,
                    struct trace_view *v);
/* Whether a traversal walks a wide view (wide, wide4, wide8). */
static inline bool trace_is_wide(int traversal)
{
	return traversal == BVHLAB_TRAVERSAL_WIDE || traversal == BVHLAB_TRAVERSAL_WIDE4 ||
	       traversal == BVHLAB_TRAVERSAL_WIDE8;
}
void trace_view_free(struct trace_view *v);

/* The stack traversal of trace.c through a view: what bvhlab_trace_closest
 * and bvhlab_trace_any do, for the batch tracer. */
void trace_ray_stack(const bvhlab_tree *tree, const bvhlab_scene *scene,
                     const struct trace_view *view, const bvhlab_ray *ray, bool any,
                     bvhlab_hit *hit, bvhlab_trace_stats *stats);

/* The wide traversal of trace_wide.c, likewise (view->wide set). */
void trace_ray_wide(const bvhlab_tree *tree, const bvhlab_scene *scene,
                    const struct trace_view *view, const bvhlab_ray *ray, bool any,
                    bvhlab_hit *hit, bvhlab_trace_stats *stats);

/* The stackless traversal of trace_stackless.c, likewise. */
void trace_ray_stackless(const bvhlab_tree *tree, const bvhlab_scene *scene,
                         const struct trace_view *view, const bvhlab_ray *ray, bool any,
                         bvhlab_hit *hit, bvhlab_trace_stats *stats);

/* The stackless walk of a tree whose leaves hold something other than
 * triangles (a two-level top's instances): on_leaf(ctx, leaf) for each
 * leaf the ray enters, in the walk's order, with hit->t the walk's tmax,
 * which on_leaf may lower; true from it ends the walk. hit is the
 * caller's, not initialised here; stats (may be NULL) gains the nodes
 * entered. (trace_stackless.c) */
void trace_walk_stackless(const bvhlab_tree *tree, const uint32_t *parents,
                          const bvhlab_ray *ray, bvhlab_hit *hit,
                          bool (*on_leaf)(void *ctx, const bvhlab_node *n), void *ctx,
                          bvhlab_trace_stats *stats);

#endif /* BVHLAB_CORE_TRACE_KERNEL_H */
