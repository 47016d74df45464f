/*
 * hlbvh: SAH over Morton clusters (the hierarchical LBVH of Pantaleoni &
 * Luebke 2010 with the SAH top of Garanzha et al. 2011), built from the
 * SAH family's parts:
 *
 *   1. sort    the primitives along the Morton curve of their centroids
 *              (plugins/common/morton, lbvh's and ploc's sort);
 *   2. cluster cut the sorted order at the highest differing code bit
 *              until every range holds at most `cluster` primitives: each
 *              cluster is a cell of the Morton grid, spatially compact;
 *   3. gather  the primitives' records in sorted order and every
 *              cluster's box (by the team, blocks of clusters);
 *   4. top     the SAH kernel over the clusters' boxes as primitives,
 *              down to single clusters (max_leaf 1), on one thread: a few
 *              tens of thousands of items for a million triangles;
 *   5. bottom  each cluster built whole by the kernel's small-subtree
 *              builder (exact SAH over at most 64 primitives) into the
 *              slot its top leaf left, by the team, clusters handed out in
 *              blocks.
 *
 * Why: a binned SAH build spends most of its time splitting and
 * scattering the top of the tree, the part where Morton order is a good
 * guess already, and LBVH's trees are poor exactly where SAH matters, at
 * the top. Here the top's SAH works on clusters instead of triangles and
 * nothing is scattered; every primitive is gathered once.
 *
 * Determinism: the sort orders by (code, id), the cuts depend on the codes
 * only, and the top and each cluster are the kernel's deterministic
 * builds; which thread builds a cluster changes only where its nodes sit
 * in the array, so the tree is the same for every thread count.
 */
#ifndef BVHLAB_HLBVH_H
#define BVHLAB_HLBVH_H

#include <stdatomic.h>
#include <stdint.h>

#include <bvhlab/builder.h>

#include "morton.h"
#include "sah_kernel.h"
#include "team.h"

/* The build's state, its options first (filled by the host, as lbvh's):
 * the kernel's (method and bins steer the top's search, quality the
 * clusters'), then the cluster size. */
typedef struct hlbvh {
	sah_options sah;
	uint32_t cluster;        /* most primitives in a cluster, 2 .. SAH_SMALL_MAX */

	const bvhlab_build_input *in;
	bvhlab_build_output *out;
	const team_host *th;     /* morton_job's th */
	uint32_t n;              /* primitives, >= 2 when the team runs */
	uint32_t threads;        /* threads asked for (morton_job's) */
	uint32_t node_count;     /* the bottom's node counter, after the team */
	team team;
	morton_sort sort;        /* 63 code bits */
	sah_prim *sorted;        /* [n] the primitives' records in sorted order */
	uint32_t *bounds;        /* [n + 1] cluster c is [bounds[c], bounds[c + 1]) */
	uint32_t cluster_count;
	bvhlab_aabb *cbox;       /* [cluster_count] each cluster's box */
	float *ccen;             /* [3 cluster_count] their centres */
	uint32_t *slot;          /* [cluster_count] the node each cluster fills */
	sah_builder bottom;      /* the clusters' builds: prims[0] = sorted */
	atomic_uint next;        /* blocks of clusters handed out */
	int rc;                  /* member 0's result of the cut and the top */
	double phase_ms[6];      /* morton_job's ms: start, sort, 4 phases */
} hlbvh;

/* Step 2, by member 0 after the sort: h->bounds and h->cluster_count. */
void hlbvh_cut(hlbvh *h);

/* Step 3 by member t of the team (blocks of clusters from h->next). */
void hlbvh_gather(hlbvh *h, unsigned t);

/* Step 4 by member 0: the top tree in the output's first nodes, h->slot,
 * and h->bottom ready. 0, or a negative errno (out of memory). */
int hlbvh_top(hlbvh *h);

/* Step 5 by every member (blocks of clusters from h->next). */
void hlbvh_bottom(hlbvh *h, unsigned t);

#endif /* BVHLAB_HLBVH_H */
