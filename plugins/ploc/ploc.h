/*
 * ploc: Parallel Locally-Ordered Clustering (Meister & Bittner 2018). The
 * primitives, sorted along a Morton curve of their centroids (shared with
 * lbvh: plugins/common/morton), start as one cluster each; every iteration
 * each cluster finds the nearest of the `radius` clusters on either side
 * in that order (distance: the surface area of the merged box), mutual
 * nearest neighbours merge, and the survivors are compacted, still in
 * order, until one cluster is left.
 *
 * Phases, run by a team of T threads (plugins/common/team) separated by
 * barriers; nothing a phase computes depends on T or on who did which
 * block, so the tree, node for node, is the same for every thread count:
 *
 *   1. sort      Morton codes and their sort (plugins/common/morton); the
 *                first clusters, one per primitive (ploc.c)
 *   2. cluster   the iterations (ploc_cluster.c): nearest neighbours by
 *                blocks, then counts, prefix and writes by chunks
 *   3. emit      the SAH collapse, decided as clusters merge, applied top
 *                down into the output: thread 0 the top, the team the
 *                subtrees below it (ploc_emit.c)
 *
 * Ties: a cluster picks, among candidates at the same distance, the
 * nearest in the order, then the one whose pair starts at an even
 * position, then the one before it. That is one total order on candidate
 * pairs, so the globally least pair is always mutual (every iteration
 * merges at least once), and coincident boxes (all centroids equal) pair
 * up as (0 1) (2 3) ... instead of one pair per iteration.
 */
#ifndef BVHLAB_PLOC_H
#define BVHLAB_PLOC_H

#include <stdatomic.h>
#include <stdbool.h>
#include <stdint.h>

#include <bvhlab/builder.h>

#include "morton.h"
#include "team.h"

#define PLOC_MAX_RADIUS 64
/* Iterations over fewer clusters are run by thread 0 alone. */
#define PLOC_SOLO_BELOW 4096
/* Emit tasks per thread: subtrees of at most n / (this x T) primitives,
 * so that a slow thread holds the others up by a small share. */
#define PLOC_EMIT_TASKS 32
/* Record flags in the count field of the merge tree (below). */
#define REC_PRIM 0x80000000u      /* one primitive; first: its sorted position */
#define REC_COLLAPSED 0x40000000u /* the SAH made this subtree one leaf */
#define REC_PRIMS 0x3fffffffu     /* primitives below */
#define DEAD UINT32_MAX

/* What a merge reads of a cluster besides its box: one 16-byte record, so
 * that compacting the clusters streams seven arrays, not ten. */
struct cluster_meta {
	uint32_t first; /* the record's first (see `tree`) */
	uint32_t info;  /* the record's count field: REC_* | primitives */
	float cost;     /* the subtree's SAH cost, area-weighted */
	uint32_t desc;  /* output nodes below the cluster's own */
};

/* Clusters of one iteration, by position in the Morton order. */
struct clusters {
	float *lo[3], *hi[3];      /* [n] boxes, by axis, for vector distance rows */
	struct cluster_meta *meta; /* [n] */
};

/* A record of the merge tree and where it goes in the output (emit). */
struct place {
	uint32_t x;     /* the record */
	uint32_t slot;  /* its output node */
	uint32_t kids;  /* output slot of its children's pair */
	uint32_t first; /* first prim_index slot of its primitives */
};

typedef struct ploc {
	/* parameters */
	const bvhlab_build_input *in;
	uint32_t n;           /* primitives, >= 2 when the team runs */
	uint32_t threads;     /* threads asked for; team.threads may be fewer */
	uint32_t radius;
	bool collapse;
	uint32_t max_leaf;
	float c_trav, c_isect;

	/* output */
	bvhlab_node *nodes;
	uint32_t *prim_index;
	uint32_t node_count;

	morton_sort sort;
	struct clusters cl[2];  /* this iteration's and the next one's */
	uint32_t *nn;           /* [n] nearest neighbour of each cluster */
	/*
	 * The merge tree, 2n - 1 records in the output's node layout: the
	 * root at 0, the two clusters of every merge as a pair, allocated
	 * downwards from the end, so children always lie above their parent
	 * and each iteration's pairs form one range. first: the pair of an
	 * inner record, the sorted position of a primitive.
	 */
	bvhlab_node *tree;
	uint32_t *desc;         /* [2n - 1] output nodes below each record */
	struct place *tasks;    /* [n] the emit phase's subtrees, for the team */
	uint32_t task_count;
	uint32_t emit_cut;      /* most primitives of a task's subtree */
	uint32_t iterations;
	uint32_t *count;        /* [2 T] per-chunk counts of merges, survivors */
	atomic_uint blocks[2];  /* blocks handed out, by iteration parity */
	team team;
	double phase_ms[4];     /* member 0's clock at the start and after each
	                         * phase (morton_job's ms) */
} ploc;

static inline float half_area3(float dx, float dy, float dz)
{
	return dx * dy + dy * dz + dz * dx;
}

void ploc_cluster(ploc *p, unsigned t); /* ploc_cluster.c */
void ploc_emit(ploc *p, unsigned t);    /* ploc_emit.c */

#endif /* BVHLAB_PLOC_H */
