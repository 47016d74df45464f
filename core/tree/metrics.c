/*
 * bvhlab — quality metrics of a built tree: SAH cost, counts, depth, leaf
 * sizes and memory, the same for every builder.
 *
 * The input is a tree that passed bvhlab_validate_tree, so every node in
 * [0, node_count) is reachable exactly once: counts, cost and histogram are
 * a plain scan of the node array, whatever order the builder wrote it in.
 * Only the depth needs a walk from the root.
 */
#include <stdlib.h>
#include <string.h>

#include <bvhlab/aabb.h>
#include <bvhlab/tree.h>

#include "tree/tree_view.h"

#define LOCAL_STACK 128

typedef struct depth_entry {
	uint32_t node;
	uint32_t depth;
} depth_entry;

/* Doubles a heap copy of the stack; false when out of memory. */
static bool grow(depth_entry **stack, uint32_t *cap, depth_entry *local)
{
	depth_entry *grown = malloc((size_t)*cap * 2 * sizeof(*grown));

	if (!grown)
		return false;
	memcpy(grown, *stack, (size_t)*cap * sizeof(*grown));
	if (*stack != local)
		free(*stack);
	*stack = grown;
	*cap *= 2;
	return true;
}

/*
 * Deepest node, root at depth 0, by an explicit stack: a degenerate tree
 * can be as deep as it has leaves. UINT32_MAX if the stack outgrew memory
 * (the function cannot fail, so the sentinel is the report). The visit
 * bound and the child range check only protect against unvalidated input.
 */
static uint32_t max_depth(const bvhlab_tree *tree)
{
	depth_entry local[LOCAL_STACK], *stack = local;
	uint32_t cap = LOCAL_STACK, sp = 0, deepest = 0;
	uint64_t visits = 0;

	stack[sp++] = (depth_entry){ 0, 0 };
	while (sp > 0 && visits++ < tree->node_count) {
		depth_entry e = stack[--sp];
		const bvhlab_node *n = &tree->nodes[e.node];

		deepest = e.depth > deepest ? e.depth : deepest;
		if (tree_is_leaf(n) || tree_children_end(n) > tree->node_count ||
		    tree_child_count(n) > BVHLAB_MAX_WIDTH)
			continue;
		if (sp + BVHLAB_MAX_WIDTH > cap && !grow(&stack, &cap, local)) {
			deepest = UINT32_MAX;
			break;
		}
		for (uint32_t k = 0; k < tree_child_count(n); k++)
			stack[sp++] = (depth_entry){ tree_child(n, k), e.depth + 1 };
	}
	if (stack != local)
		free(stack);
	return deepest;
}

static void count_leaf(bvhlab_tree_stats *stats, uint32_t count)
{
	stats->leaves++;
	stats->leaf_histogram[count <= BVHLAB_LEAF_HISTOGRAM - 1 ? count - 1
	                                                        : BVHLAB_LEAF_HISTOGRAM - 1]++;
}

/*
 * SAH cost as documented in tree.h:
 *   (sum over inner n of SA(n) * k(n) / 2 + sum over leaves l of SA(l) * count(l))
 *   / SA(root), k(n) the children of n (tree_trav_cost: 1 for a binary node).
 * SA(n) / SA(root) is the chance that a ray hitting the root hits n. When
 * the root has no area (all primitives on a line or a point) that ratio is
 * 0 / 0; every ray that meets such a scene meets all of it, so each node
 * counts with ratio 1: cost = the inner nodes' k(n) / 2 + primitive
 * references (binary: inner nodes + references). That is
 * also the limit of the formula for a box squashed flat uniformly, and it
 * keeps a single-leaf tree at cost = count, as for any other root.
 */
void bvhlab_tree_stats_compute(const bvhlab_tree *tree, bvhlab_tree_stats *stats)
{
	double root_area, inner_area = 0.0, leaf_area = 0.0, inner = 0.0;
	uint64_t refs = 0;
	uint32_t i;

	memset(stats, 0, sizeof(*stats));
	stats->nodes = tree->node_count;
	stats->memory_bytes = (uint64_t)tree->node_count * sizeof(bvhlab_node) +
	                      (uint64_t)tree->index_count * sizeof(uint32_t);
	if (tree->node_count == 0)
		return;
	for (i = 0; i < tree->node_count; i++) {
		const bvhlab_node *n = &tree->nodes[i];

		if (!tree_is_leaf(n)) {
			inner += tree_trav_cost(n);
			inner_area += bvhlab_box_area(n->lo, n->hi) * tree_trav_cost(n);
			continue;
		}
		count_leaf(stats, tree_leaf_count(n));
		refs += tree_leaf_count(n);
		leaf_area += bvhlab_box_area(n->lo, n->hi) * tree_leaf_count(n);
	}
	root_area = bvhlab_box_area(tree->nodes[0].lo, tree->nodes[0].hi);
	if (root_area > 0.0)
		stats->sah_cost = (inner_area + leaf_area) / root_area;
	else
		stats->sah_cost = inner + (double)refs;
	stats->avg_leaf_size = stats->leaves ? (double)refs / stats->leaves : 0.0;
	stats->refs = refs;
	stats->max_depth = max_depth(tree);
}
