/*
 * bvhlab — ownership of a tree's two arrays.
 *
 * A tree is plain data in the standard layout (see bvhlab_node); this file
 * only allocates, grows and frees it. Capacities may exceed the counts: the
 * host hands builders buffers sized for the usual bound (2n - 1 nodes, n
 * indices) and builders say how much they used.
 */
#include <errno.h>
#include <stdlib.h>
#include <string.h>

#include <bvhlab/tree.h>

/* realloc that keeps the old block on failure; size 0 keeps what is there. */
static int grow_array(void **array, size_t count, size_t elem)
{
	void *grown;

	if (count == 0)
		return 0;
	grown = realloc(*array, count * elem);
	if (!grown)
		return -ENOMEM;
	*array = grown;
	return 0;
}

int bvhlab_tree_init(bvhlab_tree *tree, uint32_t node_capacity, uint32_t index_capacity)
{
	int rc;

	memset(tree, 0, sizeof(*tree));
	rc = bvhlab_tree_reserve(tree, node_capacity, index_capacity);
	if (rc < 0)
		bvhlab_tree_finish(tree);
	return rc;
}

int bvhlab_tree_reserve(bvhlab_tree *tree, uint32_t node_capacity, uint32_t index_capacity)
{
	void *nodes = tree->nodes, *indices = tree->prim_index;
	int rc;

	if (node_capacity > tree->node_capacity) {
		rc = grow_array(&nodes, node_capacity, sizeof(bvhlab_node));
		if (rc < 0)
			return rc;
		tree->nodes = nodes;
		tree->node_capacity = node_capacity;
	}
	if (index_capacity > tree->index_capacity) {
		/* The node array may have grown already: the tree stays consistent,
		 * with a larger node capacity, so a failure here leaks nothing. */
		rc = grow_array(&indices, index_capacity, sizeof(uint32_t));
		if (rc < 0)
			return rc;
		tree->prim_index = indices;
		tree->index_capacity = index_capacity;
	}
	return 0;
}

void bvhlab_tree_finish(bvhlab_tree *tree)
{
	if (!tree)
		return;
	free(tree->nodes);
	free(tree->prim_index);
	memset(tree, 0, sizeof(*tree));
}
