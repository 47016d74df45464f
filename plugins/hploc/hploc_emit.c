/*
 * The merge tree into the output (hploc_tree.h), for hploc and cl_hploc.
 *
 * Sizes come from the records: an inner node whose children's pair is at
 * slot q has its left child at q, its right child at q + 1, the left
 * child's subtree from q + 2 on and the right child's after the left
 * one's desc nodes; primitives likewise, the left child's first. A
 * primitive or a collapsed record (whose primitives one short walk
 * gathers) ends its branch. Children lie above their parent, so one pass
 * over the slots in order writes the tree with no stack: each inner node
 * leaves stubs (node word, children's slot, first primitive slot) in its
 * children's slots, which the pass reaches later.
 */
#include <string.h>

#include "hploc_tree.h"

/* At most 64 primitives below a collapsed record (max_leaf): a walk holds
 * at most one pending sibling per level. */
#define GATHER_STACK 128

struct place {
	uint32_t node, kids, first;
};

static uint32_t prims_of(const hploc_tree *t, uint32_t node)
{
	return node & HPLOC_LEAF ? 1 : t->rec[node].info & HPLOC_PRIMS;
}

static uint32_t desc_of(const hploc_tree *t, uint32_t node)
{
	return node & HPLOC_LEAF ? 0 : t->rec[node].desc;
}

/* The primitives below inner node `node`, left to right, from `first`. */
static void gather(const hploc_tree *t, uint32_t node, uint32_t first, uint32_t *index)
{
	uint32_t stack[GATHER_STACK], top = 0;

	stack[top++] = node;
	while (top) {
		uint32_t x = stack[--top];

		if (x & HPLOC_LEAF) {
			index[first++] = x & ~HPLOC_LEAF;
			continue;
		}
		stack[top++] = t->rec[x].right;
		stack[top++] = t->rec[x].left;
	}
}

static void stub_put(bvhlab_node *n, struct place pl)
{
	n->first = pl.node;
	n->count = pl.kids;
	memcpy(&n->lo[0], &pl.first, sizeof(pl.first));
}

static struct place stub_get(const bvhlab_node *n)
{
	struct place pl = { .node = n->first, .kids = n->count };

	memcpy(&pl.first, &n->lo[0], sizeof(pl.first));
	return pl;
}

static void put_leaf(const hploc_tree *t, bvhlab_build_output *out, bvhlab_node *o,
                     struct place pl)
{
	uint32_t id = pl.node & ~HPLOC_LEAF;

	for (int a = 0; a < 3; a++) {
		o->lo[a] = t->prim_bounds[id].lo[a];
		o->hi[a] = t->prim_bounds[id].hi[a];
	}
	o->first = pl.first;
	o->count = 1;
	out->prim_index[pl.first] = id;
}

static void emit_place(const hploc_tree *t, bvhlab_build_output *out, uint32_t slot,
                       struct place pl)
{
	bvhlab_node *o = &out->nodes[slot];
	const hploc_rec *r;

	if (pl.node & HPLOC_LEAF) {
		put_leaf(t, out, o, pl);
		return;
	}
	r = &t->rec[pl.node];
	memcpy(o->lo, r->lo, sizeof(o->lo));
	memcpy(o->hi, r->hi, sizeof(o->hi));
	if (r->info & HPLOC_COLLAPSED) {
		o->first = pl.first;
		o->count = r->info & HPLOC_PRIMS;
		gather(t, pl.node, pl.first, out->prim_index);
		return;
	}
	o->first = pl.kids;
	o->count = 0;
	stub_put(&out->nodes[pl.kids], (struct place){ r->left, pl.kids + 2, pl.first });
	stub_put(&out->nodes[pl.kids + 1],
	         (struct place){ r->right, pl.kids + 2 + desc_of(t, r->left),
	                         pl.first + prims_of(t, r->left) });
}

uint32_t hploc_emit(const hploc_tree *t, bvhlab_build_output *out)
{
	uint32_t count = 1 + desc_of(t, t->root);

	emit_place(t, out, 0, (struct place){ t->root, 1, 0 });
	for (uint32_t slot = 1; slot < count; slot++)
		emit_place(t, out, slot, stub_get(&out->nodes[slot]));
	return count;
}
