/*
 * treelet: a refinement stage (ABI 1.2 refine) that restructures small
 * treelets of a finished tree into their best shape, after Karras & Aila
 * 2013 ("Fast parallel construction of high-quality bounding volume
 * hierarchies"). Where reinsert moves one subtree at a time, this stage
 * tries every binary tree over up to `size` subtrees at once, so it finds
 * rearrangements that no single move reaches.
 *
 * Leaves. With `leaves` on (the default) every leaf of several primitives
 * is first split into one-primitive leaves (plugins/common/leaves), so the
 * primitives of the builder's leaves can be rearranged too; at the end the
 * tree is cut into leaves of at most max_leaf again by the SAH, and kept
 * only if its SAH fell.
 *
 * A round visits every inner node in post-order (children before their
 * parent). At node v it grows a treelet: v's two children to start with,
 * then, while fewer than `size`, the inner treelet leaf of largest surface
 * area is replaced by its two children. The treelet leaves are subtrees
 * whose contents stay as they are; what can change is the shape of the
 * treelet's inner nodes above them. A dynamic program over the subsets of
 * the leaves (treelet_opt.c) finds the shape of least cost, each subset's
 * subtree costed as it will be once the final cut has made leaves
 * (treelet_cost below: Karras & Aila's program with their leaf collapse).
 * When that is lower than today's cost, the treelet is rewritten in the
 * same slots: v keeps its slot and box, the freed pairs of slots take the
 * new inner nodes, and a leaf subtree moves by copying its root record
 * (its children stay where they are).
 *
 * The cost never rises: the other nodes keep their boxes and counts, and
 * the new inner boxes are the exact unions the program measured. The tree
 * stays in the standard layout with every pair adjacent.
 *
 * Threads. A treelet at v changes nothing outside v's subtree, so the tree
 * is cut into tasks, the subtrees of at most `task_nodes` nodes whose
 * parent's subtree is larger, handed out to the threads; the nodes above
 * them are then visited by one thread. The cut depends only on the tree,
 * so the result is the same for every thread count.
 */
#ifndef BVHLAB_TREELET_H
#define BVHLAB_TREELET_H

#include <stdatomic.h>
#include <stdbool.h>
#include <stdint.h>

#include <bvhlab/builder.h>

#include "team.h"

#define TREELET_MAX 8 /* most treelet leaves: 2^8 subsets in the program */

typedef struct treelet {
	bvhlab_node *nodes;
	uint32_t node_count;
	uint32_t size;       /* treelet leaves wanted, 3 .. TREELET_MAX */
	uint32_t max_leaf;   /* most primitives the final SAH cut puts in a leaf */
	double *cost;        /* [node_count] by slot: the subtree's SAH cost once cut (below);
	                      * an inner node's is valid once the round has visited it */
	uint32_t *prims;     /* [node_count] by slot: primitives below */
	uint32_t *order;     /* [node_count] inner nodes: tasks' post-orders, then the top's */
	uint32_t *task_end;  /* [tasks] end of each task's run in `order` */
	uint32_t tasks;      /* runs in `order` done in parallel; the rest by thread 0 */
	uint32_t top_begin, top_end; /* the top's run in `order` */
	atomic_uint next;    /* tasks handed out */
	_Atomic uint64_t changed; /* treelets rewritten this round */
	team team;
} treelet;

/*
 * The cost a subtree will have once the tree is cut into leaves by the
 * SAH (leaves.h): area * primitives for a leaf; for an inner node the
 * lesser of its area plus its children's costs and, when it has at most
 * max_leaf primitives, area * primitives (the cut may make it one leaf).
 * c_trav = c_isect = 1, in area units, as the reported metric.
 */
static inline double treelet_cost(double area, uint32_t prims, uint32_t max_leaf,
                                  double split)
{
	double leaf = area * prims;

	return prims <= max_leaf && leaf <= split ? leaf : split;
}

/*
 * Restructures the treelet rooted at inner node v if a shape of lower
 * cost (above) exists, keeping cost[] and prims[] up to date for the
 * slots it rewrites (treelet_opt.c): true when it rewrote it.
 */
bool treelet_optimise(treelet *t, uint32_t v);

/* Fills order, task_end, tasks and the top's run for the tree as it is
 * now, every node's prims and every leaf's cost; scratch has room for
 * 2 * node_count words (treelet_order.c). */
void treelet_plan(treelet *t, uint32_t task_nodes, uint32_t *scratch);

#endif /* BVHLAB_TREELET_H */
