/*
 * bvhlab — the tree interface's two whole-tree services: refusing a wide
 * tree to a binary-only stage by name, and the binary expansion of a wide
 * tree for consumers whose layout is binary (the device tracer's upload).
 */
#include <errno.h>
#include <stdlib.h>

#include "tree/tree_view.h"
#include "util/util.h"

int tree_require_binary(const bvhlab_tree *t, const char *stage, bvhlab_error *err)
{
	if (tree_width(t) == 2)
		return 0;
	error_set(err, "%s takes binary trees only; this tree is %u-wide (ABI 1.5 width): use "
	          "it on the binary tree before any collapse", stage, tree_width(t));
	return -ENOTSUP;
}

/* A node to write into out[slot]: node `node` itself (hi 0) or a binary
 * node over its children lo .. hi - 1. */
struct item {
	uint32_t slot, node, lo, hi;
};

static void range_box(const bvhlab_tree *t, const struct item *it, bvhlab_node *out)
{
	const bvhlab_node *n = &t->nodes[it->node];
	for (uint32_t i = it->lo; i < it->hi; i++) {
		const bvhlab_node *c = &t->nodes[tree_child(n, i)];
		for (int k = 0; k < 3; k++) {
			out->lo[k] = i == it->lo || c->lo[k] < out->lo[k] ? c->lo[k] : out->lo[k];
			out->hi[k] = i == it->lo || c->hi[k] > out->hi[k] ? c->hi[k] : out->hi[k];
		}
	}
}

/* One item: a leaf copied, or a binary node whose two children are queued. */
static int expand(const bvhlab_tree *t, const struct item *it, bvhlab_node *out,
                  uint32_t *used, uint32_t cap, struct item *queue, uint32_t *tail)
{
	const bvhlab_node *n = &t->nodes[it->node];
	bvhlab_node *o = &out[it->slot];
	if (it->hi == 0 && tree_is_leaf(n)) {
		*o = *n;
		return 0;
	}
	if (tree_children_end(n) > t->node_count || *used + 2 > cap)
		return -EINVAL;
	uint32_t lo = it->hi ? it->lo : 0, hi = it->hi ? it->hi : tree_child_count(n);
	uint32_t mid = lo + (hi - lo) / 2, pair = *used;
	if (it->hi)
		range_box(t, it, o);
	else
		*o = *n;
	tree_set_children(o, pair, 2);
	*used += 2;
	queue[(*tail)++] = mid - lo == 1 ? (struct item){pair, tree_child(n, lo), 0, 0}
	                                 : (struct item){pair, it->node, lo, mid};
	queue[(*tail)++] = hi - mid == 1 ? (struct item){pair + 1, tree_child(n, mid), 0, 0}
	                                 : (struct item){pair + 1, it->node, mid, hi};
	return 0;
}

int tree_binary_nodes(const bvhlab_tree *t, bvhlab_node **nodes, uint32_t *count)
{
	uint64_t cap = t->node_count;
	for (uint32_t i = 0; i < t->node_count; i++)
		cap += tree_child_count(&t->nodes[i]) ? tree_child_count(&t->nodes[i]) - 2 : 0;
	*nodes = NULL;
	*count = 0;
	if (cap >= UINT32_MAX || t->node_count == 0)
		return -EINVAL;
	bvhlab_node *out = malloc(cap * sizeof(*out));
	struct item *queue = malloc(cap * sizeof(*queue));
	uint32_t used = 1, head = 0, tail = 0;
	int r = out && queue ? 0 : -ENOMEM;
	if (r == 0)
		queue[tail++] = (struct item){0, 0, 0, 0};
	/* Each item fills a distinct slot below used <= cap: the queue fits. */
	while (r == 0 && head < tail)
		r = expand(t, &queue[head++], out, &used, (uint32_t)cap, queue, &tail);
	free(queue);
	if (r < 0) {
		free(out);
		return r;
	}
	*nodes = out;
	*count = used;
	return 0;
}
