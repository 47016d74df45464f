/*
 * bvhlab — ownership of a tree's two arrays.
 *
 * A tree is plain data in the standard layout (see bvhlab_node); this file
 * only allocates, grows and frees it. Capacities may exceed the counts: the
 * host hands builders buffers sized for the usual bound (2n - 1 nodes, n
 * indices) and builders say how much they used.
 */
#include <errno.h>
#include <stdint.h>
#include <stdlib.h>
#include <string.h>
#include <sys/mman.h>

#include <bvhlab/tree.h>

#define PAGE ((uintptr_t)4096)
#define HUGE_PAGE ((size_t)2 << 20)

/*
 * Asks for transparent huge pages on a large block (malloc maps those on
 * their own): a builder's first build otherwise takes a 4 KiB page fault
 * for every 4 KiB of the output it writes, which at millions of nodes cost
 * more than the build (a cold lbvh build at 20M triangles was 4.6x its
 * warm median). A hint: refused or unsupported, nothing changes.
 */
static void advise_huge(void *block, size_t bytes)
{
#ifdef MADV_HUGEPAGE
	uintptr_t from = ((uintptr_t)block + PAGE - 1) & ~(PAGE - 1);
	uintptr_t to = ((uintptr_t)block + bytes) & ~(PAGE - 1);

	if (bytes >= 4 * HUGE_PAGE && to > from)
		(void)madvise((void *)from, to - from, MADV_HUGEPAGE);
#else
	(void)block;
	(void)bytes;
#endif
}

/* realloc that keeps the old block on failure; size 0 keeps what is there. */
static int grow_array(void **array, size_t count, size_t elem)
{
	void *grown;

	if (count == 0)
		return 0;
	grown = realloc(*array, count * elem);
	if (!grown)
		return -ENOMEM;
	advise_huge(grown, count * elem);
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
