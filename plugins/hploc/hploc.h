/*
 * hploc: H-PLOC, hierarchical parallel locally-ordered clustering
 * (Benthin, Meister, Barczak, Mohan, Hapala, Sopin, HPG 2024). The
 * primitives, in Morton order (plugins/common/morton, shared with lbvh and
 * ploc), are the leaves of the LBVH's radix tree, which is never built:
 * each leaf climbs it bottom-up as Apetrei (2014) does, deciding its
 * parent from the common prefixes with its range's two outer neighbours
 * (the range joins the side it shares more with); at each parent an
 * atomic exchange of the range's far end lets the first arrival stop and
 * the second go on with the whole range. There, the clusters its two
 * children carried up (each at most `threshold`) are merged by PLOC's
 * rounds (nearest neighbour within `radius` positions in the list,
 * distance the merged box's surface area, mutual nearest neighbours
 * merge) until at most `threshold` are left, or one at the root; the
 * survivors are carried upwards.
 *
 * What a node does depends only on its children's clusters, which depend
 * only on their subtrees; the records' slots come from the clusters'
 * representatives (hploc_tree.h). So the tree, node for node, is the same
 * for every thread count and every order of arrival, and cl_hploc, which
 * runs the same climb as one kernel launch, gives it too.
 *
 * Phases, run by a team (plugins/common/team) separated by barriers:
 *   1. sort    Morton codes and their sort; one cluster per primitive
 *              (hploc.c)
 *   2. climb   by blocks of leaves, a climb from each (hploc_climb.c)
 *   3. emit    the merge tree into the output: thread 0 the top, the team
 *              the subtrees below it (hploc_emit.c)
 *
 * Ties: as ploc's (ploc.h): among candidates at the same distance the
 * nearest in the list, then the pair whose earlier cluster is at an even
 * position, then the one before; the least pair is always mutual. The
 * merging itself is hploc_merge.h, shared with the device kernel.
 */
#ifndef BVHLAB_HPLOC_H
#define BVHLAB_HPLOC_H

#include <stdatomic.h>
#include <stdbool.h>
#include <stdint.h>

#include <bvhlab/builder.h>

#include "hploc_tree.h"
#include "morton.h"
#include "team.h"

#define HPLOC_NONE UINT32_MAX

typedef struct hploc {
	/* parameters */
	const bvhlab_build_input *in;
	uint32_t n;           /* primitives, >= 2 when the team runs */
	uint32_t threads;     /* threads asked for; team.threads may be fewer */
	uint32_t radius, threshold;
	bool collapse;
	uint32_t max_leaf;
	float c_trav, c_isect;
	hploc_params merge;   /* the above, for hploc_merge.h */
	bvhlab_build_output *out;

	morton_sort sort;
	hploc_cluster *cl;    /* [n] clusters by representative */
	hploc_rec *rec;       /* [n] the merge tree's records by slot */
	/* A range [L, R] that a climb has finished holds its clusters'
	 * representatives at idx[L ..], their count at count[L]. */
	uint32_t *idx, *count;
	atomic_uint *meet;    /* [n - 1] the far end of the first arrival at the
	                       * node split after position k; HPLOC_NONE before */
	uint32_t root;        /* node word of the root */
	hploc_place *tasks;   /* [n] the emit phase's subtrees, for the team */
	uint32_t task_count;
	uint32_t node_count;
	atomic_uint blocks;   /* blocks of leaves, then of tasks, handed out */
	team team;
	double phase_ms[4];   /* member 0's clock at the start and after each
	                       * phase (morton_job's ms) */
} hploc;

/* Emit tasks per thread: subtrees of at most n / (this x T) primitives,
 * so that a slow thread holds the others up by a small share (ploc's). */
#define HPLOC_EMIT_TASKS 32

void hploc_climb(hploc *h, unsigned t); /* hploc_climb.c */

#endif /* BVHLAB_HPLOC_H */
