/*
 * ploc phase 3: the merge tree into the output, top down, applying the
 * SAH collapse decided during the merges.
 *
 * The output is laid out from sizes known bottom-up: a record kept as an
 * inner node with its children's pair at output slot q puts its left
 * child at q, its right child at q + 1, the left child's subtree from
 * q + 2 on and the right child's after the desc[] nodes of the left one;
 * primitives likewise, the left child's first. A record that became a
 * leaf (a primitive, or a collapsed subtree whose primitives it gathers
 * in one short walk) ends its branch.
 *
 * A node's slot is above its parent's, and a subtree's nodes below its
 * root are the desc[] slots from its children's pair on. So a subtree is
 * written by one pass over its slots in order, with no stack: each inner
 * node leaves its children's records and places in their own slots (a
 * stub, see stub_put), which the pass reaches later. Thread 0 writes the
 * nodes above subtrees of at most `emit_cut` primitives, which become
 * tasks that the team takes in turn. Only live records are read (most of
 * the merge tree lies inside collapsed leaves) and the output is written
 * in the order it is laid out in.
 */
#include <string.h>

#include "ploc.h"

/* At most 64 primitives below a collapsed record: a walk of its subtree
 * holds at most one pending sibling per level, fewer than 2 * 64. */
#define GATHER_STACK 128

/* The primitives below a collapsed record, left to right, from `first`. */
static void gather(ploc *p, const bvhlab_node *rec, uint32_t first)
{
	uint32_t stack[GATHER_STACK], top = 0;

	stack[top++] = rec->first + 1;
	stack[top++] = rec->first;
	while (top) {
		const bvhlab_node *r = &p->tree[stack[--top]];

		if (r->count & REC_PRIM) {
			p->prim_index[first++] = r->first;
			continue;
		}
		stack[top++] = r->first + 1;
		stack[top++] = r->first;
	}
}

/* A stub in an output slot not yet written: the record that goes there,
 * its children's slot and its first primitive slot (in the box's bits).
 * A stub with record DEAD tells the top pass to go on at slot `kids`. */
static void stub_put(ploc *p, uint32_t slot, struct place pl)
{
	bvhlab_node *n = &p->nodes[slot];

	n->first = pl.x;
	n->count = pl.kids;
	memcpy(&n->lo[0], &pl.first, sizeof(pl.first));
}

static struct place stub_get(const ploc *p, uint32_t slot)
{
	const bvhlab_node *n = &p->nodes[slot];
	struct place pl = { .x = n->first, .slot = slot, .kids = n->count };

	memcpy(&pl.first, &n->lo[0], sizeof(pl.first));
	return pl;
}

/* The node of pl's record into its slot, and stubs for its children. */
static void emit_place(ploc *p, struct place pl)
{
	const bvhlab_node *rec = &p->tree[pl.x];
	bvhlab_node *out = &p->nodes[pl.slot];
	uint32_t left = rec->first;

	*out = *rec;
	if (rec->count & (REC_PRIM | REC_COLLAPSED)) {
		out->first = pl.first;
		out->count = rec->count & REC_PRIMS;
		if (rec->count & REC_PRIM)
			p->prim_index[pl.first] = rec->first;
		else
			gather(p, rec, pl.first);
		return;
	}
	out->first = pl.kids;
	out->count = 0;
	stub_put(p, pl.kids, (struct place){ left, pl.kids, pl.kids + 2, pl.first });
	stub_put(p, pl.kids + 1,
	         (struct place){ left + 1, pl.kids + 1, pl.kids + 2 + p->desc[left],
	                         pl.first + (p->tree[left].count & REC_PRIMS) });
}

/* A task: its root, then its other slots in order. */
static void emit_task(ploc *p, struct place root)
{
	uint32_t end = root.kids + p->desc[root.x];

	emit_place(p, root);
	for (uint32_t slot = root.kids; slot < end; slot++)
		emit_place(p, stub_get(p, slot));
}

/* Thread 0: the nodes above the tasks, in slot order; a task's slots
 * below its root are skipped (the stub at the first says how far). */
static void emit_top(ploc *p)
{
	struct place pl = { 0, 0, 1, 0 };

	p->task_count = 0;
	for (uint32_t slot = 0; slot < p->node_count;) {
		if (slot > 0)
			pl = stub_get(p, slot);
		if (pl.x == DEAD) {
			slot = pl.kids;
			continue;
		}
		if ((p->tree[pl.x].count & REC_PRIMS) <= p->emit_cut) {
			p->tasks[p->task_count++] = pl;
			if (p->desc[pl.x])
				stub_put(p, pl.kids, (struct place){ DEAD, 0, pl.kids + p->desc[pl.x], 0 });
		} else {
			emit_place(p, pl);
		}
		slot++;
	}
}

void ploc_emit(ploc *p, unsigned t)
{
	uint32_t lo, hi;

	if (t == 0) {
		p->node_count = 1 + p->desc[0];
		emit_top(p);
		atomic_store_explicit(&p->blocks[0], 0, memory_order_relaxed);
	}
	team_sync(&p->team);
	while (team_next_block(&p->blocks[0], p->task_count, 1, &lo, &hi))
		emit_task(p, p->tasks[lo]);
	team_sync(&p->team);
}
