/*
 * cl_lbvh: LBVH on an OpenCL device (Karras 2012), the tree of the CPU
 * lbvh plugin for the same options, bit for bit. Morton codes and a stable
 * LSD radix sort (plugins/common/cl), Karras's hierarchy in one kernel,
 * boxes and the SAH collapse bottom-up with atomic counters, then which
 * nodes stay inner (cl_lbvh.cl), and the compaction of the collapsed tree,
 * as lbvh_collapse.c's (cl_lbvh_compact.cl).
 *
 * Phases reported: upload (boxes and centroids, wall clock), device (the
 * kernels' and fills' own times, from their events), download (wall
 * clock) and convert (0: nothing is left to the host).
 */
#include <errno.h>
#include <stdlib.h>
#include <string.h>

#include "cl_dev.h"
#include "cl_lbvh.h"
#include "cl_lbvh_src.h"
#include "morton_front.h"
#include "plugin_options.h"

static const plugin_option options[] = {
	MORTON_OPTIONS(cl_lbvh, bits),
	CL_DEVICE_OPTION(cl_lbvh),
	PLUGIN_OPTION(cl_lbvh, leaf_block, U32, .name = "leaf_block",
	              .help = "leaves per work-item of the bounds kernel (0: 512 on a CPU "
	                      "device, 1 on a GPU); the tree is the same for every value",
	              .def_int = 0, .min = 0, .max = 1 << 20),
	CL_SHAPE_OPTION(cl_lbvh, hierarchy, "hierarchy",
	                "how each node's range and split are found: search (Karras's "
	                "searches), scan (lbvh's prefix scans), auto (scan on a CPU device, "
	                "search on a GPU)", "search|scan"),
	CL_SHAPE_OPTION(cl_lbvh, sort_shape, "sort",
	                "the radix sort's shape: passes (every digit over all keys), buckets "
	                "(the two top digits over all keys, then a work-item per bucket), auto "
	                "(buckets on a CPU device, passes on a GPU)", "passes|buckets"),
	PLUGIN_OPTION(cl_lbvh, zero_copy, BOOL, .name = "zero_copy",
	              .help = "on a CPU device, the input's and the output's arrays used where "
	                      "they lie (CL_MEM_USE_HOST_PTR) instead of copied in and out; "
	                      "no effect on a GPU",
	              .def_bool = true),
};
CL_DEVICE_CHECK(cl_lbvh)
PLUGIN_DECLS(options, cl_lbvh, cl_device_check)

static const char *const kernel_names[] = {
	CL_SORT_KERNEL_NAMES, "karras", "bounds", "inner_nodes", "prefixes", "karras_scan",
	"compact_counts", "compact_plan", "compact_movers", "compact_links", "compact_moves",
};

static const cl_builder program = CL_BUILDER(cl_lbvh_src, kernel_names, UINT32_MAX / 2);

/* Kept between builds (one build at a time, ABI rule); released when the
 * plugin is unloaded. */
static struct {
	CL_KEPT(LB_COUNT);
} S;

__attribute__((destructor)) static void release_device(void)
{
	CL_KEPT_FREE(S, LB_COUNT);
}

static int build(const bvhlab_host *host, bvhlab_build_ctx *ctx,
                 const bvhlab_build_input *input, bvhlab_build_output *output)
{
	cl_lbvh b;
	char err[BVHLAB_CL_ERROR_SIZE];
	int rc;

	/* The options first: their copy sets the whole struct. */
	rc = PLUGIN_OPTIONS_GET(host, ctx, input, &b);
	b.in = input, b.n = input->prim_count, b.dev = &S.dev, b.sort = &S.sort, b.b = S.b;
	if (rc < 0 || (rc = cl_build_begin(&program, &S.dev, b.device, host, ctx, input,
	                                   output)) != 0)
		return rc < 0 ? rc : 0;
	S.sort.shape = !strcmp(b.sort_shape, "passes")    ? CL_SORT_PASSES
	               : !strcmp(b.sort_shape, "buckets") ? CL_SORT_BUCKETS
	                                            : CL_SORT_AUTO;
	if ((rc = cl_lbvh_run(&b, output, err, sizeof(err))) < 0) {
		host->set_error(ctx, "%s", err);
		return rc;
	}
	cl_report_phases(host, ctx, b.ms);
	return 0;
}

PLUGIN_WITH_OPTIONS(options, .name = "cl_lbvh",
	.flags = BVHLAB_BUILDER_DETERMINISTIC | BVHLAB_BUILDER_DEVICE,
	.summary = "LBVH on an OpenCL device (Karras 2012): the lbvh plugin's tree, built by kernels",
	.build = build)
