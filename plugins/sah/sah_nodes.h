/*
 * Node writing and the leaf rule, shared by every split search (sweep,
 * binned, small subtrees): one place decides when a node is a leaf and how
 * its slot and children are written. Implemented by sah_nodes.c.
 */
#ifndef BVHLAB_SAH_NODES_H
#define BVHLAB_SAH_NODES_H

#include <stdbool.h>

#include "sah_types.h"

/* Writes job's node as a leaf over its whole range. */
void sah_write_leaf(sah_builder *b, const sah_job *job);

/*
 * Writes job's node as an inner node, allocates its two children and sets
 * their node, range [begin, mid) / [mid, end) and depth; boxes are the
 * caller's to fill.
 */
void sah_write_inner(sah_builder *b, const sah_job *job, uint32_t mid, sah_job child[2]);

/*
 * Writes nodes[node] as an inner node with box and allocates its two
 * adjacent children; their first slot goes to *first.
 */
void sah_write_node(sah_builder *b, uint32_t node, const bvhlab_aabb *box, uint32_t *first);

/*
 * Copies a subtree built into scratch (slot 0 its root, then its nodes in
 * allocation order, `used` of them) into the tree: the root into slot
 * `root`, the others into one range claimed from the node counter, child
 * links moved with them. Pairs stay adjacent, and with one thread the
 * slots are those the shared counter would have handed out.
 */
void sah_place_scratch(sah_builder *b, uint32_t root, const bvhlab_node *scratch, uint32_t used);

/*
 * The leaf rule for a node of n primitives with box, given `found` (a
 * candidate split exists) and its best weighted area sum A_L*N_L + A_R*N_R.
 */
bool sah_leaf_rule(const sah_options *opt, uint32_t n, const bvhlab_aabb *box, bool found,
                   float best);

/*
 * The leaf rule: true when job should become a leaf given `found` (a
 * candidate split exists) and its best weighted area sum
 * A_L * N_L + A_R * N_R. The caller handles N == 1 and the median fallback.
 */
bool sah_prefer_leaf(const sah_builder *b, const sah_job *job, bool found, float best);

#endif /* BVHLAB_SAH_NODES_H */
