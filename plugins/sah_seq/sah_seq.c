/*
 * sah_seq: the sequential top-down SAH builder, the reference the parallel
 * SAH strategies are compared with. All split decisions are the shared
 * kernel's (plugins/common/sah_kernel.h); this plugin only runs the whole
 * tree as one subtree on the calling thread.
 */
#include <errno.h>

#include <bvhlab/builder.h>

#include "sah_kernel.h"

static const bvhlab_option_decl options[] = { SAH_OPTION_DECLS };

_Static_assert(sizeof(options) / sizeof(options[0]) == SAH_OPTION_COUNT,
               "SAH_OPTION_COUNT matches SAH_OPTION_DECLS");

/* The host preallocates 2N-1 nodes and N indices; ask only if it did not. */
static int ensure_capacity(const bvhlab_host *host, bvhlab_build_ctx *ctx,
                           const bvhlab_build_input *input, bvhlab_build_output *output)
{
	uint64_t nodes = 2 * (uint64_t)input->prim_count - 1;

	if (output->node_capacity >= nodes && output->index_capacity >= input->prim_count)
		return 0;
	if (host->grow_output(ctx, output, (uint32_t)nodes, input->prim_count) < 0) {
		host->set_error(ctx, "cannot grow the output to %llu nodes",
		                (unsigned long long)nodes);
		return -ENOMEM;
	}
	return 0;
}

static int build(const bvhlab_host *host, bvhlab_build_ctx *ctx,
                 const bvhlab_build_input *input, bvhlab_build_output *output)
{
	sah_options opt;
	sah_builder b;
	sah_job root;
	int rc;

	if (input->prim_count == 0 || input->prim_count > UINT32_MAX / 2) {
		host->set_error(ctx, "cannot build over %u primitives", input->prim_count);
		return -EINVAL;
	}
	if ((rc = sah_options_read(host, ctx, &opt)) < 0 ||
	    (rc = ensure_capacity(host, ctx, input, output)) < 0)
		return rc;
	rc = sah_builder_init(&b, &opt, input, output);
	if (rc < 0) {
		host->set_error(ctx, "%s", rc == -ENOMEM ? "out of memory for the SAH scratch"
		                                         : "invalid build input");
		return rc;
	}
	sah_builder_root(&b, &root);
	sah_build_subtree(&b, &root);
	sah_builder_finish(&b, output);
	sah_builder_free(&b);
	return 0;
}

static const bvhlab_builder descriptor = {
	.abi_version = BVHLAB_ABI_CURRENT,
	.struct_size = sizeof(bvhlab_builder),
	.name = "sah_seq",
	.summary = "sequential top-down SAH (exact sweep or binned), the reference",
	.flags = BVHLAB_BUILDER_DETERMINISTIC,
	.option_count = SAH_OPTION_COUNT,
	.options = options,
	.build = build,
};

BVHLAB_PLUGIN_ENTRY
{
	return host_abi_major == BVHLAB_ABI_MAJOR ? &descriptor : NULL;
}
