/* cl_lbvh: one build's state and its device run (see cl_lbvh.c). */
#ifndef BVHLAB_CL_LBVH_H
#define BVHLAB_CL_LBVH_H

#include <stdbool.h>
#include <stdint.h>

#include "cl_dev.h"

/* The device buffers besides the sort's. */
enum { LB_BOUNDS, LB_PARENT, LB_END, LB_NODES, LB_VISITS, LB_COST, LB_FLAGS, LB_INDEX,
       LB_INNER, LB_LCP, LB_PLAN, LB_COUNT };

/* The kernels, after the sort's (cl_lbvh.c's names, in this order). */
enum { K_KARRAS = CL_SORT_KERNELS, K_BOUNDS, K_INNER, K_PREFIXES, K_SCAN, K_COUNTS, K_PLAN,
       K_MOVERS, K_LINKS, K_MOVES };

/* The most chunks of the compaction; LB_PLAN holds 3 words a chunk and F. */
#define CL_LBVH_CHUNKS 512u

typedef struct cl_lbvh {
	const bvhlab_build_input *in;
	uint32_t n;
	const char *device;
	unsigned bits;
	bool collapse;
	uint32_t max_leaf;
	float c_trav, c_isect;
	uint32_t leaf_block;  /* leaves per work-item in bounds; 0: by device */
	const char *hierarchy; /* auto, search or scan */
	const char *sort_shape; /* option sort: auto, passes or buckets */
	bool zero_copy;         /* the host's arrays on a CPU device (host[]) */

	cl_dev *dev;
	cl_sort *sort;
	cl_buf *b;           /* [LB_COUNT] */
	/* On a CPU device, this build's buffers over the host's arrays
	 * (CL_MEM_USE_HOST_PTR) in place of b[]'s: the input's boxes, the
	 * output's nodes and indices, the input's centroids; else NULL. */
	cl_mem host[LB_COUNT], centroids;
	double ms[CL_PHASES]; /* upload, device, download, convert */
	size_t plan_f;        /* where F lies in LB_PLAN, in bytes */
} cl_lbvh;

/* Builds the tree of n >= 2 primitives into out (room for 2n - 1 nodes and
 * n indices): 0, or a negative errno with the message in err. */
int cl_lbvh_run(cl_lbvh *b, bvhlab_build_output *out, char *err, size_t err_size);

/* Queues the compaction of the collapsed tree (cl_lbvh_compact.cl) after
 * inner_nodes; F is then at b->plan_f in LB_PLAN. 0 or a negative errno. */
int cl_lbvh_compact(cl_lbvh *b, cl_events *ev, char *err, size_t err_size);

#endif /* BVHLAB_CL_LBVH_H */
