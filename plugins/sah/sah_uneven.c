/*
 * sah_uneven: the thesis's "asymmetric" scheduling. The calling thread
 * walks down from the root along the larger child: at each level the
 * smaller child goes to a new thread, which builds it whole with
 * sah_build_subtree, and the larger child keeps the right to spawn. When
 * threads - 1 threads run (or the path reaches a leaf) the calling thread
 * builds what is left itself, then joins every thread it started. Splits
 * are the shared kernel's, so the tree is sah_seq's.
 *
 * The smaller children shrink level by level while the path keeps the
 * bulk, so the calling thread carries most of the work on balanced scenes;
 * on a lopsided split (a small dense object in a large sparse scene) the
 * larger child is the hard one anyway, and following it is the better bet.
 */
#include <errno.h>
#include <stdlib.h>

#include <bvhlab/builder.h>

#include "sah_kernel.h"
#include "sah_threads.h"

/* Splits along the larger child, handing each smaller one to a new thread,
 * until `spare` threads are started; returns how many tasks it used. */
static uint32_t spawn_path(team_host *th, sah_builder *b, const sah_job *root,
                           sah_subtree_task *tasks, uint32_t spare)
{
	sah_job cur = *root, child[2];
	uint32_t used = 0;

	while (used < spare) {
		if (sah_split_job(b, &cur, child) == 0)
			return used;
		unsigned big = sah_job_size(&child[1]) > sah_job_size(&child[0]);
		tasks[used] = (sah_subtree_task){ .b = b, .job = child[1 - big] };
		sah_subtree_spawn(th, &tasks[used++]);
		cur = child[big];
	}
	sah_build_subtree(b, &cur);
	return used;
}

static int schedule(team_host *th, sah_builder *b, const sah_job *root, uint32_t threads,
                    void *arg)
{
	sah_subtree_task *tasks;
	uint32_t used;

	(void)arg;
	if (threads <= 1) {
		sah_build_subtree(b, root);
		return 0;
	}
	/* The threads keep pointers into this array until joined. */
	tasks = calloc(threads - 1, sizeof(*tasks));
	if (!tasks) {
		th->host->set_error(th->ctx, "out of memory for %u thread records", threads - 1);
		return -ENOMEM;
	}
	team_pin(th, 0);
	used = spawn_path(th, b, root, tasks, threads - 1);
	for (uint32_t i = 0; i < used; i++)
		sah_subtree_join(&tasks[i]);
	free(tasks);
	return 0;
}

SAH_PLAIN_PLUGIN("sah_uneven", BVHLAB_BUILDER_PARALLEL | BVHLAB_BUILDER_DETERMINISTIC,
	"parallel SAH, thesis \"asymmetric\": only the larger child spawns threads")
