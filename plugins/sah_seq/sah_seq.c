/*
 * sah_seq: the sequential top-down SAH builder, the reference the parallel
 * SAH strategies are compared with. All split decisions are the shared
 * kernel's (plugins/common/sah_kernel.h); this plugin only runs the whole
 * tree as one subtree on the calling thread.
 */

#include <bvhlab/builder.h>

#include "sah_kernel.h"
#include "sah_threads.h"

static const bvhlab_option_decl options[] = { SAH_OPTION_DECLS };

_Static_assert(sizeof(options) / sizeof(options[0]) == SAH_OPTION_COUNT,
               "SAH_OPTION_COUNT matches SAH_OPTION_DECLS");

/* The reference schedule: the whole tree as one subtree, on this thread. */
static int schedule(const bvhlab_host *host, bvhlab_build_ctx *ctx, sah_builder *b,
                    const sah_job *root, uint32_t threads, void *arg)
{
	(void)host;
	(void)ctx;
	(void)threads;
	(void)arg;
	sah_build_subtree(b, root);
	return 0;
}

static int build(const bvhlab_host *host, bvhlab_build_ctx *ctx,
                 const bvhlab_build_input *input, bvhlab_build_output *output)
{
	return sah_run_build(host, ctx, input, output, schedule, NULL);
}

BVHLAB_PLUGIN(.name = "sah_seq", .flags = BVHLAB_BUILDER_DETERMINISTIC,
	.summary = "sequential top-down SAH (exact sweep or binned), the reference",
	.option_count = SAH_OPTION_COUNT, .options = options, .build = build)
