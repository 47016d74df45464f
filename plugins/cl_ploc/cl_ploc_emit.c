/*
 * cl_ploc's emission, on the host: ploc_emit.c's layout done by one thread
 * (its emit_task from the root). A record kept as an inner node with its
 * children's pair at slot q puts its children at q and q + 1, the left
 * child's subtree from q + 2 on and the right child's after the left one's
 * desc[] nodes; a leaf record (a primitive or a collapsed subtree, whose
 * primitives one short walk gathers) ends its branch. Children's slots lie
 * above their parent's, so one pass over the slots in order writes the
 * tree, each inner node leaving stubs (record, children's slot, first
 * primitive slot) in its children's slots for the pass to reach.
 */
#include <string.h>

#include "cl_ploc.h"

/* At most 64 primitives below a collapsed record (max_leaf). */
#define GATHER_STACK 128

struct place {
	uint32_t x, kids, first;
};

static void gather(const cl_ploc *b, const bvhlab_node *rec, uint32_t first, uint32_t *index)
{
	uint32_t stack[GATHER_STACK], top = 0;

	stack[top++] = rec->first + 1;
	stack[top++] = rec->first;
	while (top) {
		const bvhlab_node *r = &b->tree[stack[--top]];

		if (r->count & REC_PRIM) {
			index[first++] = r->first;
			continue;
		}
		stack[top++] = r->first + 1;
		stack[top++] = r->first;
	}
}

static void stub_put(bvhlab_node *n, struct place pl)
{
	n->first = pl.x;
	n->count = pl.kids;
	memcpy(&n->lo[0], &pl.first, sizeof(pl.first));
}

static struct place stub_get(const bvhlab_node *n)
{
	struct place pl = { .x = n->first, .kids = n->count };

	memcpy(&pl.first, &n->lo[0], sizeof(pl.first));
	return pl;
}

static void emit_place(const cl_ploc *b, bvhlab_build_output *out, uint32_t slot,
                       struct place pl)
{
	const bvhlab_node *rec = &b->tree[pl.x];
	bvhlab_node *o = &out->nodes[slot];
	uint32_t left = rec->first;

	*o = *rec;
	if (rec->count & (REC_PRIM | REC_COLLAPSED)) {
		o->first = pl.first;
		o->count = rec->count & REC_PRIMS;
		if (rec->count & REC_PRIM)
			out->prim_index[pl.first] = rec->first;
		else
			gather(b, rec, pl.first, out->prim_index);
		return;
	}
	o->first = pl.kids;
	o->count = 0;
	stub_put(&out->nodes[pl.kids], (struct place){ left, pl.kids + 2, pl.first });
	stub_put(&out->nodes[pl.kids + 1],
	         (struct place){ left + 1, pl.kids + 2 + b->desc[left],
	                         pl.first + (b->tree[left].count & REC_PRIMS) });
}

uint32_t cl_ploc_emit(const cl_ploc *b, bvhlab_build_output *out)
{
	uint32_t count = 1 + b->desc[0];

	emit_place(b, out, 0, (struct place){ 0, 1, 0 });
	for (uint32_t slot = 1; slot < count; slot++)
		emit_place(b, out, slot, stub_get(&out->nodes[slot]));
	return count;
}
