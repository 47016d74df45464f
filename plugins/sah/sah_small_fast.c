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

#include "sah_box.h"
#include "sah_nodes.h"
#include "sah_simd.h"
#include "sah_split.h"

typedef struct fast {
	sah_builder *b;
	uint32_t begin;               /* the subtree's first position */
	v4 lo[SAH_SMALL_MAX];         /* boxes, by local index */
	v4 hi[SAH_SMALL_MAX];
	v4 cen[SAH_SMALL_MAX];        /* centroids, by local index */
	float c[3][SAH_SMALL_MAX];    /* the same, by axis, for the sort and sweep */
	uint32_t id[SAH_SMALL_MAX];
	uint8_t o[SAH_SMALL_MAX];     /* local indices; a node owns slots [lb, le) */
	float right[SAH_SMALL_MAX];   /* A_R * N_R of the slots from j on */
} fast;

typedef struct fast_node {
	uint32_t node, lb, le; /* node slot; its slots [lb, le) */
	bvhlab_aabb box;
} fast_node;

static void load(fast *f, const sah_prim *prims, uint32_t n)
{
	for (uint32_t k = 0; k < n; k++) {
		const sah_prim *p = &prims[f->begin + k];
		f->lo[k] = v4_load3(p->lo);
		f->hi[k] = v4_load3(p->hi);
		for (int a = 0; a < 3; a++)
			f->c[a][k] = prim_centroid(p, a);
		f->cen[k] = v4_set3(f->c[0][k], f->c[1][k], f->c[2][k]);
		f->id[k] = p->id;
		f->o[k] = (uint8_t)k;
	}
}

/* The axis of the node's largest centroid extent (ties: the lower axis),
 * or -1 when every centroid coincides. */
static int pick_axis(const fast *f, const fast_node *c)
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
static void sort_slots(fast *f, int a, const fast_node *c)
{
	const float *key = f->c[a];
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

/* Lowest cost of the axis' planes, first position in *pos (INFINITY: none). */
static float sweep(fast *f, int a, const fast_node *c, uint32_t *pos)
{
	const uint8_t *o = f->o;
	const float *key = f->c[a];
	v4 lo = v4_set1(INFINITY), hi = v4_set1(-INFINITY);
	float best = INFINITY;

	for (uint32_t j = c->le - 1; j > c->lb; j--) {
		lo = v4_min(lo, f->lo[o[j]]);
		hi = v4_max(hi, f->hi[o[j]]);
		f->right[j] = v4_half_area(lo, hi) * (float)(c->le - j);
	}
	lo = v4_set1(INFINITY);
	hi = v4_set1(-INFINITY);
	for (uint32_t j = c->lb + 1; j < c->le; j++) {
		lo = v4_min(lo, f->lo[o[j - 1]]);
		hi = v4_max(hi, f->hi[o[j - 1]]);
		if (!(key[o[j - 1]] < key[o[j]]))
			continue;
		float cost = v4_half_area(lo, hi) * (float)(j - c->lb) + f->right[j];
		if (cost < best) {
			best = cost;
			*pos = j;
		}
	}
	return best;
}

static void write_leaf(fast *f, const fast_node *c)
{
	sah_builder *b = f->b;
	bvhlab_node *node = &b->nodes[c->node];

	for (int k = 0; k < 3; k++) {
		node->lo[k] = c->box.lo[k];
		node->hi[k] = c->box.hi[k];
	}
	node->first = f->begin + c->lb;
	node->count = c->le - c->lb;
	for (uint32_t k = c->lb; k < c->le; k++)
		b->ids[f->begin + k] = f->id[f->o[k]];
}

/* The union of the boxes of slots [from, to). */
static void slots_box(const fast *f, uint32_t from, uint32_t to, bvhlab_aabb *box)
{
	v4 lo = v4_set1(INFINITY), hi = v4_set1(-INFINITY);

	for (uint32_t k = from; k < to; k++) {
		lo = v4_min(lo, f->lo[f->o[k]]);
		hi = v4_max(hi, f->hi[f->o[k]]);
	}
	v4_store3(box->lo, lo);
	v4_store3(box->hi, hi);
}

/* Decides one node; returns 2 and fills child[] when it splits. */
static unsigned split_node(fast *f, const fast_node *c, fast_node child[2])
{
	uint32_t n = c->le - c->lb, pos = c->lb + n / 2;
	int axis = n > 1 ? pick_axis(f, c) : -1;
	float best = INFINITY;

	if (axis >= 0) {
		sort_slots(f, axis, c);
		best = sweep(f, axis, c, &pos);
	}
	if (n == 1 || sah_leaf_rule(&f->b->opt, n, &c->box, best < INFINITY, best)) {
		write_leaf(f, c);
		return 0;
	}
	/* No candidate (every centroid equal): pos is the middle of the order. */
	child[0].lb = c->lb;
	child[0].le = pos;
	child[1].lb = pos;
	child[1].le = c->le;
	slots_box(f, c->lb, pos, &child[0].box);
	slots_box(f, pos, c->le, &child[1].box);
	sah_write_node(f->b, c->node, &c->box, &child[0].node);
	child[1].node = child[0].node + 1;
	return 2;
}

void sah_small_fast_subtree(sah_builder *b, const sah_job *job)
{
	fast f;
	fast_node stack[SAH_SMALL_MAX], child[2];
	uint32_t n = job->end - job->begin, sp = 0;

	f.b = b;
	f.begin = job->begin;
	load(&f, sah_job_prims(b, job), n);
	stack[sp++] = (fast_node){ .node = job->node, .lb = 0, .le = n, .box = job->box };
	while (sp > 0) {
		fast_node cur = stack[--sp];
		if (split_node(&f, &cur, child) == 2) {
			stack[sp++] = child[1];
			stack[sp++] = child[0];
		}
	}
}
