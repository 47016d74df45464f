/*
 * sah_even: the thesis's "symmetric" scheduling. At every split a new
 * thread takes one child while the current thread goes on with the other,
 * and the thread budget left is halved between them (the larger child gets
 * the extra thread of an odd budget). A subtree whose budget is down to one
 * thread is built whole by sah_build_subtree. Over the whole tree exactly
 * threads - 1 threads are started, each joined by the thread that started
 * it. Splits are the shared kernel's, so the tree is sah_seq's.
 *
 * The budget is split by thread count, not by work: a lopsided split (a
 * dense object in a large sparse scene) leaves half the threads with
 * little to do. That is the weakness the thesis measured.
 */
#include <errno.h>

#include <bvhlab/builder.h>

#include "sah_kernel.h"
#include "sah_threads.h"

/* One subtree with its share of the threads; lives in its starter's frame
 * until the join, so the thread can use it throughout. */
struct even_task {
	team_host *th;
	sah_builder *b;
	sah_job job;
	uint32_t budget;
	team_thread thread;
};

static void build_even(team_host *th, sah_builder *b, const sah_job *job, uint32_t budget);

static void even_main(void *arg)
{
	struct even_task *task = arg;

	build_even(task->th, task->b, &task->job, task->budget);
}

/* Recursion depth is log2(budget): the budget halves at every level. */
static void build_even(team_host *th, sah_builder *b, const sah_job *job, uint32_t budget)
{
	sah_job child[2];

	if (budget <= 1) {
		sah_build_subtree(b, job);
		return;
	}
	if (sah_split_job(b, job, child) == 0)
		return;
	unsigned big = sah_job_size(&child[1]) > sah_job_size(&child[0]);
	struct even_task other = { .th = th, .b = b, .job = child[1 - big],
	                           .budget = budget / 2 };
	/* Without a new thread the work is still done, only later. */
	bool started = team_spawn(th, &other.thread, even_main, &other) == 0;

	build_even(th, b, &child[big], budget - budget / 2);
	if (started)
		team_join(&other.thread);
	else
		build_even(th, b, &other.job, other.budget);
}

static int schedule(team_host *th, sah_builder *b, const sah_job *root, uint32_t threads,
                    void *arg)
{
	(void)arg;
	if (threads > 1)
		team_pin(th, 0);
	build_even(th, b, root, threads);
	return 0;
}

SAH_PLAIN_PLUGIN("sah_even", BVHLAB_BUILDER_PARALLEL | BVHLAB_BUILDER_DETERMINISTIC,
	"parallel SAH, thesis \"symmetric\": a thread per split, budget halved")
