/*
 * Splitting leaves before a refinement stage and cutting the tree into
 * leaves again after it (see leaves.h). The split: every leaf of k > 1
 * primitives becomes a balanced subtree of k one-primitive leaves (new
 * pairs appended past the tree). The cut: as lbvh's collapse, a subtree
 * of at most max_leaf primitives becomes one leaf where c_isect * N * A is
 * no more than its best inner cost (c_trav = c_isect = 1 as in the
 * reported metric), written out afresh in breadth-first order. The
 * original leaves are among the cuts the collapse can choose, but the
 * stage in between may still leave a worse tree: hence the comparison
 * with the saved tree.
 */
#include <errno.h>
#include <stdlib.h>
#include <string.h>

#include <bvhlab/aabb.h>

#include "leaves.h"

static double area_of(const float lo[3], const float hi[3])
{
	return bvhlab_box_area(lo, hi);
}

/* Nodes past the tree that splitting every leaf takes. */
static uint32_t split_room(const bvhlab_build_output *t)
{
	uint64_t extra = 0;

	for (uint32_t x = 0; x < t->node_count; x++)
		if (t->nodes[x].count > 1)
			extra += 2 * (uint64_t)(t->nodes[x].count - 1);
	return extra > UINT32_MAX - t->node_count ? UINT32_MAX : t->node_count + (uint32_t)extra;
}

/*
 * Node x becomes the root of a balanced subtree over prim_index slots
 * [first, first + k). A primitive's leaf gets its box cut to the box of the
 * leaf it came from (lo, hi): a builder with spatial splits may have given
 * that leaf only part of the triangle, and the new nodes must stay inside
 * their parents.
 */
static void split_range(bvhlab_build_output *t, const bvhlab_build_input *in, uint32_t x,
                        uint32_t first, uint32_t k, const float lo[3], const float hi[3])
{
	bvhlab_node *n = &t->nodes[x];
	uint32_t pair = t->node_count, half = k / 2;

	if (k == 1) {
		const bvhlab_aabb *box = &in->prim_bounds[t->prim_index[first]];
		for (int a = 0; a < 3; a++) {
			n->lo[a] = bvhlab_maxf(box->lo[a], lo[a]);
			n->hi[a] = bvhlab_minf(box->hi[a], hi[a]);
		}
		n->first = first;
		n->count = 1;
		return;
	}
	t->node_count += 2;
	n->first = pair;
	n->count = 0;
	split_range(t, in, pair, first, half, lo, hi);
	split_range(t, in, pair + 1, first + half, k - half, lo, hi);
	memcpy(n->lo, t->nodes[pair].lo, sizeof(n->lo));
	memcpy(n->hi, t->nodes[pair].hi, sizeof(n->hi));
	bvhlab_box_grow(n->lo, n->hi, t->nodes[pair + 1].lo, t->nodes[pair + 1].hi);
}

static void split_all(bvhlab_build_output *t, const bvhlab_build_input *in)
{
	uint32_t count = t->node_count;

	for (uint32_t x = 0; x < count; x++)
		if (t->nodes[x].count > 1) {
			float lo[3], hi[3];
			memcpy(lo, t->nodes[x].lo, sizeof(lo));
			memcpy(hi, t->nodes[x].hi, sizeof(hi));
			split_range(t, in, x, t->nodes[x].first, t->nodes[x].count, lo, hi);
		}
}

/* ---- the SAH metric, as the core computes it --------------------------------- */

/* The SAH cost as the core's metric computes it (c_trav = c_isect = 1). */
static double sah(const bvhlab_node *nodes, uint32_t count)
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

static int collapse(bvhlab_build_output *t, uint32_t max_leaf)
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

/* ---- the flow around a stage ------------------------------------------------------- */

/* The tree as it came in, to put back if the cut tree is no better. */
struct saved {
	bvhlab_node *nodes;
	uint32_t *index;
	uint32_t node_count;
	double sah;
};

static int save(struct saved *s, const bvhlab_build_output *t)
{
	s->node_count = t->node_count;
	s->nodes = malloc((size_t)t->node_count * sizeof(*s->nodes));
	s->index = malloc((size_t)t->index_count * sizeof(*s->index));
	if (!s->nodes || !s->index)
		return -ENOMEM;
	memcpy(s->nodes, t->nodes, (size_t)t->node_count * sizeof(*s->nodes));
	memcpy(s->index, t->prim_index, (size_t)t->index_count * sizeof(*s->index));
	s->sah = sah(t->nodes, t->node_count);
	return 0;
}

/* Splits every leaf of t, growing the output for the new nodes; false
 * (t untouched) when the host refuses the room. */
static bool split_leaves(const bvhlab_host *host, bvhlab_build_ctx *ctx,
                         const bvhlab_build_input *in, bvhlab_build_output *t)
{
	uint32_t need = split_room(t);

	if (need > t->node_capacity &&
	    (need == UINT32_MAX || host->grow_output(ctx, t, need, t->index_capacity) < 0))
		return false;
	split_all(t, in);
	return true;
}

static void restore(const struct saved *s, bvhlab_build_output *t)
{
	memcpy(t->nodes, s->nodes, (size_t)s->node_count * sizeof(*s->nodes));
	memcpy(t->prim_index, s->index, (size_t)t->index_count * sizeof(*s->index));
	t->node_count = s->node_count;
}

int leaves_run(const bvhlab_host *host, bvhlab_build_ctx *ctx, const bvhlab_build_input *in,
               bvhlab_build_output *tree, bool split, bool cut, uint32_t max_leaf,
               leaves_stage_fn stage, void *arg)
{
	struct saved s = { 0 };
	int rc = 0;

	if ((split || cut) && (rc = save(&s, tree)) < 0) {
		host->set_error(ctx, "out of memory for a copy of the tree");
		goto out;
	}
	cut = (split && split_leaves(host, ctx, in, tree)) || cut;
	if ((rc = stage(arg, tree)) < 0 || !cut)
		goto out;
	if ((rc = collapse(tree, max_leaf)) < 0)
		host->set_error(ctx, "out of memory for the collapse");
	if (rc < 0 || sah(tree->nodes, tree->node_count) >= s.sah)
		restore(&s, tree);
out:
	free(s.nodes);
	free(s.index);
	return rc;
}
