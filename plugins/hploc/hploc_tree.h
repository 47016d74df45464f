/*
 * What the CPU builder (hploc) and the device builder (cl_hploc) share on
 * the host: H-PLOC's own options, and the merge tree as both leave it
 * (cl_hploc downloads it) with its emission into the output (hploc_emit.c,
 * compiled into both plugins).
 *
 * A node of the merge tree is named by one word: HPLOC_LEAF | the
 * primitive's id for a primitive, else the slot of an inner record. Every
 * cluster has a representative, the sorted position of one of its
 * primitives; when clusters a (earlier in the order) and b merge, the
 * record of the merge goes to slot rep(b) and the merged cluster keeps
 * rep(a). Every position is given up at most once, so the n - 1 records
 * fill n slots with no counter, whatever order the merges happen in: the
 * slots depend on the merges alone, never on the threads.
 */
#ifndef BVHLAB_HPLOC_TREE_H
#define BVHLAB_HPLOC_TREE_H

#include <bvhlab/builder.h>

#include "hploc_merge.h" /* hploc_rec, HPLOC_LEAF */
#include "plugin_options.h"

/* The options of H-PLOC's merging, in a plugin's table (plugin_options.h),
 * into the members radius and threshold (uint32_t) of its struct `owner`;
 * the Morton and collapse ones are MORTON_OPTIONS. */
#define HPLOC_OPTIONS(owner)                                                                  \
	PLUGIN_OPTION(owner, radius, U32, .name = "radius",                                   \
	              .help = "search radius: clusters on either side, in a node's list, that " \
	                      "each cluster compares with",                                   \
	              .def_int = 8, .min = 1, .max = HPLOC_MAX_RADIUS),                       \
	PLUGIN_OPTION(owner, threshold, U32, .name = "threshold",                             \
	              .help = "most clusters a node carries upwards (half a 32-wide warp in " \
	                      "the paper); a node merges its children's down to it",          \
	              .def_int = 16, .min = 1, .max = HPLOC_MAX_THRESHOLD)

/* The merge tree of n >= 2 primitives, rooted at node word `root`. */
typedef struct hploc_tree {
	uint32_t n;
	const hploc_rec *rec;             /* [n] by slot */
	uint32_t root;
	const bvhlab_aabb *prim_bounds;   /* the primitives' boxes, for the leaves */
} hploc_tree;

/* A node of the merge tree and where it goes in the output. */
typedef struct hploc_place {
	uint32_t node;  /* its node word */
	uint32_t slot;  /* its output node */
	uint32_t kids;  /* the output slot of its children's pair */
	uint32_t first; /* its first prim_index slot */
} hploc_place;

/*
 * The tree into out (room for 2n - 1 nodes, n indices), collapse
 * applied: a node's children as a pair, the left child's subtree first.
 * By one thread: hploc_emit_top with cut 0. By a team: thread 0 runs
 * hploc_emit_top, which writes the nodes above the subtrees of at most
 * `cut` primitives and puts those subtrees' roots into tasks[] (room for
 * n), returning how many; after a barrier any thread writes any task with
 * hploc_emit_task. *count gets the output's node count.
 */
uint32_t hploc_emit_top(const hploc_tree *t, bvhlab_build_output *out, uint32_t cut,
                        hploc_place *tasks, uint32_t *count);
void hploc_emit_task(const hploc_tree *t, bvhlab_build_output *out, hploc_place task);

#endif /* BVHLAB_HPLOC_TREE_H */
