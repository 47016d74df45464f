/*
 * The compressed 8-wide layout (cwbvh_node.h) of a tree, for the device
 * traversal {"name": "wide8", "device": true} (trace_cl.c).
 *
 * A tree of width 5 to 8 is encoded as built: one node per inner node.
 * A narrower one (binary, 3 or 4) is first collapsed greedily to 8 wide,
 * as Embree and tinybvh do: a node's child of largest surface area that
 * is inner is opened while its children still fit in the 8 slots. A leaf
 * root becomes one node with that leaf as its only child.
 */
#ifndef BVHLAB_CWBVH_H
#define BVHLAB_CWBVH_H

#include <stdint.h>

#include <bvhlab/tree.h>

#include "trace/cwbvh_node.h"

struct cwbvh {
	cw_node *nodes;         /* [node_count], the root first */
	uint32_t node_count;
	uint32_t (*leaves)[2];  /* [leaf_count] (first, count) into prim_index */
	uint32_t leaf_count;
	uint32_t *source;       /* [node_count] the tree node each was made from */
	uint32_t depth;         /* inner levels below the root: the kernel's stack need */
};

/* 0; -EINVAL (err says why) for links that leave the node array, a node
 * wider than 8, a cycle, or a box that is not finite; -ENOMEM. An empty
 * tree gives no nodes. */
int cwbvh_encode(const bvhlab_tree *tree, struct cwbvh *out, bvhlab_error *err);
void cwbvh_free(struct cwbvh *c);

/* The compressed layout's bytes: 80 a node, 8 a leaf range (prim_index
 * and the triangles not counted: they are the tree's and the scene's). */
uint64_t cwbvh_bytes(const struct cwbvh *c);

#endif
