/*
 * lbvh: a parallel LBVH builder. Primitives are sorted along a Morton curve
 * of their centroids and the hierarchy is emitted from the sorted codes
 * (Karras 2012); an SAH pass then collapses small subtrees into leaves.
 * The phases are described in lbvh.h.
 *
 * This file: options, scratch memory, the phases, build() on morton_build.
 */
#include <errno.h>
#include <string.h>

#include "lbvh.h"
#include "morton_front.h"

static const plugin_option options[] = { MORTON_OPTIONS(lbvh, sort.bits) };
PLUGIN_DECLS(options, lbvh, NULL)

/* ---- scratch ------------------------------------------------------------ */

/* The hierarchy's arrays; node_flags only with collapse. */
static size_t tree_size(size_t n, bool collapse)
{
	return morton_align64(n + 2 * LCP_PAD) + morton_align64(8 * n) +
	       2 * morton_align64(4 * n) + (collapse ? morton_align64(n) : 0);
}

static uint32_t spare_nodes(uint32_t n, bool collapse)
{
	return big_spare_nodes(n, tree_size(n, collapse));
}

static void place_tree(lbvh *b, char *p)
{
	size_t n = b->n;

	b->lcp = (uint8_t *)p + LCP_PAD;
	p += morton_align64(n + 2 * LCP_PAD);
	b->parent = (uint32_t *)(void *)p;
	p += morton_align64(8 * n);
	b->end = (uint32_t *)(void *)p;
	p += morton_align64(4 * n);
	b->visits = (atomic_uint *)(void *)p;
	p += morton_align64(4 * n);
	b->node_flags = b->collapse ? (uint8_t *)p : NULL;
}

/*
 * The hierarchy's arrays go past the tree in the output when the host
 * gave the room (morton_build asks for spare_nodes()), else into the fresh
 * mapping; there the arrival counters and flags start zeroed, in the
 * output the sort phase zeroes them (scratch_dirty).
 *
 * The sort's buffers live in the output node array when it is large enough
 * (always but for a few primitives): the host keeps that array between
 * builds, so it is paged in already, and the tree is written into it only
 * after the sort. Fresh pages cost more than the sort passes themselves.
 */
static int scratch_alloc(void *arg, bvhlab_build_output *out, morton_scratch *s)
{
	lbvh *b = arg;
	char *tree = morton_scratch_place(s, out, b->n, tree_size(b->n, b->collapse),
	                                  spare_nodes(b->n, b->collapse), &b->sort, b->threads, 3,
	                                  &b->count, &b->scratch_dirty);

	if (!tree)
		return -ENOMEM;
	place_tree(b, tree);
	b->nodes = out->nodes;
	b->prim_index = out->prim_index;
	return 0;
}

/* ---- build --------------------------------------------------------------- */

MORTON_PHASE_FN(lbvh, lbvh_karras)
MORTON_PHASE_FN(lbvh, lbvh_bounds)
MORTON_PHASE_FN(lbvh, lbvh_compact)

static const morton_phase phases[] = {
	{ "karras", lbvh_karras_phase }, { "bounds", lbvh_bounds_phase },
	{ "compact", lbvh_compact_phase }, { NULL, NULL },
};

MORTON_BUILD_FN(lbvh, .max_prims = UINT32_MAX / 2, .spare = spare_nodes(b.n, b.collapse),
                .place = scratch_alloc, .bucket_done = lbvh_bucket_done,
                .sorted = lbvh_sorted, .phases = phases)

PLUGIN_PARALLEL_BUILDER(options, BVHLAB_BUILDER_BOXES, .name = "lbvh",
	.summary = "parallel LBVH: Morton codes, radix sort, Karras 2012 emission, SAH collapse",
	.peak_bytes_per_prim = 100 /* measured 86-88 per triangle (issue 44) */)
