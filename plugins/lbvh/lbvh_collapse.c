/*
 * lbvh: SAH collapse. Karras's tree has one primitive per leaf; with the
 * option `collapse` every subtree of at most max_leaf primitives whose
 * leaf cost c_isect * N * A is no more than its best inner cost,
 * c_trav * A + C_L + C_R (C: the children's own best, area-weighted),
 * becomes one leaf of its contiguous primitive range. Decided bottom-up in
 * the bounds phase, so each decision already knows its children's; with
 * c_trav = c_isect = 1 this minimises the core's SAH metric (up to float
 * rounding) over all ways of cutting the Karras tree into leaves of at
 * most max_leaf.
 *
 * Slots during the bounds phase, below small nodes (at most max_leaf
 * primitives): a primitive (count 1), a collapsed node (count N >= 2 and
 * its primitive range, as in the output), or an internal node whose own
 * choice was to stay inner: its SAH cost in the count field, tagged, until
 * its parent stays inner too and clears it to the output's 0. A node that
 * collapses marks every internal node below it NODE_DEAD; a node is inner
 * in the output exactly when its node_flags are 0 (zeroed before the bounds
 * phase).
 *
 * Compaction, phase 4: the bounds phase left the children of every
 * internal node i at slots 1 + 2i and 2 + 2i. Let F be the number of
 * internal nodes that stay inner. The pairs 0..F-1 of inner nodes stay
 * where they are; the pairs below F of nodes that did not stay inner are
 * holes, exactly as many as there are inner nodes from F on (the movers),
 * and the k-th mover's pair moves into the k-th hole. Sources (pairs >= F)
 * and destinations (pairs < F) never overlap, so the moves run in parallel
 * without ordering, and only a fraction of the pairs move at all. Holes
 * and movers are listed by a parallel count and prefix over the chunks;
 * like everything else, the result depends only on the tree, never on the
 * thread count.
 */
#include <string.h>

#include <bvhlab/aabb.h>

#include "lbvh.h"

#define COST_TAG 0x80000000u
#define NODE_LEAF 1u /* the SAH made this internal node a leaf */
#define NODE_DEAD 2u /* inside a node that the SAH made a leaf */

static inline uint32_t float_bits(float f)
{
	uint32_t u;

	memcpy(&u, &f, sizeof(u));
	return u;
}

static inline float bits_float(uint32_t u)
{
	float f;

	memcpy(&f, &u, sizeof(f));
	return f;
}

/* The slot of an internal node still in internal form (first = 1 + 2i). */
static inline bool internal_form(const bvhlab_node *node)
{
	return node->count == 0 || (node->count & COST_TAG);
}

/*
 * Node i became a leaf: every internal node below it is dead. A collapsed
 * child (already a leaf, its own subtree dead already) is found from its
 * range: a left child's index is its last position, a right child's its
 * first. Everything read here was written by this thread or before an
 * acquire it made.
 */
static void kill_below(lbvh *b, uint32_t i)
{
	const bvhlab_node *kids = kids_of(b, i);

	for (uint32_t k = 0; k < 2; k++) {
		if (internal_form(&kids[k])) {
			b->node_flags[internal_index(&kids[k])] = NODE_DEAD;
			kill_below(b, internal_index(&kids[k]));
		} else if (kids[k].count > 1) {
			b->node_flags[kids[k].first + (k ? 0 : kids[k].count - 1)] = NODE_DEAD;
		}
	}
}

/* Node i stays inner, for now: its children that stayed inner too get
 * the output's count 0 (their cost is no longer needed). By mask, not by
 * branch: which children those are is a coin toss. */
static void settle_kids(lbvh *b, uint32_t i)
{
	bvhlab_node *kids = kids_of(b, i);

	for (int k = 0; k < 2; k++)
		kids[k].count &= (kids[k].count >> 31) - 1;
}

/* SAH cost of a child slot (area-weighted, so that a parent just adds): a
 * tagged cost, or a leaf's c_isect * N * A. Leaf or not is a coin toss:
 * both are computed and one is picked with a mask, as a branch here is
 * mispredicted half of the time. */
static inline float child_cost(const lbvh *b, const bvhlab_node *child)
{
	uint32_t leaf = float_bits(b->c_isect * (float)child->count *
	                           bvhlab_half_area(child->lo, child->hi));
	uint32_t tagged = -(child->count >> 31);

	return bits_float((child->count & ~COST_TAG & tagged) | (leaf & ~tagged));
}

/*
 * Ties go to the leaf (same cost, fewer nodes). A node of more than
 * max_leaf primitives, and so all its ancestors, stays inner whatever it
 * costs, so it needs no cost.
 */
void lbvh_collapse(lbvh *b, uint32_t i, uint32_t size, bvhlab_node *out)
{
	const bvhlab_node *kids = kids_of(b, i);
	float area, split_cost, leaf_cost;

	if (size > b->max_leaf) {
		settle_kids(b, i);
		return;
	}
	area = bvhlab_half_area(out->lo, out->hi);
	split_cost = b->c_trav * area + child_cost(b, &kids[0]) + child_cost(b, &kids[1]);
	leaf_cost = b->c_isect * (float)size * area;
	if (leaf_cost <= split_cost) {
		out->first = range_first(b, i);
		out->count = size;
		b->node_flags[i] = NODE_LEAF;
		kill_below(b, i);
		return;
	}
	/* the root has no parent to clear its cost */
	out->count = i ? COST_TAG | float_bits(split_cost) : 0;
	settle_kids(b, i);
}

static inline bool inner(const lbvh *b, uint32_t i)
{
	return b->node_flags[i] == 0;
}

/* Sum of count[base + u] over the threads before t, and over all. */
static uint32_t prefix(const lbvh *b, unsigned t, unsigned base, uint32_t *total)
{
	uint32_t before = 0;

	*total = 0;
	for (unsigned u = 0; u < b->team.threads; u++) {
		before += u < t ? b->count[base + u] : 0;
		*total += b->count[base + u];
	}
	return before;
}

/* F: how many internal nodes stay inner. */
static uint32_t count_inner(lbvh *b, unsigned t, uint32_t lo, uint32_t hi)
{
	uint32_t count = 0, total;

	for (uint32_t i = lo; i < hi; i++)
		count += inner(b, i);
	b->count[t] = count;
	lbvh_sync(b);
	prefix(b, t, 0, &total);
	return total;
}

/*
 * Appends to list[], from `at` on, the nodes i in [lo, hi) that are inner
 * or not, as `want` says. Written always and kept only when it matches,
 * so that there is no branch to mispredict; the write past this chunk's
 * `count` goes to a local, not into the next chunk's share.
 */
static void list_where(const lbvh *b, uint32_t *list, uint32_t at, uint32_t count,
                       uint32_t lo, uint32_t hi, bool want)
{
	uint32_t end = at + count, spare;

	for (uint32_t i = lo; i < hi; i++) {
		*(at < end ? &list[at] : &spare) = i;
		at += inner(b, i) == want;
	}
}

/*
 * Lists the holes and the movers, each in index order: the k-th mover's
 * pair goes to the k-th hole. holes[] takes the arrival counters' memory
 * and movers[] end[]'s, both dead now. Returns how many moves there are.
 */
static uint32_t list_moves(lbvh *b, unsigned t, uint32_t lo, uint32_t hi, uint32_t f)
{
	uint32_t *holes = (uint32_t *)(void *)b->visits, *movers = b->end;
	uint32_t h = 0, m = 0, total, mid = lo > f ? lo : hi < f ? hi : f;

	for (uint32_t i = lo; i < hi; i++) {
		h += i < f && !inner(b, i);
		m += i >= f && inner(b, i);
	}
	b->count[b->team.threads + t] = h;
	b->count[2 * b->team.threads + t] = m;
	lbvh_sync(b);
	list_where(b, holes, prefix(b, t, b->team.threads, &total), h, lo, mid, false);
	list_where(b, movers, prefix(b, t, 2 * b->team.threads, &total), m, mid, hi, true);
	lbvh_sync(b);
	return total;
}

/* The moves are shared out evenly: the movers all lie above F, so a split
 * by node index would leave them to the last threads. */
void lbvh_compact(lbvh *b, unsigned t)
{
	const uint32_t *holes = (const uint32_t *)(const void *)b->visits, *movers = b->end;
	uint32_t lo, hi, f, moves;

	if (!b->collapse) {
		if (t == 0)
			b->node_count = 2 * b->n - 1;
		return;
	}
	chunk(b, t, b->n - 1, &lo, &hi);
	f = count_inner(b, t, lo, hi);
	moves = list_moves(b, t, lo, hi, f);
	chunk(b, t, moves, &lo, &hi);
	/* A mover's own slot lies in its parent's pair, which may move too:
	 * first point it at the new place of its children, then move. */
	for (uint32_t r = lo; r < hi; r++)
		slot_of(b, b->parent[movers[r]])->first = 1 + 2 * holes[r];
	lbvh_sync(b);
	for (uint32_t r = lo; r < hi; r++)
		memcpy(kids_of(b, holes[r]), kids_of(b, movers[r]), 2 * sizeof(bvhlab_node));
	if (t == 0)
		b->node_count = 1 + 2 * f;
}
