/*
 * The compressed 8-wide encoder (cwbvh.h): breadth first, so each node's
 * inner children are consecutive nodes; each child's box quantised
 * outward against its node's grid.
 */
#include <errno.h>
#include <math.h>
#include <stdlib.h>
#include <string.h>

#include <bvhlab/aabb.h>

#include "trace/cwbvh.h"
#include "tree/tree_view.h"
#include "util/util.h"

BVHLAB_STATIC_ASSERT(sizeof(cw_node) == CW_NODE_BYTES, "the compressed node is 80 bytes");

struct encoder {
	const bvhlab_tree *tree;
	struct cwbvh *out;
	uint32_t *depth; /* [node_cap] each node's depth below the root */
	uint32_t node_cap, leaf_cap;
	bool collapse;
};

static const bvhlab_node *node_at(const struct encoder *c, uint32_t i)
{
	return &c->tree->nodes[i];
}

/* Whether inner node i's children lie in the array (and it is at most 8 wide). */
static bool links_ok(const struct encoder *c, uint32_t i)
{
	const bvhlab_node *n = node_at(c, i);
	return tree_child_count(n) <= CW_WIDTH && tree_child(n, 0) != 0 &&
	       tree_children_end(n) <= c->tree->node_count;
}

/* The inner child of largest area whose children still fit: its place in
 * list, or -1. */
static int widest_opening(const struct encoder *c, const uint32_t *list, uint32_t n)
{
	int best = -1;
	float best_area = -1.0f;
	for (uint32_t i = 0; i < n; i++) {
		const bvhlab_node *ch = node_at(c, list[i]);
		if (tree_is_leaf(ch) || n - 1 + tree_child_count(ch) > CW_WIDTH)
			continue;
		float a = bvhlab_half_area(ch->lo, ch->hi);
		if (best < 0 || a > best_area) {
			best = (int)i;
			best_area = a;
		}
	}
	return best;
}

/* The children the compressed node of source node i gets: its own, or
 * when collapsing those of the widest inner child opened until 8 are
 * full. -EINVAL for links that leave the array. */
static int gather(const struct encoder *c, uint32_t i, uint32_t list[CW_WIDTH], uint32_t *n)
{
	const bvhlab_node *nd = node_at(c, i);
	*n = 0;
	if (tree_is_leaf(nd)) { /* the leaf root */
		list[(*n)++] = i;
		return 0;
	}
	if (!links_ok(c, i))
		return -EINVAL;
	for (uint32_t k = 0; k < tree_child_count(nd); k++)
		list[(*n)++] = tree_child(nd, k);
	for (int at; c->collapse && (at = widest_opening(c, list, *n)) >= 0;) {
		uint32_t open = list[at];
		if (!links_ok(c, open))
			return -EINVAL;
		nd = node_at(c, open);
		list[at] = list[--*n];
		for (uint32_t k = 0; k < tree_child_count(nd); k++)
			list[(*n)++] = tree_child(nd, k);
	}
	return 0;
}

/* Children into slots by the octant their centre lies in from the
 * node's: greedily the (child, slot) pair whose centre offset reaches
 * furthest along the slot's diagonal (slot bit k set: +axis k). */
static void assign_slots(const struct encoder *c, const uint32_t *list, uint32_t n,
                         int slot_of[CW_WIDTH])
{
	float centre[CW_WIDTH][3], mid[3] = {0, 0, 0};
	bool slot_used[CW_WIDTH] = {false};
	for (uint32_t i = 0; i < n; i++) {
		const bvhlab_node *ch = node_at(c, list[i]);
		for (int k = 0; k < 3; k++) {
			centre[i][k] = 0.5f * (ch->lo[k] + ch->hi[k]);
			mid[k] += centre[i][k] / (float)n;
		}
		slot_of[i] = -1;
	}
	for (uint32_t done = 0; done < n; done++) {
		float best = -INFINITY;
		int bi = -1, bs = -1;
		for (uint32_t i = 0; i < n; i++)
			for (int s = 0; s < CW_WIDTH && slot_of[i] < 0; s++) {
				float d = 0;
				for (int k = 0; k < 3; k++)
					d += (s >> k & 1 ? 1.0f : -1.0f) * (centre[i][k] - mid[k]);
				if (!slot_used[s] && (bi < 0 || d > best)) {
					best = d, bi = (int)i, bs = s;
				}
			}
		slot_of[bi] = bs;
		slot_used[bs] = true;
	}
}

/* The least exponent byte whose grid of 255 steps from p reaches hi as
 * the kernel decodes it; 0 (scale 0) when hi is p. */
static cw_u8 exponent(float p, float hi)
{
	if (!(hi > p))
		return 0;
	int e2;
	frexp(((double)hi - p) / 255.0, &e2); /* 2^(e2-1) <= step < 2^e2 */
	int e = e2 - 1 + 127;
	e = e < 1 ? 1 : e > 254 ? 254 : e;
	while (e < 254 && p + 255.0f * cw_scale((cw_u8)e) < hi)
		e++;
	return (cw_u8)e;
}

/* The grid steps of a box's planes, outward: the largest q whose decoded
 * plane is at or below lo, the least at or above hi (the double estimate
 * moved to the exact step, as the kernel decodes it). */
static void quantise(cw_node *w, int k, float lo, float hi, cw_u8 *qlo, cw_u8 *qhi)
{
	float s = cw_scale(w->e[k]);
	double ql = s > 0 ? floor(((double)lo - w->p[k]) / s) : 0;
	double qh = s > 0 ? ceil(((double)hi - w->p[k]) / s) : 0;
	int a = ql < 0 ? 0 : ql > 255 ? 255 : (int)ql, b = qh < 0 ? 0 : qh > 255 ? 255 : (int)qh;
	while (a > 0 && cw_plane(w, k, (cw_u8)a) > lo)
		a--;
	while (a < 255 && cw_plane(w, k, (cw_u8)(a + 1)) <= lo)
		a++;
	while (b < 255 && cw_plane(w, k, (cw_u8)b) < hi)
		b++;
	while (b > 0 && cw_plane(w, k, (cw_u8)(b - 1)) >= hi)
		b--;
	*qlo = (cw_u8)a;
	*qhi = (cw_u8)b;
}

/* The node's grid over its children's boxes; -EINVAL for a box that is
 * not finite (it has no grid). */
static int grid(const struct encoder *c, const uint32_t *list, uint32_t n, cw_node *w)
{
	for (int k = 0; k < 3; k++) {
		float lo = INFINITY, hi = -INFINITY;
		for (uint32_t i = 0; i < n; i++) {
			const bvhlab_node *ch = node_at(c, list[i]);
			if (!isfinite(ch->lo[k]) || !isfinite(ch->hi[k]) || ch->lo[k] > ch->hi[k])
				return -EINVAL;
			lo = fminf(lo, ch->lo[k]);
			hi = fmaxf(hi, ch->hi[k]);
		}
		w->p[k] = lo;
		w->e[k] = exponent(lo, hi);
	}
	return 0;
}

/* Child i of list into slot s of w: its box, and its meta (inner ones
 * queued as the next nodes, leaves as the next ranges). */
static int place(struct encoder *c, cw_node *w, uint32_t child, int s, uint32_t depth)
{
	const bvhlab_node *ch = node_at(c, child);
	struct cwbvh *o = c->out;
	for (int k = 0; k < 3; k++)
		quantise(w, k, ch->lo[k], ch->hi[k], &w->qlo[k][s], &w->qhi[k][s]);
	if (tree_is_leaf(ch)) {
		if (o->leaf_count == c->leaf_cap)
			return -EINVAL;
		o->leaves[o->leaf_count][0] = tree_leaf_first(ch);
		o->leaves[o->leaf_count][1] = tree_leaf_count(ch);
		w->meta[s] = (cw_u8)(CW_META_CHILD | (o->leaf_count++ - w->leaf_base));
		return 0;
	}
	if (o->node_count == c->node_cap)
		return -EINVAL; /* more nodes than the tree has inner ones: a cycle */
	o->source[o->node_count] = child;
	c->depth[o->node_count++] = depth + 1;
	o->depth = depth + 1 > o->depth ? depth + 1 : o->depth;
	w->meta[s] = (cw_u8)(CW_META_CHILD | (CW_META_INNER_BASE + (uint32_t)s));
	w->imask |= (cw_u8)(1u << s);
	return 0;
}

/* Node q of the queue: children gathered, slotted and placed, inner ones
 * in slot order (so an inner child's rank among the slots is its offset). */
static int encode_one(struct encoder *c, uint32_t q)
{
	uint32_t list[CW_WIDTH], n;
	int slot_of[CW_WIDTH], r = gather(c, c->out->source[q], list, &n);
	cw_node *w = &c->out->nodes[q];
	memset(w, 0, sizeof(*w));
	if (r == 0)
		r = grid(c, list, n, w);
	if (r < 0)
		return r;
	assign_slots(c, list, n, slot_of);
	w->child_base = c->out->node_count;
	w->leaf_base = c->out->leaf_count;
	for (int s = 0; r == 0 && s < CW_WIDTH; s++)
		for (uint32_t i = 0; r == 0 && i < n; i++)
			if (slot_of[i] == s)
				r = place(c, w, list[i], s, c->depth[q]);
	return r;
}

/* Capacities: a compressed node per inner node at most (one for a leaf
 * root), a range per leaf. */
static int reserve(struct encoder *c)
{
	uint32_t leaves = 0;
	for (uint32_t i = 0; i < c->tree->node_count; i++)
		leaves += tree_is_leaf(&c->tree->nodes[i]);
	c->node_cap = c->tree->node_count - leaves + 1;
	c->leaf_cap = leaves;
	c->out->nodes = malloc(c->node_cap * sizeof(*c->out->nodes));
	c->out->leaves = malloc((leaves ? leaves : 1) * sizeof(*c->out->leaves));
	c->out->source = malloc(c->node_cap * sizeof(*c->out->source));
	c->depth = malloc(c->node_cap * sizeof(*c->depth));
	return c->out->nodes && c->out->leaves && c->out->source && c->depth ? 0 : -ENOMEM;
}

int cwbvh_encode(const bvhlab_tree *tree, struct cwbvh *out, bvhlab_error *err)
{
	struct encoder c = {.tree = tree, .out = out, .collapse = tree_width(tree) <= 4};
	*out = (struct cwbvh){0};
	if (tree->node_count == 0)
		return 0;
	int r = reserve(&c);
	if (r == 0) {
		out->source[0] = 0;
		c.depth[out->node_count++] = 0;
		for (uint32_t q = 0; r == 0 && q < out->node_count; q++)
			r = encode_one(&c, q);
	}
	free(c.depth);
	if (r < 0) {
		error_set(err, r == -ENOMEM ? "cwbvh: out of memory"
		                            : "cwbvh: the tree's links do not make a tree of at most 8 "
		                              "children, or a box is not finite");
		cwbvh_free(out);
	}
	return r;
}

void cwbvh_free(struct cwbvh *c)
{
	if (!c)
		return;
	free(c->nodes);
	free(c->leaves);
	free(c->source);
	*c = (struct cwbvh){0};
}

uint64_t cwbvh_bytes(const struct cwbvh *c)
{
	return (uint64_t)c->node_count * sizeof(cw_node) + (uint64_t)c->leaf_count * 8u;
}
