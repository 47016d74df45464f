/*
 * reinsert: carrying out one move with exact bookkeeping.
 *
 * A move takes node N (slot x) from its parent P (slot p), whose other
 * child S (slot s) takes P's slot, and puts it beside node X (slot d): X
 * moves into the pair N and S left, {x, s}, and a new inner node, their
 * parent, takes slot d. No slot is allocated or freed, so the tree keeps
 * its node count and layout rules. Then the boxes are refitted upwards
 * from where P was and from d, while the change of every inner node's
 * area is added up: that is the exact change of the SAH metric's inner
 * sum (leaves keep their boxes), so a move is kept only when the sum
 * falls. The inverse of a move is the move of N back beside S, which
 * restores the same slots and, boxes being unions, the same boxes.
 */
#include "reinsert.h"

static void adopt_children(reinsert *r, uint32_t slot)
{
	const bvhlab_node *n = &r->nodes[slot];

	if (n->count == 0)
		r->parent[n->first] = r->parent[n->first + 1] = slot;
}

/* Boxes from `slot` up to the root, as unions of the children; adds the
 * area changes to *delta. Stops where a box comes out unchanged: nothing
 * above can change then (the other path is refitted on its own). */
static void refit_up(reinsert *r, uint32_t slot, double *delta)
{
	for (; slot != NO_NODE; slot = r->parent[slot]) {
		bvhlab_node *n = &r->nodes[slot];
		float lo[3], hi[3];
		double before = node_area(n);

		box_union(&r->nodes[n->first], &r->nodes[n->first + 1], lo, hi);
		if (lo[0] == n->lo[0] && lo[1] == n->lo[1] && lo[2] == n->lo[2] &&
		    hi[0] == n->hi[0] && hi[1] == n->hi[1] && hi[2] == n->hi[2])
			return;
		for (int k = 0; k < 3; k++) {
			n->lo[k] = lo[k];
			n->hi[k] = hi[k];
		}
		*delta += node_area(n) - before;
	}
}

/* The move itself, valid by the caller's checks; returns the area change. */
static double move(reinsert *r, uint32_t x, uint32_t d)
{
	uint32_t p = r->parent[x], s = sibling_of(r, x), pair = r->nodes[p].first;
	double delta = -node_area(&r->nodes[p]);
	bvhlab_node *parent;

	/* out: S into P's slot */
	r->nodes[p] = r->nodes[s];
	adopt_children(r, p);
	/* in: X into S's old slot, beside N; their new parent into X's slot */
	r->nodes[s] = r->nodes[d];
	adopt_children(r, s);
	parent = &r->nodes[d];
	box_union(&r->nodes[x], &r->nodes[s], parent->lo, parent->hi);
	parent->first = pair;
	parent->count = 0;
	r->parent[x] = r->parent[s] = d;
	delta += node_area(parent);
	refit_up(r, r->parent[p], &delta);
	refit_up(r, r->parent[d], &delta);
	return delta;
}

double reinsert_try(reinsert *r, uint32_t x, uint32_t d)
{
	uint32_t p, s;
	double delta;

	if (x == 0 || x >= r->node_count || d >= r->node_count)
		return 0;
	p = r->parent[x];
	s = sibling_of(r, x);
	/* beside P or S would change nothing; inside N is no tree */
	if (d == p || d == s || in_subtree(r, d, x))
		return 0;
	delta = move(r, x, d);
	if (delta < 0)
		return delta;
	/* S now sits in P's old slot p; N goes back beside it */
	(void)move(r, x, p);
	return 0;
}

/*
 * The children move. Node N (slot x) leaves with its parent P (slot p):
 * P's other child S takes P's slot, which frees the pair {x, s}. N's
 * children go back one by one, the one of larger area (A, slot a) first:
 * beside X (slot d), A into slot x and X into slot s, their new parent
 * into slot d; then the other (B) beside Y (slot e), Y into A's old slot
 * and their parent into slot e. A place given as s means S, now at p.
 * Every slot written is logged first; taking the move back restores them
 * and refits every path from a slot given to the undo up to the root.
 *
 * Those refits cannot stop early as refit_up does: a log entry holds a
 * box as it was when the slot was logged, and a slot logged after an
 * earlier step of the same move refitted it (a place that is an
 * ancestor of P, or a child of one whose parent changes) comes back with
 * that step's box, the tree with N taken out. Its children come back
 * with their old boxes, so the restored box is too small, and a refit
 * starting above it, or stopping below it at an unchanged box, leaves it
 * so (the exploding horse after refit, frame 4: a place 3 levels above
 * N). Every such slot is on the path of a slot given to the undo, so
 * refitting those paths whole, each node from its children, gives every
 * box back; in a tight tree the very boxes it had before the move.
 */
static void log_slot(reinsert *r, uint32_t slot)
{
	r->log[r->log_count++] = (struct undo){ slot, r->parent[slot], r->nodes[slot] };
}

static void put_node(reinsert *r, uint32_t slot, const bvhlab_node *n)
{
	log_slot(r, slot);
	r->nodes[slot] = *n;
	if (n->count == 0) {
		log_slot(r, n->first);
		log_slot(r, n->first + 1);
	}
	adopt_children(r, slot);
}

/* Node c's content into slot `into`, beside what slot d held (moved to
 * slot `other`, the other of the pair); their parent into slot d. */
static void insert_beside(reinsert *r, uint32_t c, uint32_t into, uint32_t d, uint32_t other,
                          double *delta)
{
	bvhlab_node moved = r->nodes[c], old = r->nodes[d], parent;

	put_node(r, into, &moved);
	put_node(r, other, &old);
	box_union(&moved, &old, parent.lo, parent.hi);
	parent.first = into < other ? into : other;
	parent.count = 0;
	log_slot(r, d);
	r->nodes[d] = parent;
	r->parent[into] = r->parent[other] = d;
	*delta += node_area(&parent);
	refit_up(r, r->parent[d], delta);
}

/* Slot's box (an inner node's) and every box above it, from the children,
 * up to the root without stopping. */
static void refit_path(reinsert *r, uint32_t slot)
{
	for (; slot != NO_NODE; slot = r->parent[slot]) {
		bvhlab_node *n = &r->nodes[slot];

		if (n->count == 0)
			box_union(&r->nodes[n->first], &r->nodes[n->first + 1], n->lo, n->hi);
	}
}

static void undo_all(reinsert *r, const uint32_t *from, unsigned count)
{
	while (r->log_count) {
		const struct undo *u = &r->log[--r->log_count];
		r->nodes[u->slot] = u->node;
		r->parent[u->slot] = u->parent;
	}
	for (unsigned k = 0; k < count; k++)
		refit_path(r, from[k]);
}

double reinsert_try_children(reinsert *r, uint32_t x, uint32_t d, uint32_t e)
{
	uint32_t p, s, a, b;
	double delta;

	if (x == 0 || x >= r->node_count || d >= r->node_count || e >= r->node_count ||
	    r->nodes[x].count != 0 || in_subtree(r, d, x) || in_subtree(r, e, x))
		return 0;
	p = r->parent[x];
	s = sibling_of(r, x);
	a = r->nodes[x].first;
	b = a + 1;
	if (node_area(&r->nodes[b]) > node_area(&r->nodes[a])) {
		a = b;
		b = a - 1;
	}
	d = d == s ? p : d;
	e = e == s ? p : e;
	delta = -node_area(&r->nodes[p]) - node_area(&r->nodes[x]);
	r->log_count = 0;
	put_node(r, p, &r->nodes[s]);
	refit_up(r, r->parent[p], &delta);
	insert_beside(r, a, x, d, s, &delta);
	insert_beside(r, b, b, e, a, &delta);
	if (delta < 0)
		return delta;
	undo_all(r, (const uint32_t[]){ p, d, e, x, s, a, b }, 7);
	return 0;
}
