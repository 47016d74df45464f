/* hlbvh's steps 2 to 5 (see hlbvh.h); the plugin's frame is hlbvh.c. */
#include <errno.h>
#include <math.h>
#include <stdlib.h>
#include <string.h>

#include <bvhlab/aabb.h>

#include "hlbvh.h"
#include "sah_nodes.h"
#include "sah_simd.h"
#include "sah_split.h"

/* Clusters a member takes at a time in the gather and the bottom. */
#define CLUSTER_BLOCK 64

/* Ranges waiting in the cut: one per level of the cut at most, and a
 * level halves either the code bits (63) or a range of equal codes
 * (32 halvings at most). */
#define CUT_STACK 128

/* The code bits of sorted position k (those the packed word keeps). */
static inline uint64_t code_at(const hlbvh *h, uint32_t k)
{
	return h->sort.keys[0][k] >> h->sort.id_bits;
}

/* The first position in (lo, hi) whose code has `bit` set; the codes of
 * the range agree above it, so those without it come first. */
static uint32_t first_with_bit(const hlbvh *h, uint32_t lo, uint32_t hi, unsigned bit)
{
	while (hi - lo > 1) {
		uint32_t mid = lo + (hi - lo) / 2;
		if ((code_at(h, mid) >> bit) & 1)
			hi = mid;
		else
			lo = mid;
	}
	return hi;
}

/* Where range [lo, hi) splits: at its highest differing code bit, or in
 * the middle when every code is equal. */
static uint32_t cut_at(const hlbvh *h, uint32_t lo, uint32_t hi)
{
	uint64_t diff = code_at(h, lo) ^ code_at(h, hi - 1);

	if (!diff)
		return lo + (hi - lo) / 2;
	return first_with_bit(h, lo, hi - 1, 63u - (unsigned)__builtin_clzll(diff));
}

void hlbvh_cut(hlbvh *h)
{
	uint32_t stack[CUT_STACK][2], sp = 0, count = 0;

	stack[sp][0] = 0;
	stack[sp++][1] = h->n;
	while (sp > 0) {
		uint32_t lo = stack[--sp][0], hi = stack[sp][1];
		if (hi - lo <= h->cluster) {
			h->bounds[count++] = lo;
			continue;
		}
		uint32_t mid = cut_at(h, lo, hi);
		/* Right first, so the left is cut next: clusters come in order. */
		stack[sp][0] = mid;
		stack[sp++][1] = hi;
		stack[sp][0] = lo;
		stack[sp++][1] = mid;
	}
	h->bounds[count] = h->n;
	h->cluster_count = count;
}

/* Boxes read ahead of the gather (ploc's reason: Morton order scatters
 * the reads over the input, which no hardware prefetcher follows). */
#define GATHER_AHEAD 16

static void gather_cluster(hlbvh *h, uint32_t c)
{
	const bvhlab_aabb *pb = h->in->prim_bounds;
	uint32_t end = h->bounds[c + 1];
	v4 lo = v4_set1(INFINITY), hi = v4_set1(-INFINITY);

	for (uint32_t k = h->bounds[c]; k < end; k++) {
		uint32_t id = morton_id(&h->sort, k);
		sah_prim *p = &h->sorted[k];

		if (k + GATHER_AHEAD < h->n)
			__builtin_prefetch(&pb[morton_id(&h->sort, k + GATHER_AHEAD)]);
		memcpy(p->lo, pb[id].lo, sizeof(p->lo));
		memcpy(p->hi, pb[id].hi, sizeof(p->hi));
		p->id = id;
		p->pad = 0;
		lo = v4_min(lo, v4_load3(p->lo));
		hi = v4_max(hi, v4_load3(p->hi));
	}
	v4_store3(h->cbox[c].lo, lo);
	v4_store3(h->cbox[c].hi, hi);
	for (int a = 0; a < 3; a++)
		h->ccen[3 * c + a] = 0.5f * (h->cbox[c].lo[a] + h->cbox[c].hi[a]);
}

void hlbvh_gather(hlbvh *h, unsigned t)
{
	uint32_t lo, hi;

	(void)t;
	while (team_next_block(&h->next, h->cluster_count, CLUSTER_BLOCK, &lo, &hi))
		for (uint32_t c = lo; c < hi; c++)
			gather_cluster(h, c);
}

/* The clusters as the top's primitives: their boxes, centres and bounds. */
static void top_input(const hlbvh *h, bvhlab_build_input *in)
{
	memset(in, 0, sizeof(*in));
	in->struct_size = sizeof(*in);
	in->prim_count = h->cluster_count;
	in->prim_bounds = h->cbox;
	in->centroids = h->ccen;
	in->threads = 1;
	in->bounds = h->in->bounds;
	bvhlab_aabb_empty(&in->centroid_bounds);
	for (uint32_t c = 0; c < h->cluster_count; c++)
		bvhlab_aabb_grow_point(&in->centroid_bounds, &h->ccen[3 * c]);
}

/* The bottom's builder: the kernel over the sorted records, its node
 * counter past the top's nodes. */
static void bottom_init(hlbvh *h, uint32_t top_nodes)
{
	sah_builder *b = &h->bottom;

	memset(b, 0, sizeof(*b));
	b->opt = h->sah;
	/* The small builders sort a cluster themselves; sweep's would read
	 * presorted arrays this builder does not keep. */
	b->opt.method = SAH_BINNED;
	b->th = h->th;
	b->prim_count = h->n;
	b->root_box = h->in->bounds;
	b->nodes = h->out->nodes;
	b->ids = h->out->prim_index;
	b->prims[0] = h->sorted;
	atomic_init(&b->node_counter, top_nodes);
}

int hlbvh_top(hlbvh *h)
{
	uint32_t cc = h->cluster_count, *ids = malloc(cc * sizeof(*ids));
	/* Exactly the top's nodes: past them lie the bottom's slots and the
	 * sorted records, not room for the top builder's arrays. */
	bvhlab_build_output out = { .struct_size = sizeof(out), .nodes = h->out->nodes,
	                            .node_capacity = 2 * cc - 1,
	                            .prim_index = ids, .index_capacity = cc };
	sah_options opt = h->sah;
	bvhlab_build_input in;
	sah_builder top;
	sah_job root;
	int rc;

	if (!ids)
		return -ENOMEM;
	top_input(h, &in);
	opt.max_leaf = 1; /* every top leaf one cluster, whose slot it becomes */
	if ((rc = sah_builder_init(&top, &opt, &in, &out, h->th)) < 0)
		goto out;
	sah_builder_root(&top, &root);
	sah_build_subtree(&top, &root);
	sah_builder_finish(&top, &out);
	for (uint32_t s = 0; s < out.node_count; s++)
		if (h->out->nodes[s].count)
			h->slot[ids[h->out->nodes[s].first]] = s;
	bottom_init(h, out.node_count);
	sah_builder_free(&top);
out:
	free(ids);
	return rc;
}

/* Nodes of a cluster's subtree: 2 * SAH_SMALL_MAX - 1 at most. */
#define CLUSTER_NODES (2 * SAH_SMALL_MAX)

void hlbvh_bottom(hlbvh *h, unsigned t)
{
	bvhlab_node scratch[CLUSTER_NODES];
	sah_builder local;
	uint32_t lo, hi;

	(void)t;
	memcpy(&local, &h->bottom, sizeof(local));
	local.nodes = scratch;
	while (team_next_block(&h->next, h->cluster_count, CLUSTER_BLOCK, &lo, &hi)) {
		for (uint32_t c = lo; c < hi; c++) {
			sah_job job = { .node = 0, .begin = h->bounds[c], .end = h->bounds[c + 1],
			                .box = h->cbox[c], .cbox = h->cbox[c] };
			atomic_init(&local.node_counter, 1);
			sah_build_subtree(&local, &job);
			sah_place_scratch(&h->bottom, h->slot[c], scratch,
			                  atomic_load_explicit(&local.node_counter,
			                                       memory_order_relaxed));
		}
	}
}
