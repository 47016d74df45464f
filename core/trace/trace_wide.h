/*
 * The wide traversal's copy of a tree: the binary tree collapsed into
 * nodes of up to four children whose boxes sit side by side, one float
 * lane each, so one node visit tests four boxes with 4-wide vector
 * arithmetic and a ray descends about half as many levels as in the binary
 * tree. Subtrees of at most 8 triangles become one leaf whose triangles are
 * tested four at a time, as Embree's leaves of Triangle4 blocks are. The
 * boxes and triangles are the binary tree's own, so the hits are the same.
 */
#ifndef BVHLAB_CORE_TRACE_WIDE_H
#define BVHLAB_CORE_TRACE_WIDE_H

#include <stdint.h>

#include <bvhlab/scene.h>
#include <bvhlab/tree.h>

#define WIDE 4      /* children per wide node */
#define TRI_LANES 4 /* triangles per group */
#define WIDE_STACK 256 /* a ray's stack entries (at most 3 per wide level) */

/*
 * The layout at `lanes` lanes (4 here, 8 in trace_wide8.h), its types
 * named node_name, tris_name and bvh_name, so that trace_wide_body.h
 * serves both widths.
 *
 * node: 32 * lanes bytes. box[k] for k < 3 is the low bound on axis k,
 * box[3 + k] the high bound, for all lanes. A lane with count 0 is an
 * inner child (child: its node), 0 < count < WIDE_EMPTY a leaf (child: its
 * first group of bvh.tris, count its triangles), and count WIDE_EMPTY an
 * empty lane: its box is inverted, +inf to -inf, and the traversal masks
 * it out besides, since a ray with a NaN origin enters every box.
 *
 * tris: up to `tri_lanes` triangles of a leaf, one lane each (TRI_LANES
 * at either node width: see trace_wide8.h), so the sign test
 * of the triangle test runs on all at once: v[3 * j + k] is coordinate k
 * of vertex j. prim holds the primitive ids of the lanes. A leaf's
 * triangles take consecutive groups in slot order; lanes past the leaf's
 * count and ids outside the scene have NaN vertices, which no ray hits.
 *
 * bvh: nodes[0] is the root; depth counts wide levels on the longest
 * root-to-leaf path.
 */
#define WIDE_EMPTY UINT32_MAX

#define WIDE_LAYOUT(node_name, tris_name, bvh_name, lanes, tri_lanes) \
	struct node_name {                                            \
		float box[6][lanes];                                  \
		uint32_t child[lanes];                                \
		uint32_t count[lanes];                                \
	};                                                            \
	struct tris_name {                                            \
		float v[9][tri_lanes];                                \
		uint32_t prim[tri_lanes];                             \
	};                                                            \
	struct bvh_name {                                  \
		struct node_name *nodes;                   \
		struct tris_name *tris;                    \
		uint32_t node_count, tri_groups, depth;    \
	}

WIDE_LAYOUT(wide_node, wide_tris, wide_bvh, WIDE, TRI_LANES);

/*
 * Collapses tree into *w: each wide node takes a binary inner node's two
 * children and keeps opening the inner child of largest surface area until
 * it has four. 0; -EINVAL for links that leave the node array or reach a
 * node twice (validate first); -ENOMEM. (wide_bvh.c)
 */
int wide_bvh_init(struct wide_bvh *w, const bvhlab_tree *tree, const bvhlab_scene *scene);
void wide_bvh_finish(struct wide_bvh *w);

/*
 * A tree of width 3 to `lanes` (4 or 8) as built, without re-collapse:
 * nodes of `lanes` lanes and triangle groups of TRI_LANES, struct
 * wide_node and wide_tris for 4 (so a struct wide_bvh over them),
 * trace_wide8.h's for 8.
 * 0; -ERANGE when some node has more than `lanes` children; -EINVAL for
 * links that do not make a tree; -ENOMEM. (wide_built.c; the arrays are
 * freed with free())
 */
struct wide_built {
	void *nodes, *tris;
	uint32_t node_count, tri_groups, depth;
};
int wide_built_init(struct wide_built *out, const bvhlab_tree *tree, const bvhlab_scene *scene,
                    uint32_t lanes);

#endif
