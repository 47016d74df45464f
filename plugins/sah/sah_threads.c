/*
 * The build frame and thread helpers of the parallel SAH plugins (see
 * sah_threads.h). The frame mirrors sah_seq's build() so that the parallel
 * plugins accept and reject exactly the same inputs as the reference.
 */
#include <errno.h>

#include "sah_threads.h"

/* The host preallocates 2N-1 nodes and N indices; ask only if it did not. */
static int ensure_capacity(const bvhlab_host *host, bvhlab_build_ctx *ctx,
                           const bvhlab_build_input *input, bvhlab_build_output *output,
                           int method)
{
	uint64_t nodes = 2 * (uint64_t)input->prim_count - 1;
	uint64_t room = nodes + sah_scratch_nodes(method, input->prim_count);

	/* The record arrays past the tree (sah_scratch_nodes); fine if refused. */
	if (room <= UINT32_MAX && output->node_capacity < room)
		(void)host->grow_output(ctx, output, (uint32_t)room, input->prim_count);
	if (output->node_capacity >= nodes && output->index_capacity >= input->prim_count)
		return 0;
	if (host->grow_output(ctx, output, (uint32_t)nodes, input->prim_count) < 0) {
		host->set_error(ctx, "cannot grow the output to %llu nodes",
		                (unsigned long long)nodes);
		return -ENOMEM;
	}
	return 0;
}

int sah_run_build(const bvhlab_host *host, bvhlab_build_ctx *ctx,
                  const bvhlab_build_input *input, bvhlab_build_output *output,
                  sah_options *opt, sah_scheduler_fn schedule, void *arg)
{
	sah_builder b;
	sah_job root;
	team_host th;
	int rc;

	if (input->prim_count == 0 || input->prim_count > UINT32_MAX / 2) {
		host->set_error(ctx, "cannot build over %u primitives", input->prim_count);
		return -EINVAL;
	}
	if ((rc = sah_options_resolve(host, ctx, opt)) < 0 ||
	    (rc = ensure_capacity(host, ctx, input, output, opt->method)) < 0)
		return rc;
	team_host_init(&th, host, ctx);
	rc = sah_builder_init(&b, opt, input, output, &th);
	if (rc < 0) {
		host->set_error(ctx, "%s", rc == -ENOMEM ? "out of memory for the SAH scratch"
		                                         : "invalid build input");
		return rc;
	}
	sah_builder_root(&b, &root);
	rc = schedule(&th, &b, &root, input->threads ? input->threads : 1, arg);
	if (rc == 0)
		sah_builder_finish(&b, output);
	sah_builder_free(&b);
	return rc;
}

static void subtree_main(void *arg)
{
	sah_subtree_task *task = arg;

	sah_build_subtree(task->b, &task->job);
}

void sah_subtree_spawn(team_host *th, sah_subtree_task *task)
{
	if (team_spawn(th, &task->thread, subtree_main, task) < 0)
		sah_build_subtree(task->b, &task->job);
}

void sah_subtree_join(sah_subtree_task *task)
{
	team_join(&task->thread);
}
