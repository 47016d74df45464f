/*
 * bvhlab — ownership of a tree's two arrays.
 *
 * A tree is plain data in the standard layout (see bvhlab_node); this file
 * only allocates, grows and frees it. Capacities may exceed the counts: the
 * host hands builders buffers sized for the usual bound (2n - 1 nodes, n
 * indices) and builders say how much they used.
 */
/* mremap needs _GNU_SOURCE, which the build defines. */
#include <errno.h>
#include <stdint.h>
#include <stdlib.h>
#include <string.h>
#include <sys/mman.h>
#include <unistd.h>

#include <bvhlab/tree.h>

#include "tree/tree_spare.h"

/*
 * Arrays of at least BIG_ARRAY bytes are page mappings of their own, grown
 * with mremap: glibc's realloc copies a large block into a fresh one, and
 * that copy pages in (and the kernel zeroes) the whole new block on one
 * thread before the builder writes a byte. lbvh grows its 20M-triangle
 * output by a few per cent at every cold build: the copy was 4 s of a
 * 5.5 s first build, the parallel build itself 1.3 s. Which kind an array
 * is follows from its capacity alone, so the struct needs no flag.
 */
#define BIG_ARRAY ((size_t)32 << 20)

static size_t page_round(size_t bytes)
{
	size_t page = (size_t)sysconf(_SC_PAGESIZE);
	return (bytes + page - 1) / page * page;
}

static void *map_array(size_t bytes)
{
	void *p = mmap(NULL, page_round(bytes), PROT_READ | PROT_WRITE,
	               MAP_PRIVATE | MAP_ANONYMOUS, -1, 0);
	if (p == MAP_FAILED)
		return NULL;
	(void)madvise(p, page_round(bytes), MADV_HUGEPAGE);
	return p;
}

static void free_array(void *array, size_t capacity, size_t elem)
{
	if (array && capacity * elem >= BIG_ARRAY)
		munmap(array, page_round(capacity * elem));
	else
		free(array);
}

/* A larger block holding the old one's contents; NULL keeps the old one. */
static void *regrow(void *old, size_t old_count, size_t count, size_t elem)
{
	size_t was = old_count * elem, bytes = count * elem;
	void *grown;

	if (bytes < BIG_ARRAY)
		return realloc(old, bytes);
	if (old && was >= BIG_ARRAY) {
		grown = mremap(old, page_round(was), page_round(bytes), MREMAP_MAYMOVE);
		return grown == MAP_FAILED ? NULL : grown;
	}
	grown = map_array(bytes);
	if (grown && old) {
		memcpy(grown, old, was);
		free(old);
	}
	return grown;
}

/* Grows *array from old_count to count elements, keeping the old block on
 * failure; a count of 0 keeps what is there. */
static int grow_array(void **array, size_t old_count, size_t count, size_t elem)
{
	void *grown;

	if (count == 0)
		return 0;
	grown = regrow(*array, old_count, count, elem);
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
		rc = grow_array(&nodes, tree->node_capacity, node_capacity, sizeof(bvhlab_node));
		if (rc < 0)
			return rc;
		tree->nodes = nodes;
		tree->node_capacity = node_capacity;
	}
	if (index_capacity > tree->index_capacity) {
		/* The node array may have grown already: the tree stays consistent,
		 * with a larger node capacity, so a failure here leaks nothing. */
		rc = grow_array(&indices, tree->index_capacity, index_capacity, sizeof(uint32_t));
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
	free_array(tree->nodes, tree->node_capacity, sizeof(bvhlab_node));
	free_array(tree->prim_index, tree->index_capacity, sizeof(uint32_t));
	memset(tree, 0, sizeof(*tree));
}

/* The whole pages of one array past `used` elements, given back: inside
 * the block, so a malloc'd array's neighbours are not touched. */
static void release_tail(void *array, size_t used, size_t capacity, size_t elem)
{
	uintptr_t page = (uintptr_t)sysconf(_SC_PAGESIZE);
	uintptr_t from = ((uintptr_t)array + used * elem + page - 1) / page * page;
	uintptr_t end = ((uintptr_t)array + capacity * elem) / page * page;

	if (array && end > from)
		(void)madvise((void *)from, end - from, MADV_DONTNEED);
}

void tree_release_spare(bvhlab_tree *tree)
{
	release_tail(tree->nodes, tree->node_count, tree->node_capacity, sizeof(bvhlab_node));
	release_tail(tree->prim_index, tree->index_count, tree->index_capacity,
	             sizeof(uint32_t));
}
