/*
 * One treelet (see treelet.h): growing it, the dynamic program over its
 * leaves' subsets, and rewriting it in its own slots.
 */
#include <math.h>
#include <string.h>

#include <bvhlab/aabb.h>

#include "treelet.h"

#define SUBSETS (1u << TREELET_MAX)

/* A treelet: its leaves (subtree roots) and its inner nodes, v first. */
struct shape {
	uint32_t leaf[TREELET_MAX], inner[TREELET_MAX - 1];
	uint32_t leaves, inners;
};

/* The program's table, by subset of the leaves (bit i: leaf i). */
struct table {
	float lo[SUBSETS][3], hi[SUBSETS][3];
	double area[SUBSETS]; /* of the subset's box (v's own box for the whole set) */
	double cost[SUBSETS]; /* least cost of a subtree over the subset (treelet_cost) */
	uint32_t prims[SUBSETS];
	uint8_t left[SUBSETS]; /* the subset its root's left child takes */
};

/* v's children, then the inner leaf of largest area split while there is
 * room (ties to the earlier leaf). */
static void grow(const bvhlab_node *nodes, uint32_t v, uint32_t size, struct shape *s)
{
	s->leaf[0] = nodes[v].first;
	s->leaf[1] = nodes[v].first + 1;
	s->leaves = 2;
	s->inner[0] = v;
	s->inners = 1;
	while (s->leaves < size) {
		uint32_t pick = UINT32_MAX;
		double best = -1.0;

		for (uint32_t i = 0; i < s->leaves; i++) {
			const bvhlab_node *n = &nodes[s->leaf[i]];
			double a = bvhlab_box_area(n->lo, n->hi);
			if (n->count == 0 && a > best) {
				best = a;
				pick = i;
			}
		}
		if (pick == UINT32_MAX)
			return;
		uint32_t x = s->leaf[pick];
		s->inner[s->inners++] = x;
		s->leaf[pick] = nodes[x].first;
		s->leaf[s->leaves++] = nodes[x].first + 1;
	}
}

/* Boxes and areas of every subset, each from the one without its lowest leaf. */
static void subset_boxes(const treelet *tr, const struct shape *s, struct table *t)
{
	uint32_t full = (1u << s->leaves) - 1;

	for (uint32_t m = 1; m <= full; m++) {
		uint32_t low = (uint32_t)__builtin_ctz(m), rest = m & (m - 1);
		const bvhlab_node *n = &tr->nodes[s->leaf[low]];

		memcpy(t->lo[m], n->lo, sizeof(t->lo[m]));
		memcpy(t->hi[m], n->hi, sizeof(t->hi[m]));
		t->prims[m] = tr->prims[s->leaf[low]];
		if (rest) {
			bvhlab_box_grow(t->lo[m], t->hi[m], t->lo[rest], t->hi[rest]);
			t->prims[m] += t->prims[rest];
		}
		t->area[m] = bvhlab_box_area(t->lo[m], t->hi[m]);
	}
}

/*
 * cost[m] for every subset in increasing order (a subset's parts are
 * smaller numbers): a single leaf its subtree's cost, a larger subset
 * treelet_cost of its best split into two parts. The part holding the
 * lowest leaf is the left one, so each split is tried once; ties keep the
 * first found.
 */
static void program(const treelet *tr, const struct shape *s, struct table *t)
{
	uint32_t full = (1u << s->leaves) - 1;

	for (uint32_t m = 1; m <= full; m++) {
		uint32_t low = m & (0u - m), rest = m ^ low;
		double best = INFINITY;

		t->left[m] = (uint8_t)m;
		if (!rest) {
			t->cost[m] = tr->cost[s->leaf[__builtin_ctz(m)]];
			continue;
		}
		for (uint32_t sub = (rest - 1) & rest;; sub = (sub - 1) & rest) {
			uint32_t l = sub | low;
			double c = t->cost[l] + t->cost[m ^ l];
			if (c < best) {
				best = c;
				t->left[m] = (uint8_t)l;
			}
			if (!sub)
				break;
		}
		t->cost[m] = treelet_cost(t->area[m], t->prims[m], tr->max_leaf, t->area[m] + best);
	}
}

struct writer {
	treelet *tr;
	const struct table *t;
	bvhlab_node rec[TREELET_MAX]; /* the leaves' root records, as they were */
	uint32_t pair[TREELET_MAX - 1]; /* the freed pairs of slots */
	uint32_t pairs_used;
};

/* Writes subset m's subtree into `slot`; v (the treelet root) keeps its box. */
static void write_subset(struct writer *w, uint32_t m, uint32_t slot, bool root)
{
	bvhlab_node *n = &w->tr->nodes[slot];

	w->tr->cost[slot] = w->t->cost[m];
	w->tr->prims[slot] = w->t->prims[m];
	if (!(m & (m - 1))) {
		*n = w->rec[__builtin_ctz(m)];
		return;
	}
	uint32_t pair = w->pair[w->pairs_used++], l = w->t->left[m];
	if (!root) {
		memcpy(n->lo, w->t->lo[m], sizeof(n->lo));
		memcpy(n->hi, w->t->hi[m], sizeof(n->hi));
	}
	n->first = pair;
	n->count = 0;
	write_subset(w, l, pair, false);
	write_subset(w, m ^ l, pair + 1, false);
}

bool treelet_optimise(treelet *tr, uint32_t v)
{
	bvhlab_node *nodes = tr->nodes;
	struct shape s;
	struct table t;

	/* Treelets below may have lowered v's cost since the round began: its
	 * children are up to date (post-order), so it is taken from them. */
	uint32_t l = nodes[v].first;
	double area = bvhlab_box_area(nodes[v].lo, nodes[v].hi);
	tr->cost[v] = treelet_cost(area, tr->prims[v], tr->max_leaf,
	                           area + tr->cost[l] + tr->cost[l + 1]);
	grow(nodes, v, tr->size, &s);
	if (s.leaves < 3)
		return false; /* two leaves have one shape */
	subset_boxes(tr, &s, &t);
	uint32_t full = (1u << s.leaves) - 1;
	t.area[full] = area; /* v keeps its box, which may be larger than the union */
	program(tr, &s, &t);
	/* a margin keeps rounding from churning */
	if (!(t.cost[full] < tr->cost[v] * (1.0 - 1e-9)))
		return false;

	struct writer w = { .tr = tr, .t = &t };
	for (uint32_t i = 0; i < s.leaves; i++)
		w.rec[i] = nodes[s.leaf[i]];
	for (uint32_t j = 0; j < s.inners; j++)
		w.pair[j] = nodes[s.inner[j]].first;
	write_subset(&w, full, v, true);
	return true;
}
