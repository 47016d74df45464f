/*
 * embree plugin internals: Embree's rtcBuildBVH builds a temporary binary
 * tree through callbacks (embree_tree.c), which is then written out in the
 * standard layout.
 */
#ifndef BVHLAB_EMBREE_INTERNAL_H
#define BVHLAB_EMBREE_INTERNAL_H

#include <embree3/rtcore.h>

#include <bvhlab/builder.h>

/*
 * A node of the temporary tree, allocated in Embree's thread-local arena
 * (freed all at once with the RTCBVH). count 0: inner node with `arity`
 * children, up to the build's branching factor (the `width` option: 2, or
 * Embree's own 4- and 8-wide trees); Embree may emit one-child nodes,
 * which are skipped on output;
 * count > 0: leaf whose primitive ids follow the header.
 */
typedef struct tnode {
	uint32_t count;
	uint32_t arity;
} tnode;

typedef struct tinner {
	tnode head;
	tnode *child[BVHLAB_MAX_WIDTH];
} tinner;

typedef struct tleaf {
	tnode head;
	float lo[3], hi[3]; /* union of Embree's boxes of its references (clipped
	                     * to the part of the triangle in the leaf for "high") */
	uint32_t prim[];    /* [head.count] */
} tleaf;

/* What the callbacks see through Embree's userPtr. */
typedef struct embree_job {
	const bvhlab_build_input *input;
} embree_job;

/* Sets the callbacks (and splitPrimitive when `spatial`) in args. */
void embree_set_callbacks(struct RTCBuildArguments *args, bool spatial);

/*
 * Writes the tree under `root` into `out` (growing it through the host
 * when spatial splits made more references than primitives): leaf boxes
 * as Embree gave them, inner boxes the union of their children's, an
 * inner node of k > 2 children marked BVHLAB_NODE_INNER | k (ABI 1.5; the
 * caller sets out->width). 0, or a negative errno after host->set_error.
 */
int embree_write_tree(const bvhlab_host *host, bvhlab_build_ctx *ctx, const tnode *root,
                      bvhlab_build_output *out);

#endif
