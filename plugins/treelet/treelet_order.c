/*
 * The order of a round (see treelet.h): the tasks' inner nodes, each task
 * in post-order, then the top nodes above the tasks in post-order.
 */
#include <string.h>

#include <bvhlab/aabb.h>

#include "treelet.h"

/* size[x]: nodes in x's subtree, and t's prims[x], and cost[x] of the
 * leaves (an inner node's is taken from its children when the round
 * reaches it: treelet_optimise); `pre` gets a pre-order of the tree. */
static void subtree_sizes(treelet *t, uint32_t *stack, uint32_t *pre, uint32_t *size)
{
	const bvhlab_node *nodes = t->nodes;
	uint32_t m = 0, sp = 0;

	stack[sp++] = 0;
	while (sp) {
		uint32_t x = stack[--sp];
		pre[m++] = x;
		if (nodes[x].count == 0) {
			stack[sp++] = nodes[x].first;
			stack[sp++] = nodes[x].first + 1;
		}
	}
	while (m-- > 0) {
		uint32_t x = pre[m], l = nodes[x].first;

		if (nodes[x].count) {
			size[x] = 1;
			t->prims[x] = nodes[x].count;
			t->cost[x] = bvhlab_box_area(nodes[x].lo, nodes[x].hi) * nodes[x].count;
			continue;
		}
		size[x] = 1 + size[l] + size[l + 1];
		t->prims[x] = t->prims[l] + t->prims[l + 1];
	}
}

/*
 * Appends the inner nodes of x's subtree to out in post-order; with `top`,
 * stopping at subtrees of at most task_nodes (the tasks'): a pre-order
 * that visits the right child first, reversed. `stack` has room
 * for the subtree.
 */
static uint32_t post_order(const bvhlab_node *nodes, uint32_t x, const uint32_t *size,
                           uint32_t task_nodes, bool top, uint32_t *stack, uint32_t *out)
{
	uint32_t sp = 0, m = 0;

	stack[sp++] = x;
	while (sp) {
		uint32_t y = stack[--sp];
		if (nodes[y].count != 0 || (top && size[y] <= task_nodes))
			continue;
		out[m++] = y;
		stack[sp++] = nodes[y].first;
		stack[sp++] = nodes[y].first + 1;
	}
	for (uint32_t i = 0, j = m; i + 1 < j; i++, j--) {
		uint32_t tmp = out[i];
		out[i] = out[j - 1];
		out[j - 1] = tmp;
	}
	return m;
}

/* The task roots in pre-order: subtrees of at most task_nodes whose parent's is larger. */
static uint32_t task_roots(const bvhlab_node *nodes, const uint32_t *size, uint32_t task_nodes,
                           uint32_t *stack, uint32_t *roots)
{
	uint32_t sp = 0, m = 0;

	stack[sp++] = 0;
	while (sp) {
		uint32_t y = stack[--sp];
		if (size[y] <= task_nodes) {
			if (nodes[y].count == 0)
				roots[m++] = y;
			continue;
		}
		stack[sp++] = nodes[y].first + 1;
		stack[sp++] = nodes[y].first;
	}
	return m;
}

void treelet_plan(treelet *t, uint32_t task_nodes, uint32_t *scratch)
{
	uint32_t n = t->node_count, *size = scratch, *stack = scratch + n, at = 0;

	subtree_sizes(t, stack, t->order, size);
	t->tasks = task_roots(t->nodes, size, task_nodes, stack, t->task_end);
	for (uint32_t k = 0; k < t->tasks; k++) {
		uint32_t root = t->task_end[k];
		at += post_order(t->nodes, root, size, task_nodes, false, stack, t->order + at);
		t->task_end[k] = at;
	}
	t->top_begin = at;
	t->top_end = at + post_order(t->nodes, 0, size, task_nodes, true, stack, t->order + at);
}
