/* cl_ploc: one build's state, its device run and the host emission (see
 * cl_ploc.c). */
#ifndef BVHLAB_CL_PLOC_H
#define BVHLAB_CL_PLOC_H

#include <stdbool.h>
#include <stdint.h>

#include "cl_dev.h"

#define CL_PLOC_MAX_RADIUS 64 /* ploc's PLOC_MAX_RADIUS */
#define CL_PLOC_MAX_NN_BLOCK 256 /* cl_ploc.cl's NN_BLOCK_MAX */
/* Record flags in the count field of the merge tree (ploc.h's). */
#define REC_PRIM 0x80000000u
#define REC_COLLAPSED 0x40000000u
#define REC_PRIMS 0x3fffffffu
/* Bytes of a cluster on the device (cl_ploc.cl's struct cluster). */
#define CLUSTER_BYTES 40

/* The device buffers besides the sort's. */
enum { PB_BOUNDS, PB_CL0, PB_CL1, PB_NN, PB_COUNTS, PB_STATE, PB_TREE, PB_DESC, PB_COUNT };

typedef struct cl_ploc {
	const bvhlab_build_input *in;
	uint32_t n;
	const char *device;
	unsigned bits;
	uint32_t radius;
	uint32_t nn_block;      /* clusters per work-item of nearest; 0: by device */
	bool collapse;
	uint32_t max_leaf;
	float c_trav, c_isect;

	cl_dev *dev;
	cl_sort *sort;
	cl_buf *b;              /* [PB_COUNT] */
	bvhlab_node *tree;      /* [2n - 1] the merge tree's records, downloaded */
	uint32_t *desc;         /* [2n - 1] output nodes below each record */
	uint32_t iterations;
	double ms[CL_PHASES];   /* upload, device, download, convert */
} cl_ploc;

/* Builds the merge tree of n >= 2 primitives into b->tree and b->desc
 * (host memory the caller sized): 0, or a negative errno with the message
 * in err. */
int cl_ploc_run(cl_ploc *b, char *err, size_t err_size);

/* The merge tree into out as ploc_emit.c lays it out, collapse applied;
 * returns the node count. */
uint32_t cl_ploc_emit(const cl_ploc *b, bvhlab_build_output *out);

#endif /* BVHLAB_CL_PLOC_H */
