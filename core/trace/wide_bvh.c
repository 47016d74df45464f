/*
 * Collapsing a binary tree into the wide traversal's 4-child nodes, once
 * per batch. Opening the child of largest surface area first keeps the
 * nodes a ray is most likely to enter near the top, as Embree and
 * tinybvh's wide layouts do when they collapse a binary build.
 */
#include <errno.h>
#include <math.h>
#include <stdbool.h>
#include <stdint.h>
#include <stdlib.h>
#include <string.h>

#include <bvhlab/aabb.h>

#include "trace/trace_wide.h"

#define LINE 64
/* Subtrees of at most this many triangles become one leaf lane (two
 * groups): on igea subdivided once, 4 gave 0.65 of Embree's speed, 8 gave
 * 0.74; 16 and 32 gave more (0.79, 0.83) but flatten so much of the
 * builder's tree that its lower levels would no longer count. */
#define SMALL (2 * TRI_LANES)

/* A binary node waiting to become the wide node `wide`, at wide level `level`. */
struct pending {
	uint32_t node, wide, level;
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

/* A lane being gathered: a binary node, and when it is an inner node with
 * at most SMALL triangles below it, their slots (it becomes a leaf lane). */
struct lane {
	uint32_t node;
	uint32_t small; /* how many slots; 0: a leaf, or an inner node to open */
	uint32_t slots[SMALL];
};

static void set_lane(struct wide_node *w, uint32_t i, const bvhlab_node *n)
{
	for (int k = 0; k < 3; k++) {
		w->box[k][i] = n ? n->lo[k] : INFINITY;
		w->box[3 + k][i] = n ? n->hi[k] : -INFINITY;
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
 * (a binary leaf, of any size).
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
		if (++visits > 2 * SMALL)
			return 0;
		if (b->count) {
			if (b->count > SMALL - n || b->first > t->index_count - b->count)
				return 0;
			for (uint32_t i = 0; i < b->count; i++)
				slots[n++] = b->first + i;
		} else {
			if (b->first == 0 || b->first >= t->node_count - 1 || sp + 2 > 2 * SMALL)
				return 0;
			stack[sp++] = b->first;
			stack[sp++] = b->first + 1;
		}
	}
	return n;
}

/* Lane l for binary node `node`, its small subtree found once here. */
static void take_lane(const struct collapse *c, struct lane *l, uint32_t node)
{
	l->node = node;
	l->small = c->tree->nodes[node].count ? 0 : small_subtree(c, node, l->slots);
}

/* Takes both children of inner node `node` as lanes at lane[at] and lane[n]. */
static int open_node(struct collapse *c, uint32_t node, struct lane *lane, uint32_t at,
                     uint32_t n)
{
	const bvhlab_tree *t = c->tree;
	uint32_t first = t->nodes[node].first;
	if (first == 0 || first >= t->node_count - 1 || c->seen[first] || c->seen[first + 1])
		return -EINVAL;
	c->seen[first] = c->seen[first + 1] = 1;
	take_lane(c, &lane[at], first);
	take_lane(c, &lane[n], first + 1);
	return 0;
}

/* The binary nodes under `node` that become one wide node's lanes: the
 * inner lane of largest area that is not a small subtree is opened until
 * there are WIDE. */
static int gather(struct collapse *c, uint32_t node, struct lane lane[WIDE], uint32_t *lanes)
{
	const bvhlab_node *nodes = c->tree->nodes;
	uint32_t n = 2;
	int r = open_node(c, node, lane, 0, 1);
	while (r == 0 && n < WIDE) {
		int best = -1;
		float best_area = -1.0f;
		for (uint32_t i = 0; i < n; i++) {
			const bvhlab_node *b = &nodes[lane[i].node];
			float a = bvhlab_half_area(b->lo, b->hi);
			if (!(a <= best_area) && b->count == 0 && lane[i].small == 0) {
				best = (int)i;
				best_area = a;
			}
		}
		if (best < 0)
			break;
		r = open_node(c, lane[best].node, lane, (uint32_t)best, n++);
	}
	*lanes = n;
	return r;
}

/* An inner lane: its node becomes a new wide node, filled later. */
static int inner_lane(struct collapse *c, struct wide_node *w, uint32_t i, uint32_t node,
                      uint32_t level)
{
	if (c->w->node_count == c->cap)
		return -EINVAL; /* more wide nodes than inner nodes: links are shared */
	uint32_t id = c->w->node_count++;
	w->child[i] = id;
	w->count[i] = 0;
	c->todo[c->todo_count++] = (struct pending){node, id, level};
	return 0;
}

/* A binary leaf as a leaf lane, checked against the index array so the
 * traversal need not. */
static int binary_leaf(struct collapse *c, struct wide_node *w, uint32_t i,
                       const bvhlab_node *b)
{
	if (b->first > c->tree->index_count || b->count > c->tree->index_count - b->first ||
	    b->count == WIDE_EMPTY)
		return -EINVAL;
	return leaf_lane(c, w, i, NULL, b->first, b->count);
}

static int fill(struct collapse *c, const struct pending *p)
{
	const bvhlab_node *nodes = c->tree->nodes;
	struct wide_node *w = &c->w->nodes[p->wide];
	struct lane lane[WIDE];
	uint32_t n = 1;
	int r = 0;
	if (nodes[p->node].count == 0)
		r = gather(c, p->node, lane, &n);
	else
		lane[0] = (struct lane){.node = p->node}; /* a leaf root */
	for (uint32_t i = 0; r == 0 && i < WIDE; i++) {
		const bvhlab_node *b = i < n ? &nodes[lane[i].node] : NULL;
		set_lane(w, i, b);
		if (!b) {
			w->child[i] = 0;
			w->count[i] = WIDE_EMPTY;
		} else if (b->count) {
			r = binary_leaf(c, w, i, b);
		} else if (lane[i].small) {
			r = leaf_lane(c, w, i, lane[i].slots, 0, lane[i].small);
		} else {
			r = inner_lane(c, w, i, lane[i].node, p->level + 1);
		}
	}
	if (c->w->depth < p->level)
		c->w->depth = p->level;
	return r;
}

/* Inner nodes, and triangle groups the leaves need (saturating: a sum
 * that overflows is a tree no wide copy can hold). */
static void count_nodes(const bvhlab_tree *tree, uint32_t *inner, uint32_t *groups)
{
	uint64_t g = 0;
	*inner = 0;
	for (uint32_t i = 0; i < tree->node_count; i++) {
		uint32_t n = tree->nodes[i].count;
		*inner += n == 0;
		g += (n + (uint64_t)TRI_LANES - 1) / TRI_LANES;
	}
	*groups = g < UINT32_MAX ? (uint32_t)g : UINT32_MAX;
}

static void *aligned(size_t count, size_t size)
{
	void *mem = NULL;
	if (count > SIZE_MAX / size || posix_memalign(&mem, LINE, count * size) != 0)
		return NULL;
	return mem;
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
	w->nodes = aligned(c.cap, sizeof(*w->nodes));
	w->tris = aligned(c.group_cap ? c.group_cap : 1, sizeof(*w->tris));
	int r = c.seen && c.todo && w->nodes && w->tris ? 0 : -ENOMEM;
	if (r == 0) {
		w->node_count = 1;
		c.todo[c.todo_count++] = (struct pending){0, 0, 1};
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
