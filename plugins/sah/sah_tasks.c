/*
 * sah_tasks: task-parallel binned SAH. Nodes above `parallel_min`
 * primitives are split one at a time by the whole team (horizontal
 * parallelism, tasks_split.c): every thread bins and partitions a chunk of
 * the node. Their smaller children become independent tasks (vertical
 * parallelism) that the threads then claim largest first from a shared
 * array and build whole with the kernel's sah_build_subtree.
 *
 * Why two phases rather than one queue: the top splits are the serial
 * part that caps the thesis's speedup; once they are done the tasks are
 * all known, so an atomic index over them (sorted by size, the classic
 * longest-first rule) is the whole scheduler. Termination is exact: a
 * thread leaves once the index passes the last task, and the caller's
 * barrier returns only when every thread has.
 *
 * Determinism: the kernel decides every split of the tasks; the team's
 * splits are the kernel's binned split (see tasks_split.h) and its stable
 * partition does not depend on the team's size. The horizontal path runs
 * with one thread too, so every thread count sees the same order in every
 * range. Method sweep has no team split: its large nodes are split by the
 * kernel on the calling thread, then its tasks run in parallel the same way.
 */
#include <errno.h>
#include <stdbool.h>
#include <stdatomic.h>
#include <stdlib.h>
#include <string.h>

#include <bvhlab/builder.h>

#include "sah_kernel.h"
#include "sah_nodes.h"
#include "sah_threads.h"
#include "tasks_split.h"
#include "team_list.h"
#include "team.h"

/* Where the options go. */
struct tasks_options {
	sah_options sah;
	uint32_t parallel_min;
};

/* SAH_OPTIONS in the same order, parallel_min among them, but binned by
 * default: the team split exists for binned only. */
static const plugin_option options[] = {
	PLUGIN_OPTION(struct tasks_options, sah.method, CHOICE, .name = "method",
	              .help = "split search: binned (team-parallel top splits) or sweep (exact "
	                      "SAH, top splits on one thread)",
	              .def_string = "binned", .choices = "sweep|binned"),
	SAH_SPLIT_OPTIONS(struct tasks_options),
	PLUGIN_OPTION(struct tasks_options, parallel_min, U32, .name = "parallel_min",
	              .help = "nodes with more primitives are split by all threads together; "
	                      "smaller ones are tasks built by one thread each",
	              .def_int = 65536, .min = 128, .max = 1 << 30),
	SAH_SIMD_OPTION(struct tasks_options),
	SAH_QUALITY_OPTION(struct tasks_options),
	PLUGIN_OPTION(struct tasks_options, sah.sample, U32, .name = "sample",
	              .help = "0: bin every primitive; else a node of over 4 * sample primitives "
	                      "bins `sample` of them, evenly spaced (fewer passes' worth of "
	                      "binning at the top, a slightly worse tree; same for every thread "
	                      "count)",
	              .def_int = 0, .min = 0, .max = SAH_MAX_SAMPLE),
};

/* A node larger than 64 (the most max_leaf allows) is never a leaf, which
 * the team split relies on. */
_Static_assert(128 > 64, "parallel_min's minimum exceeds max_leaf's maximum");

enum command { CMD_BIN, CMD_SCATTER, CMD_TASKS, CMD_EXIT };

/* The threads of one build (the name "team" is team.h's). */
struct crew {
	team bar;             /* the members; polls, then sleeps: see team.h */
	uint32_t size;        /* bar.threads, once the team runs */
	int cmd;              /* set by the caller between barriers */
	int rc;               /* the calling thread's result */
	uint32_t parallel_min;
	const sah_job *root;
	tasks_split split;
	sah_builder *b;
	team_list tasks;      /* of sah_job: the subtrees below parallel_min */
};

/*
 * Each task builds into a scratch array of its own, with a counter of its
 * own, and is copied into the tree when done (sah_place_scratch): the shared counter is then
 * touched once per task instead of once per split, and two threads share
 * a cache line of nodes only at the ends of a task's range. With the
 * shared counter, the atomic's cache line and the interleaved node writes
 * bounced between the cores at every split (on igea subdivided once: 148 to 150 ms for the
 * tasks at 2 threads, 137 to 140 without).
 */
static void run_tasks(struct crew *tm)
{
	sah_builder local;
	sah_job *tasks = tm->tasks.items;
	size_t i, cap = tm->tasks.n ? 2 * sah_job_size(&tasks[0]) : 0;
	bvhlab_node *scratch = cap ? malloc(cap * sizeof(*scratch)) : NULL;

	memcpy(&local, tm->b, sizeof(local));
	local.nodes = scratch;
	while (team_list_claim(&tm->tasks, &i)) {
		sah_job job = tasks[i];
		if (!scratch) { /* no memory for it: the shared counter still works */
			sah_build_subtree(tm->b, &job);
			continue;
		}
		job.node = 0;
		atomic_init(&local.node_counter, 1);
		sah_build_subtree(&local, &job);
		sah_place_scratch(tm->b, tasks[i].node, scratch,
		                  atomic_load_explicit(&local.node_counter, memory_order_relaxed));
	}
	free(scratch);
}

static void run_part(struct crew *tm, uint32_t part)
{
	switch (tm->cmd) {
	case CMD_BIN: tasks_bin(&tm->split, part); break;
	case CMD_SCATTER: tasks_scatter(&tm->split, part); break;
	case CMD_TASKS: run_tasks(tm); break;
	default: break;
	}
}

/* A member other than the calling thread: follows its commands. */
static void follow(struct crew *tm, unsigned index)
{
	for (;;) {
		team_sync(&tm->bar);
		if (tm->cmd == CMD_EXIT)
			return;
		run_part(tm, index);
		team_sync(&tm->bar);
	}
}

/* One step by every member; the barriers publish the caller's settings
 * before it and every member's results after it. */
static void crew_run(struct crew *tm, int cmd)
{
	tm->cmd = cmd;
	if (tm->size > 1)
		team_sync(&tm->bar);
	run_part(tm, 0);
	if (tm->size > 1)
		team_sync(&tm->bar);
}

/* Splits one large node: by the team for binned, else by the kernel. */
static unsigned split_large(struct crew *tm, const sah_job *job, sah_job child[2])
{
	if (tm->b->opt.method != SAH_BINNED)
		return sah_split_job(tm->b, job, child);
	tasks_split_begin(&tm->split, job);
	crew_run(tm, CMD_BIN);
	/* No candidate: every centroid coincides; the kernel's median. */
	if (!tasks_choose(&tm->split))
		return sah_split_job(tm->b, job, child);
	crew_run(tm, CMD_SCATTER);
	tasks_split_end(&tm->split, child);
	return 2;
}

/*
 * The horizontal phase, on the calling thread (the members follow its
 * commands). Larger child pushed first, smaller processed first: the stack
 * stays within log2(N) + 1 entries.
 */
static int split_top(struct crew *tm, uint32_t parallel_min, const sah_job *root)
{
	sah_job stack[64], child[2];
	unsigned sp = 0;
	int rc = 0;

	stack[sp++] = *root;
	while (sp > 0 && rc == 0) {
		sah_job job = stack[--sp];
		if (sah_job_size(&job) <= parallel_min) {
			rc = team_list_push(&tm->tasks, &job);
			continue;
		}
		if (split_large(tm, &job, child) == 0)
			continue;
		unsigned big = sah_job_size(&child[1]) > sah_job_size(&child[0]);
		stack[sp++] = child[big];
		stack[sp++] = child[1 - big];
	}
	return rc;
}

/* Largest first, ties by position: the order is the same on every run. */
static int by_size_desc(const void *pa, const void *pb)
{
	const sah_job *a = pa, *b = pb;
	uint32_t na = sah_job_size(a), nb = sah_job_size(b);

	if (na != nb)
		return na > nb ? -1 : 1;
	return a->begin < b->begin ? -1 : a->begin > b->begin;
}

/* Top splits, then the tasks, largest first. */
static int run_build(struct crew *tm)
{
	int rc = split_top(tm, tm->parallel_min, tm->root);

	if (rc < 0)
		return rc;
	team_list_order(&tm->tasks, by_size_desc);
	crew_run(tm, CMD_TASKS);
	return 0;
}

/*
 * The calling thread (member 0) leads: the team is as large as what
 * started (every step is correct for any size), known to all once the
 * team runs. Members leave after the barrier that reads CMD_EXIT, so
 * there is no second one to meet.
 */
static void crew_member(void *arg, unsigned t)
{
	struct crew *tm = arg;

	if (t > 0) {
		follow(tm, t);
		return;
	}
	tm->size = tm->bar.threads;
	tm->split.parts = tm->size;
	tm->rc = run_build(tm);
	tm->cmd = CMD_EXIT;
	if (tm->size > 1)
		team_sync(&tm->bar);
}

static int schedule(team_host *th, sah_builder *b, const sah_job *root, uint32_t asked,
                    void *arg)
{
	const struct tasks_options *o = arg;
	/* no more OS threads than the scene has work for */
	uint32_t threads = sah_useful_threads(asked, root);
	struct crew tm = { .b = b, .parallel_min = o->parallel_min, .root = root,
	                   .tasks = TEAM_LIST(sah_job) };
	int rc = tasks_split_init(&tm.split, b, threads);
	if (rc == 0)
		rc = team_run_on(&tm.bar, th, threads, crew_member, &tm);
	if (rc == 0)
		rc = tm.rc;
	tasks_split_free(&tm.split);
	team_list_free(&tm.tasks);
	if (rc < 0)
		th->host->set_error(th->ctx, "sah_tasks: cannot set up the build (%d)", rc);
	return rc;
}

SAH_PLUGIN("sah_tasks",
	BVHLAB_BUILDER_PARALLEL | BVHLAB_BUILDER_DETERMINISTIC | BVHLAB_BUILDER_BOXES,
	"parallel binned SAH: large nodes split by all threads, small ones as tasks",
	struct tasks_options)
