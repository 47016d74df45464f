/*
 * cl_ploc: PLOC (Meister & Bittner 2018) on an OpenCL device, the tree of
 * the CPU ploc plugin for the same options. Morton codes and their sort
 * (plugins/common/cl), then the iterations on the device: every cluster's
 * nearest neighbour within `radius` positions in Morton order, mutual
 * pairs merge, the survivors are compacted in order, until one cluster is
 * left (cl_ploc.cl, cl_ploc_run.c). The merge tree goes into the output
 * on the host, as ploc_emit.c lays it out (cl_ploc_emit.c).
 *
 * Phases reported: upload, device (the kernels' own times, from their
 * events), download, convert (the emission), as cl_lbvh's.
 */
#include <errno.h>
#include <stdlib.h>
#include <string.h>

#include "cl_dev.h"
#include "cl_ploc.h"
#include "cl_ploc_src.h"
#include "morton_front.h"
#include "plugin_options.h"

static const plugin_option options[] = {
	PLUGIN_OPTION(cl_ploc, radius, U32, .name = "radius",
	              .help = "search radius: clusters on either side, in Morton order, that "
	                      "each cluster compares with",
	              .def_int = 16, .min = 1, .max = CL_PLOC_MAX_RADIUS),
	MORTON_OPTIONS(cl_ploc, bits),
	CL_DEVICE_OPTION(cl_ploc),
	PLUGIN_OPTION(cl_ploc, nn_block, U32, .name = "nn_block",
	              .help = "clusters per work-item of the nearest-neighbour search (0: 256 "
	                      "on a CPU device, 1 on a GPU); the tree is the same for every value",
	              .def_int = 0, .min = 0, .max = CL_PLOC_MAX_NN_BLOCK),
};
CL_DEVICE_CHECK(cl_ploc)
PLUGIN_DECLS(options, cl_ploc, cl_device_check)

static const char *const kernel_names[] = {
	CL_SORT_KERNEL_NAMES, "first_clusters", "nearest", "count_chunks", "prefix",
	"write_chunks", "nearest_blocks",
};

static const cl_builder program = CL_BUILDER(cl_ploc_src, kernel_names, REC_PRIMS);

/* Kept between builds (one build at a time, ABI rule), with the host's
 * copy of the merge tree; released when the plugin is unloaded. */
static struct {
	CL_KEPT(PB_COUNT);
	bvhlab_node *tree;
	uint32_t *desc;
	uint32_t cap;
} S;

__attribute__((destructor)) static void release_device(void)
{
	CL_KEPT_FREE(S, PB_COUNT);
	free(S.tree);
	free(S.desc);
}

/* The host's copy of the merge tree, kept between builds. */
static int host_tree(cl_ploc *b)
{
	size_t records = 2 * (size_t)b->n - 1;

	if (S.cap < b->n) {
		free(S.tree);
		free(S.desc);
		S.tree = malloc(records * sizeof(*S.tree));
		S.desc = malloc(records * sizeof(*S.desc));
		S.cap = S.tree && S.desc ? b->n : 0;
		if (!S.cap)
			return -ENOMEM;
	}
	b->tree = S.tree;
	b->desc = S.desc;
	return 0;
}

static int run(void *p, bvhlab_build_output *out, char *err, size_t err_size)
{
	cl_ploc *b = p;
	double t0;
	int rc;

	if (host_tree(b) < 0)
		return bvhlab_cl_fail(-ENOMEM, err, err_size,
		                      "out of memory for the merge tree of %u primitives", b->n);
	if ((rc = cl_ploc_run(b, err, err_size)) < 0)
		return rc;
	t0 = cl_now_ms();
	out->node_count = cl_ploc_emit(b, out);
	out->index_count = b->n;
	b->ms[CL_PHASE_CONVERT] = cl_now_ms() - t0;
	return 0;
}

CL_PLUGIN(cl_ploc, run, .name = "cl_ploc",
	.summary = "PLOC on an OpenCL device (Meister & Bittner 2018): the ploc plugin's tree, "
	           "built by kernels")
