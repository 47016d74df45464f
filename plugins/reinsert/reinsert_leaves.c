/*
 * reinsert with `leaves` on: a leaf of several primitives cannot be taken
 * apart by moving subtrees, and the SAH builders' trees keep most of their
 * primitives in such leaves. So before the iterations every leaf of k > 1
 * primitives becomes a balanced subtree of k one-primitive leaves (new
 * pairs appended past the tree), and after them the tree is cut into
 * leaves again by the SAH as lbvh's collapse does (a subtree of at most
 * max_leaf primitives becomes one leaf where c_isect * N * A is no more
 * than its best inner cost, c_trav = c_isect = 1 as in the reported
 * metric) and written out afresh in depth-first order. The original
 * leaves are among the cuts the collapse can choose, but the moves in
 * between may still leave a worse tree: the result is kept only when its
 * SAH, computed as the core's metric does, is lower; otherwise the tree
 * as it came in is put back.
 */
#include <errno.h>
#include <stdlib.h>
#include <string.h>

#include "reinsert.h"

/* Nodes past the tree that splitting every leaf takes. */
uint32_t reinsert_split_room(const bvhlab_build_output *t)
{
	uint64_t extra = 0;

	for (uint32_t x = 0; x < t->node_count; x++)
		if (t->nodes[x].count > 1)
			extra += 2 * (uint64_t)(t->nodes[x].count - 1);
	return extra > UINT32_MAX - t->node_count ? UINT32_MAX : t->node_count + (uint32_t)extra;
}

/* Node x becomes the root of a balanced subtree over prim_index slots
 * [first, first + k); its box is kept (it contains them all). */
static void split_range(bvhlab_build_output *t, const bvhlab_build_input *in, uint32_t x,
                        uint32_t first, uint32_t k)
{
	bvhlab_node *n = &t->nodes[x];
	uint32_t pair = t->node_count, half = k / 2;

	if (k == 1) {
		const bvhlab_aabb *box = &in->prim_bounds[t->prim_index[first]];
		memcpy(n->lo, box->lo, sizeof(n->lo));
		memcpy(n->hi, box->hi, sizeof(n->hi));
		n->first = first;
		n->count = 1;
		return;
	}
	t->node_count += 2;
	n->first = pair;
	n->count = 0;
	split_range(t, in, pair, first, half);
	split_range(t, in, pair + 1, first + half, k - half);
	box_union(&t->nodes[pair], &t->nodes[pair + 1], t->nodes[x].lo, t->nodes[x].hi);
}

void reinsert_split_leaves(bvhlab_build_output *t, const bvhlab_build_input *in)
{
	uint32_t count = t->node_count;

	for (uint32_t x = 0; x < count; x++)
		if (t->nodes[x].count > 1)
			split_range(t, in, x, t->nodes[x].first, t->nodes[x].count);
}

/* ---- the SAH metric, as the core computes it --------------------------------- */

double reinsert_sah(const bvhlab_node *nodes, uint32_t count)
{
	double root = area_of(nodes[0].lo, nodes[0].hi), sum = 0, refs = 0;

	for (uint32_t x = 0; x < count; x++) {
		sum += area_of(nodes[x].lo, nodes[x].hi) * (nodes[x].count ? nodes[x].count : 1);
		refs += nodes[x].count ? nodes[x].count : 1;
	}
	return root > 0 ? sum / root : refs;
}

/* ---- collapse ----------------------------------------------------------------- */

struct collapse {
	bvhlab_build_output *t;
	uint32_t max_leaf;
	uint32_t *prims;  /* [node_count] primitives below each node */
	double *cost;     /* [node_count] best SAH cost, area-weighted */
	uint32_t *stack;  /* [2 node_count + 2]: marks and siblings of a path */
	bvhlab_node *out; /* [node_count] the new nodes */
	uint32_t *index;  /* [index_count] the new prim_index */
};

/* Children before parents: a depth-first walk that finishes each node
 * after both children (second visit marked in the stack's top bit). */
static void costs(struct collapse *c)
{
	const bvhlab_node *nodes = c->t->nodes;
	uint32_t top = 0;

	c->stack[top++] = 0;
	while (top) {
		uint32_t w = c->stack[--top], x = w & 0x7fffffffu;
		const bvhlab_node *n = &nodes[x];
		double area = area_of(n->lo, n->hi);

		if (n->count) {
			c->prims[x] = n->count;
			c->cost[x] = area * n->count;
		} else if (!(w >> 31)) {
			c->stack[top++] = x | 0x80000000u;
			c->stack[top++] = n->first;
			c->stack[top++] = n->first + 1;
		} else {
			uint32_t l = n->first, r = l + 1, prims = c->prims[l] + c->prims[r];
			double split = area + c->cost[l] + c->cost[r], leaf = area * prims;

			c->prims[x] = prims;
			c->cost[x] = prims <= c->max_leaf && leaf <= split ? leaf : split;
		}
	}
}

static bool leaf_here(const struct collapse *c, uint32_t x)
{
	const bvhlab_node *n = &c->t->nodes[x];

	return n->count || (c->prims[x] <= c->max_leaf &&
	                    area_of(n->lo, n->hi) * c->prims[x] <= c->cost[x]);
}

/* The primitives below x into index[at ..). */
static uint32_t gather(struct collapse *c, uint32_t x, uint32_t at)
{
	uint32_t top = 0;

	c->stack[top++] = x;
	while (top) {
		const bvhlab_node *n = &c->t->nodes[c->stack[--top]];

		if (n->count) {
			memcpy(c->index + at, c->t->prim_index + n->first, n->count * sizeof(uint32_t));
			at += n->count;
		} else {
			c->stack[top++] = n->first + 1;
			c->stack[top++] = n->first;
		}
	}
	return at;
}

/* Writes the cut tree breadth-first: a node's pair goes at the next free
 * slot when the node is written. Returns the node count. */
static uint32_t emit(struct collapse *c)
{
	uint32_t used = 1, at = 0;

	/* out[k].first holds the source node of slot k until slot k is written */
	c->out[0].first = 0;
	for (uint32_t k = 0; k < used; k++) {
		uint32_t x = c->out[k].first;
		const bvhlab_node *n = &c->t->nodes[x];

		c->out[k] = *n;
		if (leaf_here(c, x)) {
			c->out[k].first = at;
			c->out[k].count = c->prims[x];
			at = gather(c, x, at);
			continue;
		}
		c->out[k].first = used;
		c->out[used++].first = n->first;
		c->out[used++].first = n->first + 1;
	}
	return used;
}

int reinsert_collapse(bvhlab_build_output *t, uint32_t max_leaf)
{
	size_t n = t->node_count;
	struct collapse c = { .t = t, .max_leaf = max_leaf };
	uint32_t count;
	int rc = 0;

	c.prims = malloc(n * sizeof(*c.prims));
	c.cost = malloc(n * sizeof(*c.cost));
	c.stack = malloc((2 * n + 2) * sizeof(*c.stack));
	c.out = malloc(n * sizeof(*c.out));
	c.index = malloc((size_t)t->index_count * sizeof(*c.index));
	if (!c.prims || !c.cost || !c.stack || !c.out || !c.index) {
		rc = -ENOMEM;
		goto out;
	}
	costs(&c);
	count = emit(&c);
	memcpy(t->nodes, c.out, count * sizeof(*c.out));
	memcpy(t->prim_index, c.index, (size_t)t->index_count * sizeof(*c.index));
	t->node_count = count;
out:
	free(c.prims);
	free(c.cost);
	free(c.stack);
	free(c.out);
	free(c.index);
	return rc;
}
