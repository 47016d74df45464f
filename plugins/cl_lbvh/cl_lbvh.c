/*
 * cl_lbvh: LBVH on an OpenCL device (Karras 2012), the tree of the CPU
 * lbvh plugin for the same options, bit for bit. Morton codes and a stable
 * LSD radix sort (plugins/common/cl), Karras's hierarchy in one kernel,
 * boxes and the SAH collapse bottom-up with atomic counters, then which
 * nodes stay inner (cl_lbvh.cl); the compaction of the collapsed tree, as
 * lbvh_collapse.c's, on the host (cl_lbvh_compact.c).
 *
 * Phases reported: upload (boxes and centroids, wall clock), device (the
 * kernels' and fills' own times, from their events), download and convert
 * (the compaction), wall clock.
 */
#include <errno.h>
#include <stdlib.h>
#include <string.h>

#include "cl_dev.h"
#include "cl_lbvh.h"
#include "cl_lbvh_src.h"
#include "morton_front.h"

static const bvhlab_option_decl options[] = {
	MORTON_OPTION_DECLS,
	CL_DEVICE_OPTION_DECL,
	{ .name = "leaf_block", .type = BVHLAB_OPTION_INT,
	  .help = "leaves per work-item of the bounds kernel (0: 512 on a CPU device, "
	          "1 on a GPU); the tree is the same for every value",
	  .def_int = 0, .min = 0, .max = 1 << 20 },
	{ .name = "hierarchy", .type = BVHLAB_OPTION_STRING,
	  .help = "how each node's range and split are found: search (Karras's searches), "
	          "scan (lbvh's prefix scans), auto (scan on a CPU device, search on a GPU); "
	          "the tree is the same",
	  .def_string = "auto", .choices = "auto|search|scan" },
};

#define OPTION_COUNT (sizeof(options) / sizeof(options[0]))

static const char *const kernel_names[] = {
	CL_SORT_KERNEL_NAMES, "karras", "bounds", "inner_nodes", "gather_leaves", "prefixes",
	"karras_scan",
};

/* Kept between builds (one build at a time, ABI rule); released when the
 * plugin is unloaded. */
static struct {
	cl_dev dev;
	cl_sort sort;
	cl_buf b[LB_COUNT];
} S;

__attribute__((destructor)) static void release_device(void)
{
	cl_bufs_free(S.b, LB_COUNT);
	cl_bufs_free(S.sort.b, SB_COUNT);
	cl_dev_close(&S.dev);
}

static int read_options(const bvhlab_host *host, bvhlab_build_ctx *ctx, cl_lbvh *b)
{
	morton_options o;
	int64_t block;
	int rc = morton_read_options(host, ctx, &o);

	if (rc < 0)
		return rc;
	if ((rc = host->option_string(ctx, "device", &b->device)) < 0 ||
	    (rc = host->option_int(ctx, "leaf_block", &block)) < 0 ||
	    (rc = host->option_string(ctx, "hierarchy", &b->hierarchy)) < 0) {
		host->set_error(ctx, "cannot read the options device, leaf_block and hierarchy");
		return rc;
	}
	if (o.bits != 30 && o.bits != 63) {
		host->set_error(ctx, "option bits: %lld, expected 30 or 63", (long long)o.bits);
		return -EINVAL;
	}
	b->leaf_block = (uint32_t)block;
	b->collapse = o.collapse;
	b->bits = (unsigned)o.bits;
	b->max_leaf = (uint32_t)o.max_leaf;
	b->c_trav = (float)o.c_trav;
	b->c_isect = (float)o.c_isect;
	return 0;
}

static void report(const bvhlab_host *host, bvhlab_build_ctx *ctx, const cl_lbvh *b)
{
	static const char *const names[] = { "upload", "device", "download", "convert" };

	if (!BVHLAB_HOST_HAS(host, phase))
		return;
	for (int k = 0; k < 4; k++)
		host->phase(ctx, names[k], b->ms[k]);
}

static int build(const bvhlab_host *host, bvhlab_build_ctx *ctx,
                 const bvhlab_build_input *input, bvhlab_build_output *output)
{
	cl_lbvh b = { .in = input, .n = input->prim_count, .dev = &S.dev, .sort = &S.sort,
	              .b = S.b };
	char err[BVHLAB_CL_ERROR_SIZE];
	int rc;

	if (b.n == 0 || b.n > UINT32_MAX / 2) {
		host->set_error(ctx, "cannot build over %u primitives", b.n);
		return -EINVAL;
	}
	if ((rc = read_options(host, ctx, &b)) < 0 ||
	    (rc = morton_ensure_capacity(host, ctx, b.n, 0, output)) < 0)
		return rc;
	rc = cl_dev_open(&S.dev, b.device, cl_lbvh_src, cl_lbvh_src_LEN, kernel_names,
	                 sizeof(kernel_names) / sizeof(kernel_names[0]), err, sizeof(err));
	if (rc < 0) {
		host->set_error(ctx, "%s", err);
		return rc;
	}
	if (b.n == 1) {
		morton_single_leaf(input, output);
		return 0;
	}
	if ((rc = cl_lbvh_run(&b, output, err, sizeof(err))) < 0) {
		host->set_error(ctx, "%s", err);
		return rc;
	}
	report(host, ctx, &b);
	return 0;
}

BVHLAB_PLUGIN(.name = "cl_lbvh", .flags = BVHLAB_BUILDER_DETERMINISTIC,
	.summary = "LBVH on an OpenCL device (Karras 2012): the lbvh plugin's tree, built by kernels",
	.option_count = OPTION_COUNT, .options = options, .build = build)
