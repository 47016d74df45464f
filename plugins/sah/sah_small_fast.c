/*
 * Small subtrees at quality fast: a job of at most SAH_SMALL_MAX
 * primitives is built whole, as in sah_small.c, but each node sweeps only
 * the axis of its largest centroid extent. That changes what the search
 * needs: the high path keeps all three axes sorted for every node (three
 * insertion sorts of the whole job up front, from orders the binned parent
 * left random along two axes, then a stable partition of two orders per
 * split), and those sorts were most of its time. Here one slot array holds
 * a node's primitives; a node sorts its own slots along its one axis and a
 * split cuts that sorted run in two, so the children inherit a sorted
 * order, usually along the axis they will use again (an insertion sort of
 * a sorted run is one pass). Nothing is partitioned.
 *
 * The rule is still the kernel's (sah_kernel.h) on that one axis: every
 * plane strictly between two consecutive distinct centroids, cost
 * A_L * N_L + A_R * N_R, first lowest position, the kernel's leaf rule.
 * The sort breaks ties by local index, so a node's order, and with it the
 * tree, depends only on its set of primitives; the object-median fallback
 * (every centroid equal) reads that order as well.
 */
#include <math.h>

#include "sah_small.h"

typedef struct fast {
	small_copy l;
	v4 cen[SAH_SMALL_MAX];        /* centroids, by local index */
	uint8_t o[SAH_SMALL_MAX];     /* local indices; a node owns slots [lb, le) */
} fast;

static void load(fast *f, const sah_prim *prims, uint32_t n)
{
	for (uint32_t k = 0; k < n; k++) {
		small_load_prim(&f->l, &prims[f->l.begin + k], k);
		f->cen[k] = v4_set3(f->l.cen[0][k], f->l.cen[1][k], f->l.cen[2][k]);
		f->o[k] = (uint8_t)k;
	}
}

/* The axis of the node's largest centroid extent (ties: the lower axis),
 * or -1 when every centroid coincides. */
static int pick_axis(const fast *f, const small_node *c)
{
	v4 lo = f->cen[f->o[c->lb]], hi = lo;
	float ext[4];
	int best = -1;

	for (uint32_t k = c->lb + 1; k < c->le; k++) {
		lo = v4_min(lo, f->cen[f->o[k]]);
		hi = v4_max(hi, f->cen[f->o[k]]);
	}
	v4_store(ext, v4_sub(hi, lo));
	for (int a = 0; a < 3; a++)
		if (ext[a] > 0 && (best < 0 || ext[a] > ext[best]))
			best = a;
	return best;
}

/* Insertion sort of the node's slots by (centroid, local index): one pass
 * when the run is sorted already, as after a parent split on this axis. */
static void sort_slots(fast *f, int a, const small_node *c)
{
	const float *key = f->l.cen[a];
	uint8_t *o = f->o;

	for (uint32_t k = c->lb + 1; k < c->le; k++) {
		uint8_t v = o[k];
		float x = key[v];
		uint32_t j = k;
		while (j > c->lb && (key[o[j - 1]] > x || (key[o[j - 1]] == x && o[j - 1] > v))) {
			o[j] = o[j - 1];
			j--;
		}
		o[j] = v;
	}
}

/* The union of the boxes of slots [from, to). */
static void slots_box(const fast *f, uint32_t from, uint32_t to, bvhlab_aabb *box)
{
	v4 lo = v4_set1(INFINITY), hi = v4_set1(-INFINITY);

	for (uint32_t k = from; k < to; k++) {
		lo = v4_min(lo, f->l.lo[f->o[k]]);
		hi = v4_max(hi, f->l.hi[f->o[k]]);
	}
	v4_store3(box->lo, lo);
	v4_store3(box->hi, hi);
}

/* Decides one node; returns 2 and fills child[] when it splits. */
static unsigned split_node(void *state, const small_node *c, small_node child[2])
{
	fast *f = state;
	uint32_t n = c->le - c->lb, pos = c->lb + n / 2;
	int axis = n > 1 ? pick_axis(f, c) : -1;
	float best = INFINITY;

	if (axis >= 0) {
		sort_slots(f, axis, c);
		best = small_sweep(&f->l, f->o, axis, c->lb, c->le, INFINITY, &pos);
	}
	if (n == 1 || sah_leaf_rule(&f->l.b->opt, n, &c->box, best < INFINITY, best)) {
		small_write_leaf(&f->l, c, f->o);
		return 0;
	}
	/* No candidate (every centroid equal): pos is the middle of the order. */
	child[0].lb = c->lb;
	child[0].le = pos;
	child[1].lb = pos;
	child[1].le = c->le;
	slots_box(f, c->lb, pos, &child[0].box);
	slots_box(f, pos, c->le, &child[1].box);
	return small_write_inner(&f->l, c, child);
}

void sah_small_fast_subtree(sah_builder *b, const sah_job *job)
{
	fast f;
	uint32_t n = job->end - job->begin;

	load(&f, small_begin(&f.l, b, job), n);
	small_walk(job, n, &f, split_node);
}
