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

static const bvhlab_option_decl options[] = {
	{ .name = "radius", .type = BVHLAB_OPTION_INT,
	  .help = "search radius: clusters on either side, in Morton order, that each "
	          "cluster compares with",
	  .def_int = 16, .min = 1, .max = CL_PLOC_MAX_RADIUS },
	MORTON_OPTION_DECLS,
	CL_DEVICE_OPTION_DECL,
	{ .name = "nn_block", .type = BVHLAB_OPTION_INT,
	  .help = "clusters per work-item of the nearest-neighbour search (0: 256 on a CPU "
	          "device, 1 on a GPU); the tree is the same for every value",
	  .def_int = 0, .min = 0, .max = CL_PLOC_MAX_NN_BLOCK },
};

#define OPTION_COUNT (sizeof(options) / sizeof(options[0]))

static const char *const kernel_names[] = {
	CL_SORT_KERNEL_NAMES, "first_clusters", "nearest", "count_chunks", "prefix",
	"write_chunks", "nearest_blocks",
};

/* Kept between builds (one build at a time, ABI rule), with the host's
 * copy of the merge tree; released when the plugin is unloaded. */
static struct {
	cl_dev dev;
	cl_sort sort;
	cl_buf b[PB_COUNT];
	bvhlab_node *tree;
	uint32_t *desc;
	uint32_t cap;
} S;

__attribute__((destructor)) static void release_device(void)
{
	cl_bufs_free(S.b, PB_COUNT);
	cl_bufs_free(S.sort.b, SB_COUNT);
	cl_dev_close(&S.dev);
	free(S.tree);
	free(S.desc);
}

static int read_options(const bvhlab_host *host, bvhlab_build_ctx *ctx, cl_ploc *b)
{
	morton_options o;
	int64_t radius, nn_block;
	int rc;

	if ((rc = host->option_int(ctx, "radius", &radius)) < 0 ||
	    (rc = host->option_int(ctx, "nn_block", &nn_block)) < 0 ||
	    (rc = host->option_string(ctx, "device", &b->device)) < 0) {
		host->set_error(ctx, "cannot read the options");
		return rc;
	}
	if ((rc = morton_read_options(host, ctx, &o)) < 0)
		return rc;
	if (o.bits != 30 && o.bits != 63) {
		host->set_error(ctx, "option bits: %lld, expected 30 or 63", (long long)o.bits);
		return -EINVAL;
	}
	b->radius = (uint32_t)radius;
	b->nn_block = (uint32_t)nn_block;
	b->collapse = o.collapse;
	b->bits = (unsigned)o.bits;
	b->max_leaf = (uint32_t)o.max_leaf;
	b->c_trav = (float)o.c_trav;
	b->c_isect = (float)o.c_isect;
	return 0;
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

static void report(const bvhlab_host *host, bvhlab_build_ctx *ctx, const cl_ploc *b)
{
	static const char *const names[] = { "upload", "device", "download", "convert" };

	if (!BVHLAB_HOST_HAS(host, phase))
		return;
	for (int k = 0; k < 4; k++)
		host->phase(ctx, names[k], b->ms[k]);
}

static int run(const bvhlab_host *host, bvhlab_build_ctx *ctx, cl_ploc *b,
               bvhlab_build_output *out)
{
	char err[BVHLAB_CL_ERROR_SIZE];
	double t0;
	int rc;

	if (host_tree(b) < 0) {
		host->set_error(ctx, "out of memory for the merge tree of %u primitives", b->n);
		return -ENOMEM;
	}
	if ((rc = cl_ploc_run(b, err, sizeof(err))) < 0) {
		host->set_error(ctx, "%s", err);
		return rc;
	}
	t0 = cl_now_ms();
	out->node_count = cl_ploc_emit(b, out);
	out->index_count = b->n;
	b->ms[3] = cl_now_ms() - t0;
	host->log(ctx, BVHLAB_LOG_DEBUG, "%u prims, %u iterations on %s", b->n, b->iterations,
	          S.dev.cl.name);
	report(host, ctx, b);
	return 0;
}

static int build(const bvhlab_host *host, bvhlab_build_ctx *ctx,
                 const bvhlab_build_input *input, bvhlab_build_output *output)
{
	cl_ploc b = { .in = input, .n = input->prim_count, .dev = &S.dev, .sort = &S.sort,
	              .b = S.b };
	char err[BVHLAB_CL_ERROR_SIZE];
	int rc;

	if (b.n == 0 || b.n > REC_PRIMS) {
		host->set_error(ctx, "cannot build over %u primitives", b.n);
		return -EINVAL;
	}
	if ((rc = read_options(host, ctx, &b)) < 0 ||
	    (rc = morton_ensure_capacity(host, ctx, b.n, 0, output)) < 0)
		return rc;
	rc = cl_dev_open(&S.dev, b.device, cl_ploc_src, cl_ploc_src_LEN, kernel_names,
	                 sizeof(kernel_names) / sizeof(kernel_names[0]), err, sizeof(err));
	if (rc < 0) {
		host->set_error(ctx, "%s", err);
		return rc;
	}
	if (b.n == 1) {
		morton_single_leaf(input, output);
		return 0;
	}
	return run(host, ctx, &b, output);
}

BVHLAB_PLUGIN(.name = "cl_ploc", .flags = BVHLAB_BUILDER_DETERMINISTIC,
	.summary = "PLOC on an OpenCL device (Meister & Bittner 2018): the ploc plugin's tree, "
	           "built by kernels",
	.option_count = OPTION_COUNT, .options = options, .build = build)
