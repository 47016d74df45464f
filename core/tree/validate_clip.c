/*
 * Coverage of triangles by clipped reference boxes (see validate_clip.h).
 *
 * A spatial-split builder may give a leaf only the box of the piece of a
 * triangle that lies in it, so "the leaf box contains the triangle's box"
 * no longer holds. What rays need instead is that every point of every
 * triangle lies in some leaf that references it: then a ray that hits the
 * triangle enters that leaf (a child's box lies in its parent's, checked by
 * the walk) and finds the hit. This file proves that, per triangle: it
 * subtracts the references' boxes from the triangle one after another,
 * keeping what is left as convex polygons in the triangle's plane, and
 * measures the area that remains uncovered.
 *
 * Exact arithmetic would reject every builder: clipped boxes are computed
 * in float and rounded. So each box is widened by a few ulps of its
 * coordinates plus a millionth of its extent, and a remainder up to a
 * 1e-5 share of the triangle's area passes: a dropped piece from a real
 * split is far larger, rounding slivers are far smaller.
 */
#include <errno.h>
#include <inttypes.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include <bvhlab/clip.h>

#include "tree/validate_clip.h"

#define MAX_PIECES (1 << 18) /* uncovered pieces kept per triangle */
#define PAD_ULPS 0x1p-20 /* 8 float ulps of a coordinate's magnitude */
#define PAD_EXTENT 1e-6
#define AREA_TOLERANCE 1e-5

typedef bvhlab_poly poly; /* the clipper shared with the builders (bvhlab/clip.h) */

/* The uncovered pieces before and after one box's subtraction. */
typedef struct cover {
	poly *pieces[2];
	int count[2], cap[2];
} cover;

/* The leaf's box widened for float rounding (see the top of the file). */
static void padded_box(const bvhlab_node *n, double lo[3], double hi[3])
{
	double extent = 0.0;

	for (int k = 0; k < 3; k++)
		extent = fmax(extent, (double)n->hi[k] - n->lo[k]);
	for (int k = 0; k < 3; k++) {
		double mag = fmax(fabs((double)n->lo[k]), fabs((double)n->hi[k]));
		double pad = PAD_ULPS * mag + PAD_EXTENT * extent;

		lo[k] = (double)n->lo[k] - pad;
		hi[k] = (double)n->hi[k] + pad;
	}
}

static bool disjoint(const poly *p, const double lo[3], const double hi[3])
{
	for (int k = 0; k < 3; k++) {
		bool below = true, above = true;
		for (int i = 0; i < p->n; i++) {
			below = below && p->v[i][k] < lo[k];
			above = above && p->v[i][k] > hi[k];
		}
		if (below || above)
			return true;
	}
	return false;
}

/* Room for one more piece in c->pieces[to] (never moves the other array,
 * which the caller is reading from); false past MAX_PIECES or out of
 * memory. */
static bool room(cover *c, int to)
{
	if (c->count[to] < c->cap[to])
		return true;
	int cap = c->cap[to] ? 2 * c->cap[to] : 64;
	if (cap > MAX_PIECES)
		return false;
	poly *grown = realloc(c->pieces[to], (size_t)cap * sizeof(poly));
	if (!grown)
		return false;
	c->pieces[to] = grown;
	c->cap[to] = cap;
	return true;
}

/*
 * p minus the box, as up to 6 convex pieces appended to c->pieces[to]:
 * what lies below lo[0], then what lies above hi[0] of the rest, and so
 * on. Pieces of no area are dropped; a piece the box misses is kept whole.
 * False when the pieces outgrow MAX_PIECES or memory.
 */
static bool subtract(const poly *p, const double lo[3], const double hi[3], cover *c, int to,
                     double min_area)
{
	poly rest = *p, next, out;

	if (disjoint(&rest, lo, hi)) {
		if (!room(c, to))
			return false;
		c->pieces[to][c->count[to]++] = rest;
		return true;
	}
	for (int k = 0; k < 3 && rest.n > 0; k++) {
		for (int side = 0; side < 2; side++) {
			double at = side ? hi[k] : lo[k], sign = side ? 1.0 : -1.0;

			bvhlab_poly_clip(&rest, k, at, sign, &out);
			if (out.n >= 3 && bvhlab_poly_area(&out) > min_area) {
				if (!room(c, to))
					return false;
				c->pieces[to][c->count[to]++] = out;
			}
			bvhlab_poly_clip(&rest, k, at, -sign, &next);
			rest = next;
		}
	}
	return true;
}

typedef struct refs {
	uint32_t *offset; /* [prim_count + 1] first entry of each primitive */
	uint32_t *leaf;   /* [index_count] leaves referencing each primitive */
} refs;

#define FAIL(err, ...) (snprintf((err)->message, sizeof((err)->message), __VA_ARGS__), -EINVAL)

/* A zero-area triangle cannot be measured by area: each vertex in some box. */
static int check_degenerate(const bvhlab_tree *t, const poly *tri, const uint32_t *leaves,
                            uint32_t count, uint32_t prim, bvhlab_error *err)
{
	for (int j = 0; j < 3; j++) {
		bool inside = false;

		for (uint32_t r = 0; r < count && !inside; r++) {
			double lo[3], hi[3];

			padded_box(&t->nodes[leaves[r]], lo, hi);
			inside = true;
			for (int k = 0; k < 3; k++)
				inside = inside && lo[k] <= tri->v[j][k] && tri->v[j][k] <= hi[k];
		}
		if (!inside)
			return FAIL(err, "primitive %" PRIu32 " (zero area): vertex %d lies in none "
			            "of its %" PRIu32 " reference(s)' leaf boxes", prim, j, count);
	}
	return 0;
}

/* Every reference's box overlaps the triangle; together they cover it. */
static int check_prim(const bvhlab_tree *t, const bvhlab_build_input *in, const refs *r,
                      uint32_t prim, cover *c, bvhlab_error *err)
{
	const uint32_t *leaves = r->leaf + r->offset[prim];
	uint32_t count = r->offset[prim + 1] - r->offset[prim];
	double full, left = 0.0, lo[3], hi[3];
	int cur = 0;
	poly tri, part;

	bvhlab_poly_triangle(&tri, in->vertices, &in->indices[3 * (size_t)prim]);
	full = bvhlab_poly_area(&tri);
	if (!(full > 0.0))
		return check_degenerate(t, &tri, leaves, count, prim, err);
	c->count[0] = c->count[1] = 0;
	if (!room(c, 0))
		return FAIL(err, "out of memory checking primitive %" PRIu32, prim);
	c->pieces[0][0] = tri;
	c->count[0] = 1;
	for (uint32_t i = 0; i < count; i++) {
		padded_box(&t->nodes[leaves[i]], lo, hi);
		part = tri;
		bvhlab_poly_clip_box(&part, lo, hi);
		if (part.n == 0) {
			const bvhlab_node *n = &t->nodes[leaves[i]];
			return FAIL(err, "node %" PRIu32 ": box (%g, %g, %g) - (%g, %g, %g) misses "
			            "primitive %" PRIu32 " (a reference's box must overlap its "
			            "triangle)", leaves[i], n->lo[0], n->lo[1], n->lo[2], n->hi[0],
			            n->hi[1], n->hi[2], prim);
		}
		c->count[!cur] = 0;
		for (int j = 0; j < c->count[cur]; j++)
			if (!subtract(&c->pieces[cur][j], lo, hi, c, !cur, 1e-3 * AREA_TOLERANCE * full))
				return FAIL(err, "primitive %" PRIu32 ": its %" PRIu32 " references "
				            "leave it in more than %d pieces", prim, count, MAX_PIECES);
		cur = !cur;
	}
	for (int j = 0; j < c->count[cur]; j++)
		left += bvhlab_poly_area(&c->pieces[cur][j]);
	if (left > AREA_TOLERANCE * full)
		return FAIL(err, "primitive %" PRIu32 ": its %" PRIu32 " reference(s)' leaf boxes "
		            "leave %.3g%% of its area uncovered (leaf %" PRIu32 " among them)", prim,
		            count, 100.0 * left / full, leaves[0]);
	return 0;
}

/* Counting sort of the slots by primitive: each primitive's leaves. */
static void group_refs(const bvhlab_tree *t, const bvhlab_build_input *in,
                       const uint32_t *slot_leaf, refs *r)
{
	uint32_t sum = 0;

	memset(r->offset, 0, ((size_t)in->prim_count + 1) * sizeof(uint32_t));
	for (uint32_t s = 0; s < t->index_count; s++)
		r->offset[t->prim_index[s]]++;
	for (uint32_t p = 0; p <= in->prim_count; p++) {
		uint32_t n = r->offset[p];

		r->offset[p] = sum;
		sum += n;
	}
	for (uint32_t s = 0; s < t->index_count; s++)
		r->leaf[r->offset[t->prim_index[s]]++] = slot_leaf[s];
	for (uint32_t p = in->prim_count; p > 0; p--)
		r->offset[p] = r->offset[p - 1];
	r->offset[0] = 0;
}

int validate_coverage(const bvhlab_tree *tree, const bvhlab_build_input *input,
                      const uint32_t *slot_leaf, bvhlab_error *err)
{
	refs r = { malloc(((size_t)input->prim_count + 1) * sizeof(uint32_t)),
	           malloc(((size_t)tree->index_count + 1) * sizeof(uint32_t)) };
	cover *c = calloc(1, sizeof(*c));
	int rc = 0;

	if (!r.offset || !r.leaf || !c) {
		snprintf(err->message, sizeof(err->message),
		         "out of memory checking the coverage of %" PRIu32 " references "
		         "(not checked, so not found invalid)",
		         tree->index_count);
		rc = -ENOMEM;
		goto out;
	}
	group_refs(tree, input, slot_leaf, &r);
	for (uint32_t p = 0; p < input->prim_count && rc == 0; p++)
		rc = check_prim(tree, input, &r, p, c, err);
out:
	free(r.offset);
	free(r.leaf);
	if (c) {
		free(c->pieces[0]);
		free(c->pieces[1]);
	}
	free(c);
	return rc;
}
