/*
 * refit's layout: the cut of the tree into spans that refit_sweep.c
 * sweeps, the check that the array is laid out so (refit.h), and the
 * rewrite of a tree that is not.
 *
 * The check walks the top of the tree only. In the streamed layout the
 * pre-order hand-out of sibling pairs tiles the array: the pair of each
 * node above the cut, and the span of each inner node at the cut, follow
 * one another in pre-order with no gap and no overlap, from slot 1 to
 * node_count. So the walk lists them in pre-order, each span reaching to
 * where the next item starts, and the layout is taken when every item
 * starts where the one before it ends. Whether every node inside a span
 * keeps its children inside it, after itself, and its references in
 * turn, the sweep checks as it goes: no thread then reads or writes
 * outside its own span. Any other tree (lbvh's, where half the inner
 * nodes have their children before them; one a refinement moved subtrees
 * in) is rewritten by one depth-first walk, after which it passes.
 */
#include <stdlib.h>
#include <string.h>

#include "refit.h"

/* Levels the cut may descend at most. */
#define CUT_DEPTH 64

/* One item of the top walk: a pair of children (root == UINT32_MAX), or
 * the span below an inner node at the cut. */
struct item {
	uint32_t lo, root;
};

struct walk {
	refit *r;
	uint32_t depth;          /* nodes at this depth are the cut's roots */
	struct item items[2 * CUT_MAX];
	uint32_t item_count;
};

/*
 * How deep the cut goes: the first depth with at least CUT_ROOTS nodes on
 * it, counting leaves above it, breadth first; shallower where a level
 * would not fit the arrays. Only counts are kept: the walk below lists
 * the nodes. FAULT_LAYOUT for a child out of range.
 */
static enum refit_fault cut_depth(const refit *r, uint32_t *depth)
{
	uint32_t level[CUT_MAX], next[CUT_MAX], count = 1, inner = 1, top = 0;
	level[0] = 0;
	*depth = 0;
	while (count < CUT_ROOTS && inner && *depth < CUT_DEPTH && 2 * count <= CUT_MAX &&
	       top + count <= CUT_MAX) {
		uint32_t m = 0;
		inner = 0;
		for (uint32_t k = 0; k < count; k++) {
			const bvhlab_node *n = &r->nodes[level[k]];
			if (n->count) {
				next[m++] = level[k];
				continue;
			}
			if (!refit_has_children(r, n))
				return FAULT_LAYOUT;
			next[m++] = n->first;
			next[m++] = n->first + 1;
			inner++;
		}
		top += inner;
		memcpy(level, next, m * sizeof(*level));
		count = m;
		*depth += inner != 0;
	}
	return FAULT_NONE;
}

static bool add_item(struct walk *w, uint32_t lo, uint32_t root)
{
	if (w->item_count == sizeof(w->items) / sizeof(w->items[0]))
		return false;
	w->items[w->item_count++] = (struct item){lo, root};
	return true;
}

/* Pre-order over the top: pairs of the inner nodes above the cut, then
 * the roots, as the streamed layout allocates them. */
static bool walk_top(struct walk *w, uint32_t i, uint32_t depth)
{
	refit *r = w->r;
	const bvhlab_node *n = &r->nodes[i];
	if (n->count || depth == w->depth) {
		if (r->root_count == CUT_MAX)
			return false;
		r->roots[r->root_count++] = i;
		return n->count || (refit_has_children(r, n) && add_item(w, n->first, i));
	}
	if (!refit_has_children(r, n) || r->top_count == CUT_MAX)
		return false;
	r->top[r->top_count++] = i;
	return add_item(w, n->first, UINT32_MAX) && walk_top(w, n->first, depth + 1) &&
	       walk_top(w, n->first + 1, depth + 1);
}

/* The items tile [1, node_count): spans out of them, FAULT_LAYOUT where
 * they do not. */
static enum refit_fault tile(struct walk *w)
{
	refit *r = w->r;
	uint32_t at = 1;
	r->span_count = 0;
	for (uint32_t k = 0; k < w->item_count; k++) {
		const struct item *it = &w->items[k];
		uint32_t hi = k + 1 < w->item_count ? w->items[k + 1].lo : r->node_count;
		if (it->lo != at || hi < it->lo + 2 || hi > r->node_count)
			return FAULT_LAYOUT;
		if (it->root == UINT32_MAX)
			hi = it->lo + 2;
		else
			r->spans[r->span_count++] = (struct span){it->lo, hi};
		at = hi;
	}
	return at == r->node_count || w->item_count == 0 ? FAULT_NONE : FAULT_LAYOUT;
}

enum refit_fault refit_plan(refit *r)
{
	struct walk *w = calloc(1, sizeof(*w));
	enum refit_fault f = w ? FAULT_NONE : FAULT_MEMORY;
	r->root_count = r->top_count = r->span_count = 0;
	if (f == FAULT_NONE) {
		w->r = r;
		f = cut_depth(r, &w->depth);
	}
	if (f == FAULT_NONE)
		f = walk_top(w, 0, 0) ? tile(w) : FAULT_LAYOUT;
	free(w);
	return f;
}

/* ---- the rewrite ------------------------------------------------------- */

/* A node of the old array and the slot it gets in the new one. */
struct move {
	uint32_t from, to;
};

struct relayout {
	const refit *r;
	bvhlab_node *nodes;   /* [node_count] the new array, past the old one */
	uint32_t *prim_index; /* [index_count] the new references, past the old */
	struct move *stack;
	size_t size, cap;
	uint32_t used;        /* slots handed out */
};

static bool push(struct relayout *o, uint32_t from, uint32_t to)
{
	if (o->size == o->cap) {
		size_t cap = o->cap ? 2 * o->cap : 256;
		struct move *s = realloc(o->stack, cap * sizeof(*s));
		if (!s)
			return false;
		o->stack = s;
		o->cap = cap;
	}
	o->stack[o->size++] = (struct move){from, to};
	return true;
}

/* Pre-order, left before right, each inner node's pair handed out as it
 * is met; a leaf keeps its old first slot until its references move. A
 * cycle or a shared node shows as more slots than nodes. */
static enum refit_fault place(struct relayout *o)
{
	const refit *r = o->r;
	o->used = 1;
	if (!push(o, 0, 0))
		return FAULT_MEMORY;
	while (o->size) {
		struct move m = o->stack[--o->size];
		bvhlab_node n = r->nodes[m.from];
		if (!n.count) {
			if (!refit_has_children(r, &n) || r->node_count - o->used < 2)
				return FAULT_SHAPE;
			/* the children's line on its way while the stack is updated */
			__builtin_prefetch(&r->nodes[n.first]);
			if (!push(o, n.first + 1, o->used + 1) || !push(o, n.first, o->used))
				return FAULT_MEMORY;
			n.first = o->used;
			o->used += 2;
		}
		o->nodes[m.to] = n;
	}
	return FAULT_NONE;
}

/* The leaves' references in the new node order. */
static enum refit_fault references(struct relayout *o, uint32_t *count)
{
	const refit *r = o->r;
	uint32_t at = 0;
	for (uint32_t i = 0; i < o->used; i++) {
		bvhlab_node *n = &o->nodes[i];
		if (!n->count)
			continue;
		if (n->first > r->index_count || n->count > r->index_count - n->first ||
		    n->count > r->index_count - at)
			return FAULT_PRIM;
		memcpy(o->prim_index + at, r->prim_index + n->first, n->count * sizeof(uint32_t));
		n->first = at;
		at += n->count;
	}
	*count = at;
	return FAULT_NONE;
}

/*
 * Room for the new tree past the old one, in the output's own capacity
 * (scratch past the counts, ABI 1.4), grown through the host where it
 * is short: it stays with the tree, so a rewrite every frame (after a
 * refinement) touches no new memory. A fresh mapping per rewrite cost
 * 17 ms of page faults in 4 KiB pages and up to 70 in huge pages (a new
 * process compacting memory) on lbvh's tree of igea subdivided once.
 */
static enum refit_fault make_room(refit *r)
{
	uint64_t nodes = 2 * (uint64_t)r->node_count, refs = 2 * (uint64_t)r->index_count;
	int rc = 0;
	if (nodes > UINT32_MAX || refs > UINT32_MAX)
		return FAULT_MEMORY;
	if (nodes > r->out->node_capacity || refs > r->out->index_capacity)
		rc = r->host->grow_output(r->ctx, r->out, (uint32_t)nodes, (uint32_t)refs);
	/* even a refused growth may have moved the arrays */
	r->nodes = r->out->nodes;
	r->prim_index = r->out->prim_index;
	return rc < 0 ? FAULT_MEMORY : FAULT_NONE;
}

enum refit_fault refit_relayout(refit *r)
{
	struct relayout o = {.r = r};
	uint32_t refs = 0;
	enum refit_fault f = make_room(r);
	o.nodes = r->nodes + r->node_count;
	o.prim_index = r->prim_index + r->index_count;
	if (f == FAULT_NONE)
		f = place(&o);
	if (f == FAULT_NONE)
		f = references(&o, &refs);
	if (f == FAULT_NONE) {
		memcpy(r->nodes, o.nodes, o.used * sizeof(*o.nodes));
		memcpy(r->prim_index, o.prim_index, refs * sizeof(*o.prim_index));
		r->node_count = o.used;
		r->index_count = refs;
	}
	free(o.stack);
	return f;
}
