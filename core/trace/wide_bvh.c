/*
 * Collapsing a tree into the wide traversal's 4-child nodes, once per
 * batch. Opening the child of largest surface area first keeps the nodes a
 * ray is most likely to enter near the top, as Embree and tinybvh's wide
 * layouts do when they collapse a binary build. A node of a wider tree
 * whose children do not fit in the lanes left is opened in halves first
 * (a piece: children lo .. hi - 1 of one node, its box their union).
 */
#include <errno.h>
#include <math.h>
#include <stdbool.h>
#include <stdint.h>
#include <stdlib.h>
#include <string.h>

#include <bvhlab/aabb.h>

#include "trace/trace_wide.h"
#include "tree/tree_view.h"
#include "util/util.h"

/* Subtrees of at most this many triangles become one leaf lane (two
 * groups): on igea subdivided once, 4 gave 0.65 of Embree's speed, 8 gave
 * 0.74; 16 and 32 gave more (0.79, 0.83) but flatten so much of the
 * builder's tree that its lower levels would no longer count. */
#define SMALL (2 * TRI_LANES)

/* A node, or a piece of one (hi > 0: its children lo .. hi - 1). */
struct piece {
	uint32_t node, lo, hi;
};

/* A node or piece waiting to become the wide node `wide`, at wide level `level`. */
struct pending {
	struct piece at;
	uint32_t wide, level;
};

struct collapse {
	const bvhlab_tree *tree;
	const bvhlab_scene *scene;
	uint32_t group_cap;
	struct wide_bvh *w;
	uint8_t *seen;          /* binary nodes already placed in a lane */
	struct pending *todo;
	uint32_t todo_count, cap;
};

/* A lane being gathered: a node or piece, and when it is an inner node
 * with at most SMALL triangles below it, their slots (a leaf lane then). */
struct lane {
	struct piece at;
	uint32_t small; /* how many slots; 0: a leaf, or an inner node to open */
	uint32_t slots[SMALL];
};

/* The box of a lane: its node's, or the union of its piece's children. */
static void lane_box(const struct collapse *c, const struct lane *l, float lo[3], float hi[3])
{
	const bvhlab_node *n = &c->tree->nodes[l->at.node];
	for (int k = 0; k < 3; k++)
		lo[k] = n->lo[k], hi[k] = n->hi[k];
	for (uint32_t i = l->at.lo; i < l->at.hi; i++) {
		const bvhlab_node *b = &c->tree->nodes[tree_child(n, i)];
		for (int k = 0; k < 3; k++) {
			lo[k] = i == l->at.lo || b->lo[k] < lo[k] ? b->lo[k] : lo[k];
			hi[k] = i == l->at.lo || b->hi[k] > hi[k] ? b->hi[k] : hi[k];
		}
	}
}

static void set_lane(const struct collapse *c, struct wide_node *w, uint32_t i,
                     const struct lane *l)
{
	float lo[3], hi[3];
	if (l)
		lane_box(c, l, lo, hi);
	for (int k = 0; k < 3; k++) {
		w->box[k][i] = l ? lo[k] : INFINITY;
		w->box[3 + k][i] = l ? hi[k] : -INFINITY;
	}
}

/* Lane `lane` of group g: slot `slot`'s triangle, or NaN vertices. */
static void group_lane(struct collapse *c, struct wide_tris *g, uint32_t lane, uint32_t slot,
                       bool used)
{
	const bvhlab_scene *s = c->scene;
	uint32_t prim = used ? c->tree->prim_index[slot] : BVHLAB_NO_HIT;
	g->prim[lane] = prim;
	for (int j = 0; j < 3; j++) {
		const float *v = prim < s->triangle_count
		                         ? s->vertices + 3 * (size_t)s->indices[3 * (size_t)prim + j]
		                         : NULL;
		for (int k = 0; k < 3; k++)
			g->v[3 * j + k][lane] = v ? v[k] : NAN;
	}
}

/*
 * Wide lane i as a leaf of n triangles copied into groups: those of slots
 * (a small subtree's), or with slots NULL those of slots first..first+n-1
 * (a leaf of the tree, of any size).
 */
static int leaf_lane(struct collapse *c, struct wide_node *w, uint32_t i,
                     const uint32_t *slots, uint32_t first, uint32_t n)
{
	uint64_t groups = ((uint64_t)n + TRI_LANES - 1) / TRI_LANES;
	if (groups > c->group_cap - c->w->tri_groups)
		return -EINVAL;
	w->child[i] = c->w->tri_groups;
	w->count[i] = n;
	for (uint32_t k = 0; k < n; k += TRI_LANES) {
		struct wide_tris *g = &c->w->tris[c->w->tri_groups++];
		for (uint32_t lane = 0; lane < TRI_LANES; lane++) {
			uint32_t at = k + lane;
			group_lane(c, g, lane, slots ? (at < n ? slots[at] : 0) : first + at, at < n);
		}
	}
	return 0;
}

/*
 * The slots of the triangles under inner node `node` when there are at
 * most SMALL of them: such a subtree becomes one leaf lane, whose groups'
 * vector triangle tests cost less than walking its nodes. 0 when there
 * are more (or links a tree cannot have).
 */
static uint32_t small_subtree(const struct collapse *c, uint32_t node, uint32_t slots[SMALL])
{
	const bvhlab_tree *t = c->tree;
	uint32_t stack[2 * SMALL], sp = 0, n = 0, visits = 0;
	stack[sp++] = node;
	while (sp > 0) {
		const bvhlab_node *b = &t->nodes[stack[--sp]];
		uint32_t first = tree_leaf_first(b), count = tree_leaf_count(b);
		if (++visits > 2 * SMALL)
			return 0;
		if (tree_is_leaf(b)) {
			if (count > SMALL - n || first > t->index_count - count)
				return 0;
			for (uint32_t i = 0; i < count; i++)
				slots[n++] = first + i;
		} else {
			if (tree_child(b, 0) == 0 || tree_children_end(b) > t->node_count ||
			    sp + tree_child_count(b) > 2 * SMALL)
				return 0;
			for (uint32_t i = 0; i < tree_child_count(b); i++)
				stack[sp++] = tree_child(b, i);
		}
	}
	return n;
}

/* Lane l for node `node`, its small subtree found once here. */
static void take_lane(const struct collapse *c, struct lane *l, uint32_t node)
{
	l->at = (struct piece){node, 0, 0};
	l->small = tree_is_leaf(&c->tree->nodes[node]) ? 0 : small_subtree(c, node, l->slots);
}

/* Lane l for children lo .. hi - 1 of `node`: the child itself when one. */
static int take_piece(struct collapse *c, struct lane *l, uint32_t node, uint32_t lo,
                      uint32_t hi)
{
	if (hi - lo > 1) {
		*l = (struct lane){.at = {node, lo, hi}};
		return 0;
	}
	uint32_t child = tree_child(&c->tree->nodes[node], lo);
	if (c->seen[child])
		return -EINVAL;
	c->seen[child] = 1;
	take_lane(c, l, child);
	return 0;
}

/* Replaces lane[at] by its children, the first at lane[at] and the rest
 * from lane[*n] on, or by two halves when they would not fit in WIDE. */
static int open_lane(struct collapse *c, struct lane *lane, uint32_t at, uint32_t *n)
{
	struct piece p = lane[at].at;
	const bvhlab_node *b = &c->tree->nodes[p.node];
	uint32_t lo = p.hi ? p.lo : 0, hi = p.hi ? p.hi : tree_child_count(b);
	if (tree_child(b, 0) == 0 || tree_children_end(b) > c->tree->node_count)
		return -EINVAL;
	if (hi - lo > WIDE - *n + 1) {
		uint32_t mid = lo + (hi - lo) / 2;
		int r = take_piece(c, &lane[at], p.node, lo, mid);
		return r < 0 ? r : take_piece(c, &lane[(*n)++], p.node, mid, hi);
	}
	for (uint32_t k = lo; k < hi; k++) {
		int r = take_piece(c, &lane[k == lo ? at : (*n)++], p.node, k, k + 1);
		if (r < 0)
			return r;
	}
	return 0;
}

static bool lane_opens(const struct collapse *c, const struct lane *l)
{
	return l->at.hi > 0 || (!tree_is_leaf(&c->tree->nodes[l->at.node]) && l->small == 0);
}

/* The nodes under piece `p` that become one wide node's lanes: the inner
 * lane of largest area that is not a small subtree is opened until there
 * are WIDE. */
static int gather(struct collapse *c, struct piece p, struct lane lane[WIDE], uint32_t *lanes)
{
	uint32_t n = 1;
	lane[0] = (struct lane){.at = p};
	int r = open_lane(c, lane, 0, &n);
	while (r == 0 && n < WIDE) {
		int best = -1;
		float best_area = -1.0f;
		for (uint32_t i = 0; i < n; i++) {
			float lo[3], hi[3];
			lane_box(c, &lane[i], lo, hi);
			float a = bvhlab_half_area(lo, hi);
			if (!(a <= best_area) && lane_opens(c, &lane[i])) {
				best = (int)i;
				best_area = a;
			}
		}
		if (best < 0)
			break;
		r = open_lane(c, lane, (uint32_t)best, &n);
	}
	*lanes = n;
	return r;
}

/* An inner lane: its node becomes a new wide node, filled later. */
static int inner_lane(struct collapse *c, struct wide_node *w, uint32_t i, struct piece at,
                      uint32_t level)
{
	if (c->w->node_count == c->cap)
		return -EINVAL; /* more wide nodes than pieces: links are shared */
	uint32_t id = c->w->node_count++;
	w->child[i] = id;
	w->count[i] = 0;
	c->todo[c->todo_count++] = (struct pending){at, id, level};
	return 0;
}

/* A leaf of the tree as a leaf lane, checked against the index array so
 * the traversal need not. */
static int tree_leaf(struct collapse *c, struct wide_node *w, uint32_t i, const bvhlab_node *b)
{
	uint32_t first = tree_leaf_first(b), count = tree_leaf_count(b);
	if (first > c->tree->index_count || count > c->tree->index_count - first)
		return -EINVAL;
	return leaf_lane(c, w, i, NULL, first, count);
}

static int fill(struct collapse *c, const struct pending *p)
{
	const bvhlab_node *nodes = c->tree->nodes;
	struct wide_node *w = &c->w->nodes[p->wide];
	struct lane lane[WIDE];
	uint32_t n = 1;
	int r = 0;
	if (p->at.hi > 0 || !tree_is_leaf(&nodes[p->at.node]))
		r = gather(c, p->at, lane, &n);
	else
		lane[0] = (struct lane){.at = p->at}; /* a leaf root */
	for (uint32_t i = 0; r == 0 && i < WIDE; i++) {
		const struct lane *l = i < n ? &lane[i] : NULL;
		const bvhlab_node *b = l ? &nodes[l->at.node] : NULL;
		set_lane(c, w, i, l);
		if (!b) {
			w->child[i] = 0;
			w->count[i] = WIDE_EMPTY;
		} else if (l->at.hi == 0 && tree_is_leaf(b)) {
			r = tree_leaf(c, w, i, b);
		} else if (l->small) {
			r = leaf_lane(c, w, i, l->slots, 0, l->small);
		} else {
			r = inner_lane(c, w, i, l->at, p->level + 1);
		}
	}
	if (c->w->depth < p->level)
		c->w->depth = p->level;
	return r;
}

/* The pieces that can become wide nodes: the inner nodes, and the k - 2
 * halves at most a node of k children is opened in; and the triangle
 * groups the leaves need (saturating: a sum that overflows is a tree no
 * wide copy can hold). */
static void count_nodes(const bvhlab_tree *tree, uint32_t *pieces, uint32_t *groups)
{
	uint64_t g = 0, p = 0;
	for (uint32_t i = 0; i < tree->node_count; i++) {
		const bvhlab_node *n = &tree->nodes[i];
		uint32_t k = tree_child_count(n);
		p += k ? k - 1 : 0;
		g += (tree_leaf_count(n) + (uint64_t)TRI_LANES - 1) / TRI_LANES;
	}
	*pieces = p < UINT32_MAX - 1 ? (uint32_t)p : UINT32_MAX - 1;
	*groups = g < UINT32_MAX ? (uint32_t)g : UINT32_MAX;
}

int wide_bvh_init(struct wide_bvh *w, const bvhlab_tree *tree, const bvhlab_scene *scene)
{
	struct collapse c = {.tree = tree, .scene = scene, .w = w};
	memset(w, 0, sizeof(*w));
	if (tree->node_count == 0)
		return -EINVAL;
	count_nodes(tree, &c.cap, &c.group_cap);
	c.cap++; /* a leaf root still needs one wide node */
	c.seen = calloc(tree->node_count, 1);
	c.todo = malloc(c.cap * sizeof(*c.todo));
	w->nodes = util_big_alloc(c.cap, sizeof(*w->nodes));
	w->tris = util_big_alloc(c.group_cap, sizeof(*w->tris));
	int r = c.seen && c.todo && w->nodes && w->tris ? 0 : -ENOMEM;
	if (r == 0) {
		w->node_count = 1;
		c.todo[c.todo_count++] = (struct pending){{0, 0, 0}, 0, 1};
	}
	while (r == 0 && c.todo_count > 0) {
		struct pending p = c.todo[--c.todo_count];
		r = fill(&c, &p);
	}
	free(c.seen);
	free(c.todo);
	if (r < 0)
		wide_bvh_finish(w);
	return r;
}

void wide_bvh_finish(struct wide_bvh *w)
{
	free(w->nodes);
	free(w->tris);
	memset(w, 0, sizeof(*w));
}
