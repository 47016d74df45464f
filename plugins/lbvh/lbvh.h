/*
 * lbvh: the parallel LBVH builder's shared state and phases.
 *
 * A build is a fixed sequence of phases run by a team of T threads (the
 * calling one included), separated by barriers, so every phase sees
 * everything the earlier ones wrote. The sort's passes over memory and the
 * compaction split their index ranges into T contiguous chunks (chunk());
 * the sort's buckets, Karras and bounds hand out blocks to whichever
 * thread is free (next_block()), since on a shared machine a thread can
 * lose its CPU for milliseconds. Nothing a
 * phase computes depends on T or on who did which block, so the tree, and
 * the order of its nodes, is the same for every thread count.
 *
 *   1. sort      Morton codes of the centroids, sorted as packed (code,
 *                primitive) words: one pass into buckets by the top code
 *                bits, then each bucket in cache; the ids into
 *                output->prim_index, and the common prefix lengths of
 *                neighbours in that order (lbvh_sort.c)
 *   2. karras    every internal node's range and split (lbvh_emit.c)
 *   3. bounds    bottom-up boxes and SAH collapse decisions (lbvh_emit.c)
 *   4. compact   with collapse: drop the nodes inside the new leaves
 *                (lbvh_collapse.c)
 *
 * Karras numbering: n sorted primitives (leaves 0..n-1) and n-1 internal
 * nodes 0..n-2. Internal node i covers the sorted range between i and
 * end[i] (either side); its children are split and split + 1, each a
 * leaf when it is the range's own end, else the internal node of that
 * index. The root is internal node 0 and covers everything.
 *
 * Output layout, built in place: the children of internal node i sit at
 * output slots 1 + 2i and 2 + 2i (adjacent by construction), the root at
 * slot 0. A node's own slot is therefore 1 + its parent word (2p + side).
 * Each node writes its own slot when its box is known: leaves at the start
 * of the bounds phase, internal nodes when both children are done. With
 * collapse, the pairs of the nodes that did not stay inner become holes
 * that the compaction fills (lbvh_collapse.c).
 */
#ifndef BVHLAB_LBVH_H
#define BVHLAB_LBVH_H

#include <pthread.h>
#include <stdatomic.h>
#include <stdbool.h>
#include <stdint.h>

#include <bvhlab/aabb.h>
#include <bvhlab/builder.h>

#include "morton.h"
#include "team.h"

#define NO_NODE UINT32_MAX
/* Zero bytes before and after lcp[], so that 16-byte scans never leave it. */
#define LCP_PAD 32

typedef struct lbvh {
	/* parameters */
	const bvhlab_build_input *in;
	uint32_t n;          /* primitives, >= 2 when the team runs */
	uint32_t threads;    /* threads asked for; the team (team.threads) may be smaller */
	bool collapse;
	uint32_t max_leaf;
	float c_trav, c_isect;

	/* output */
	bvhlab_node *nodes;
	uint32_t *prim_index;
	uint32_t node_count;  /* set by the last phase */

	/* sort (plugins/common/morton): its buffers in the output node array,
	 * which the bounds phase is the first to write (see lbvh.c), so the
	 * sorted words last through Karras. keys[0][k] holds the code of
	 * sorted position k from bit sort.base up, shifted above
	 * sort.id_bits of primitive id (base 0 when the whole code fits).
	 * sort.bits is the option `bits`. */
	morton_sort sort;

	/* hierarchy: past the tree in the output, or a fresh mapping */
	uint8_t *lcp;             /* [n - 1] 1 + common prefix length of sorted
	                           * keys k and k + 1; 0 at [-1], [n - 1] and in
	                           * the LCP_PAD bytes around */
	uint32_t *parent;         /* [2n - 1] parent word, 2 * parent + (1 if
	                           * right child), of internal node i at [i] and
	                           * of leaf k at [n - 1 + k]; NO_NODE at the root */
	uint32_t *end;            /* [n - 1] the other end of node i's range;
	                           * then the movers of the compaction */
	atomic_uint *visits;      /* [n - 1] arrivals at nodes shared by threads,
	                           * zeroed; then the holes */
	uint8_t *node_flags;      /* [n - 1] see lbvh_collapse.c */
	bool scratch_dirty;       /* visits and node_flags left from a build
	                           * before: the sort zeroes them */
	uint32_t *count;          /* [3 T] per-chunk counts for the compaction */
	atomic_uint blocks[2];    /* blocks handed out in karras and bounds */

	team team;                /* the threads (plugins/common/team) */
	double phase_ms[5];       /* member 0's clock at the start and after each
	                           * phase (morton_job's ms) */
} lbvh;

/* The [lo, hi) share of thread t of `count` items. */
static inline void chunk(const lbvh *b, unsigned t, uint32_t count, uint32_t *lo,
                         uint32_t *hi)
{
	team_chunk(b->team.threads, t, count, lo, hi);
}

/* Waits for the whole team: everything written before is visible after. */
static inline void lbvh_sync(lbvh *b)
{
	team_sync(&b->team);
}

/* The sorted range of internal node i: [range_first, + range_size). */
static inline uint32_t range_first(const lbvh *b, uint32_t i)
{
	return i < b->end[i] ? i : b->end[i];
}

static inline uint32_t range_size(const lbvh *b, uint32_t i)
{
	uint32_t end = b->end[i], first = i < end ? i : end;

	return (i ^ end ^ first) - first + 1;
}

/* The output slot of the node whose parent word is `word`. */
static inline bvhlab_node *slot_of(const lbvh *b, uint32_t word)
{
	return &b->nodes[word == NO_NODE ? 0 : 1 + (size_t)word];
}

/* The slots of internal node i's children (before any compaction). */
static inline bvhlab_node *kids_of(const lbvh *b, uint32_t i)
{
	return &b->nodes[1 + 2 * (size_t)i];
}

/* The index of the internal node whose slot this is, while the slot has
 * first = 1 + 2i (until the compaction). */
static inline uint32_t internal_index(const bvhlab_node *node)
{
	return (node->first - 1) / 2;
}

/* The sort phase's parts (morton_job's bucket_done and sorted), then the
 * phases, run by every thread t of the team; each ends with lbvh_sync
 * except the last, which the caller's join ends. */
void lbvh_bucket_done(void *arg, uint32_t first, uint32_t end); /* lbvh_sort.c */
void lbvh_sorted(void *arg, unsigned t);                         /* lbvh_sort.c */
void lbvh_karras(lbvh *b, unsigned t);    /* lbvh_emit.c */
void lbvh_bounds(lbvh *b, unsigned t);    /* lbvh_emit.c */
void lbvh_compact(lbvh *b, unsigned t);   /* lbvh_collapse.c */

/* The SAH decision for internal node i of `size` primitives whose box is
 * in its slot `out`, during the bounds phase (lbvh_collapse.c). */
void lbvh_collapse(lbvh *b, uint32_t i, uint32_t size, bvhlab_node *out);

#endif /* BVHLAB_LBVH_H */
