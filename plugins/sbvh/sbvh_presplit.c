/*
 * Pre-splitting for the sbvh plugin (early split clipping: Ernst & Greiner
 * 2007, Dammertz & Keller 2008; the budgeted form of Karras & Aila 2013):
 * before the top-down build, the references with the largest boxes are cut
 * in two, again and again, until `presplit` of the budget's spare room is
 * used. Each cut is at the middle of the box's longest side and clips the
 * triangle exactly, so a long diagonal triangle becomes a chain of pieces
 * with small boxes that a plain SAH sweep can sort apart.
 *
 * It is a different bet from spatial splits: those cut only where the
 * greedy SAH of one node says a cut pays at once, which on scenes of long
 * thin triangles crossing one another (needles) is almost nowhere, since
 * the gain only shows a few levels down. Pre-splitting spends the room up
 * front on the references that waste the most area.
 *
 * A triangle is cut at most MAX_CUTS times deep (8 pieces): cutting a
 * lone huge triangle into many tiles only stacks levels of nodes over it,
 * each costing about its whole box again; spatial splits decide where
 * cutting further pays.
 *
 * Order: a max-heap on the area a reference's box wastes, its half
 * surface area minus the area of the triangle's piece in it (a flat
 * piece's tightest box has a half surface of at least the piece's area):
 * a long diagonal needle wastes nearly all of its box, a wall lying in
 * an axis plane almost none, and cutting the latter would only add
 * nodes. Ties go to the lower index, so the result is the same on every
 * run (it runs on one thread).
 */
#include <errno.h>
#include <stdlib.h>
#include <string.h>

#include "sbvh.h"
#include "tri_clip.h"

#define MAX_CUTS 3

static double ref_area(const sbvh_ref *r)
{
	double d[3];

	for (int k = 0; k < 3; k++)
		d[k] = r->hi[k] > r->lo[k] ? (double)r->hi[k] - r->lo[k] : 0.0;
	return d[0] * d[1] + d[1] * d[2] + d[2] * d[0];
}

typedef struct heap {
	uint32_t *at;   /* reference indices */
	double *key;    /* [reference] its area */
	uint32_t n;
} heap;

static bool above(const heap *h, uint32_t a, uint32_t b)
{
	return h->key[a] > h->key[b] || (h->key[a] == h->key[b] && a < b);
}

static void sift_up(heap *h, uint32_t i)
{
	while (i > 0 && above(h, h->at[i], h->at[(i - 1) / 2])) {
		uint32_t p = (i - 1) / 2, t = h->at[i];
		h->at[i] = h->at[p];
		h->at[p] = t;
		i = p;
	}
}

static void sift_down(heap *h, uint32_t i)
{
	for (;;) {
		uint32_t l = 2 * i + 1, r = l + 1, m = i, t;
		if (l < h->n && above(h, h->at[l], h->at[m]))
			m = l;
		if (r < h->n && above(h, h->at[r], h->at[m]))
			m = r;
		if (m == i)
			return;
		t = h->at[i];
		h->at[i] = h->at[m];
		h->at[m] = t;
		i = m;
	}
}

static void push(heap *h, const sbvh_ref *refs, uint32_t i, double piece_area)
{
	h->key[i] = ref_area(&refs[i]) - piece_area;
	h->at[h->n++] = i;
	sift_up(h, h->n - 1);
}

/* The triangle's part inside refs[i]'s box, and that part's area. */
static double piece(const sbvh_build *B, const sbvh_ref *r, tri_poly *p)
{
	const bvhlab_aabb box = { { r->lo[0], r->lo[1], r->lo[2] },
		                  { r->hi[0], r->hi[1], r->hi[2] } };

	bvhlab_poly_triangle(p, B->in->vertices, &B->in->indices[3 * (size_t)r->prim]);
	tri_poly_clip_box(p, &box);
	return bvhlab_poly_area(p);
}

/* Cuts refs[i] at the middle of its longest side into refs[i] and
 * refs[j] (areas of their pieces in *ai, *aj); false when one side holds
 * nothing of the triangle. */
static bool cut(const sbvh_build *B, sbvh_ref *refs, uint32_t i, uint32_t j, double *ai,
                double *aj)
{
	sbvh_ref *r = &refs[i];
	const bvhlab_aabb box = { { r->lo[0], r->lo[1], r->lo[2] },
		                  { r->hi[0], r->hi[1], r->hi[2] } };
	bvhlab_aabb lb, hb;
	tri_poly p, l, h;
	int k = 0;

	for (int m = 1; m < 3; m++)
		if (r->hi[m] - r->lo[m] > r->hi[k] - r->lo[k])
			k = m;
	float pos = 0.5f * (r->lo[k] + r->hi[k]);
	if (!(pos > r->lo[k] && pos < r->hi[k]) || r->cuts >= MAX_CUTS)
		return false;
	piece(B, r, &p);
	tri_poly_split(&p, k, pos, &l, &h);
	tri_poly_bounds(&l, &box, &lb);
	tri_poly_bounds(&h, &box, &hb);
	if (!(lb.lo[0] <= lb.hi[0] && hb.lo[0] <= hb.hi[0]))
		return false;
	r->cuts++; /* how often this piece's triangle was cut to make it */
	refs[j] = *r;
	memcpy(r->lo, lb.lo, sizeof(r->lo));
	memcpy(r->hi, lb.hi, sizeof(r->hi));
	memcpy(refs[j].lo, hb.lo, sizeof(r->lo));
	memcpy(refs[j].hi, hb.hi, sizeof(r->hi));
	*ai = bvhlab_poly_area(&l);
	*aj = bvhlab_poly_area(&h);
	return true;
}

int sbvh_presplit(const sbvh_build *B, uint32_t count, uint32_t target, uint32_t *out_count)
{
	sbvh_ref *refs = B->refs[0];
	heap h = { malloc((size_t)target * sizeof(uint32_t)),
		   malloc((size_t)target * sizeof(double)), 0 };

	*out_count = count;
	if (!h.at || !h.key) {
		free(h.at);
		free(h.key);
		return -ENOMEM;
	}
	for (uint32_t i = 0; i < count; i++) {
		tri_poly p;
		push(&h, refs, i, piece(B, &refs[i], &p));
	}
	while (count < target && h.n > 0) {
		uint32_t i = h.at[0];
		double ai, aj;
		h.at[0] = h.at[--h.n];
		sift_down(&h, 0);
		if (!cut(B, refs, i, count, &ai, &aj))
			continue; /* cannot be cut further: stays as it is */
		push(&h, refs, i, ai);
		push(&h, refs, count++, aj);
	}
	*out_count = count;
	free(h.at);
	free(h.key);
	return 0;
}
