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
 * in one short walk) marks its children DEAD, and the dead pass that on.
 *
 * Each record's place is written by its parent, which lies below it in
 * the merge tree's array, in the range of a later iteration: the ranges
 * are taken from the last iteration's to the first's, each shared out in
 * chunks and closed by a barrier.
 */
#include "ploc.h"

/* At most 64 primitives below a collapsed record: a walk of its subtree
 * holds at most one pending sibling per level, fewer than 2 * 64. */
#define GATHER_STACK 128

static void kill_children(ploc *p, const bvhlab_node *rec)
{
	if (rec->count & REC_PRIM)
		return;
	p->place[rec->first].slot = DEAD;
	p->place[rec->first + 1].slot = DEAD;
}

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

static void emit_record(ploc *p, uint32_t x)
{
	const bvhlab_node *rec = &p->tree[x];
	struct place pl = p->place[x];
	bvhlab_node *out;
	uint32_t left;

	if (pl.slot == DEAD) {
		kill_children(p, rec);
		return;
	}
	out = &p->nodes[pl.slot];
	*out = *rec;
	if (rec->count & (REC_PRIM | REC_COLLAPSED)) {
		out->first = pl.first;
		out->count = rec->count & REC_PRIMS;
		if (rec->count & REC_PRIM)
			p->prim_index[pl.first] = rec->first;
		else
			gather(p, rec, pl.first);
		kill_children(p, rec);
		return;
	}
	out->first = pl.kids;
	out->count = 0;
	left = rec->first;
	p->place[left] = (struct place){ pl.kids, pl.kids + 2, pl.first };
	p->place[left + 1] = (struct place){ pl.kids + 1, pl.kids + 2 + p->desc[left],
	                                     pl.first + (p->tree[left].count & REC_PRIMS) };
}

/* The records of iteration it's pairs, chunk t of `chunks`. */
static void emit_range(ploc *p, uint32_t it, unsigned chunks, unsigned t)
{
	uint32_t first = p->iter_first[it], lo, hi;
	uint32_t size = (it ? p->iter_first[it - 1] : 2 * p->n - 1) - first;

	team_chunk(chunks, t, size, &lo, &hi);
	for (uint32_t x = first + lo; x < first + hi; x++)
		emit_record(p, x);
}

/* The root and the small late iterations' ranges by thread 0 alone (as
 * they were clustered), then the large ones by the team. */
void ploc_emit(ploc *p, unsigned t)
{
	if (t == 0) {
		p->place[0] = (struct place){ 0, 1, 0 };
		emit_record(p, 0);
		p->node_count = 1 + p->desc[0];
		for (uint32_t it = p->iterations; it-- > p->solo_from;)
			emit_range(p, it, 1, 0);
	}
	team_sync(&p->team);
	for (uint32_t it = p->solo_from; it-- > 0;) {
		emit_range(p, it, p->team.threads, t);
		team_sync(&p->team);
	}
}
