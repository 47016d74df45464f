/*
 * The build frame and thread helpers of the parallel SAH plugins (see
 * sah_threads.h). The frame mirrors sah_seq's build() so that the parallel
 * plugins accept and reject exactly the same inputs as the reference.
 */
#include <errno.h>

#include "big_alloc.h"
#include "sah_threads.h"

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
	if ((rc = big_ensure_output(host, ctx, input->prim_count,
	                            sah_scratch_nodes(opt->method, input->prim_count), output)) < 0)
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
