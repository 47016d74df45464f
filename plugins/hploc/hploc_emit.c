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
 * children's slots, which the pass reaches later. A subtree's nodes below
 * its root are the desc slots from its children's pair on, so a subtree
 * is one such pass of its own: the top pass leaves the small ones to the
 * team as tasks (as ploc_emit.c does), marking their ranges to be skipped.
 */
#include <string.h>

#include "hploc_tree.h"

/* At most 64 primitives below a collapsed record (max_leaf): a walk holds
 * at most one pending sibling per level. */
#define GATHER_STACK 128
/* A stub's node word that says: go on at slot `kids` (no node word is
 * this: primitive ids are at most HPLOC_PRIMS). */
#define SKIP 0xffffffffu

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

/* A stub in output slot pl.slot, not yet written: the node that goes
 * there, its children's slot and its first primitive slot (in the box's
 * bits). */
static void stub_put(bvhlab_build_output *out, hploc_place pl)
{
	bvhlab_node *n = &out->nodes[pl.slot];

	n->first = pl.node;
	n->count = pl.kids;
	memcpy(&n->lo[0], &pl.first, sizeof(pl.first));
}

static hploc_place stub_get(const bvhlab_build_output *out, uint32_t slot)
{
	const bvhlab_node *n = &out->nodes[slot];
	hploc_place pl = { .node = n->first, .slot = slot, .kids = n->count };

	memcpy(&pl.first, &n->lo[0], sizeof(pl.first));
	return pl;
}

static void put_leaf(const hploc_tree *t, bvhlab_build_output *out, hploc_place pl)
{
	bvhlab_node *o = &out->nodes[pl.slot];
	uint32_t id = pl.node & ~HPLOC_LEAF;

	for (int a = 0; a < 3; a++) {
		o->lo[a] = t->prim_bounds[id].lo[a];
		o->hi[a] = t->prim_bounds[id].hi[a];
	}
	o->first = pl.first;
	o->count = 1;
	out->prim_index[pl.first] = id;
}

/* The node of pl into its slot, and stubs for its children. */
static void emit_place(const hploc_tree *t, bvhlab_build_output *out, hploc_place pl)
{
	bvhlab_node *o = &out->nodes[pl.slot];
	const hploc_rec *r;

	if (pl.node & HPLOC_LEAF) {
		put_leaf(t, out, pl);
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
	stub_put(out, (hploc_place){ r->left, pl.kids, pl.kids + 2, pl.first });
	stub_put(out, (hploc_place){ r->right, pl.kids + 1, pl.kids + 2 + desc_of(t, r->left),
	                             pl.first + prims_of(t, r->left) });
}

void hploc_emit_task(const hploc_tree *t, bvhlab_build_output *out, hploc_place task)
{
	uint32_t end = task.kids + desc_of(t, task.node);

	emit_place(t, out, task);
	for (uint32_t slot = task.kids; slot < end; slot++)
		emit_place(t, out, stub_get(out, slot));
}

uint32_t hploc_emit_top(const hploc_tree *t, bvhlab_build_output *out, uint32_t cut,
                        hploc_place *tasks, uint32_t *count)
{
	hploc_place pl = { t->root, 0, 1, 0 };
	uint32_t task_count = 0;

	*count = 1 + desc_of(t, t->root);
	for (uint32_t slot = 0; slot < *count;) {
		if (slot > 0)
			pl = stub_get(out, slot);
		if (pl.node == SKIP) {
			slot = pl.kids;
			continue;
		}
		if (desc_of(t, pl.node) > 0 && prims_of(t, pl.node) <= cut) {
			tasks[task_count++] = pl;
			stub_put(out, (hploc_place){ SKIP, pl.kids, pl.kids + desc_of(t, pl.node), 0 });
		} else {
			emit_place(t, out, pl);
		}
		slot++;
	}
	return task_count;
}
