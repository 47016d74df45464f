/*
 * treelet: the refinement plugin (see treelet.h). This file: options,
 * scratch, the rounds and their threads, refine().
 */
#include <errno.h>
#include <stdlib.h>

#include "leaves.h"
#include "plugin_options.h"
#include "treelet.h"

/* Tasks: subtrees of at most this share of the nodes, so that two threads
 * get dozens each, but never tiny ones. */
#define TASK_SHARE 256
#define TASK_MIN 1024

/* One thread's part of a round: whole tasks, whichever are left. */
static void member(void *arg, unsigned m)
{
	treelet *t = arg;
	uint64_t changed = 0;
	uint32_t k;

	(void)m;
	while ((k = atomic_fetch_add_explicit(&t->next, 1, memory_order_relaxed)) < t->tasks)
		for (uint32_t i = k ? t->task_end[k - 1] : 0; i < t->task_end[k]; i++)
			changed += treelet_optimise(t, t->order[i]);
	atomic_fetch_add_explicit(&t->changed, changed, memory_order_relaxed);
}

static int rounds(treelet *t, int64_t count, uint32_t *scratch, unsigned threads,
                  const team_host *th)
{
	uint32_t task_nodes = t->node_count / TASK_SHARE;

	task_nodes = task_nodes < TASK_MIN ? TASK_MIN : task_nodes;
	for (int64_t r = 0; r < count; r++) {
		int rc;

		treelet_plan(t, task_nodes, scratch);
		atomic_store_explicit(&t->next, 0, memory_order_relaxed);
		atomic_store_explicit(&t->changed, 0, memory_order_relaxed);
		if ((rc = team_run_on(&t->team, th, threads, member, t)) < 0)
			return rc;
		uint64_t changed = atomic_load_explicit(&t->changed, memory_order_relaxed);
		for (uint32_t i = t->top_begin; i < t->top_end; i++)
			changed += treelet_optimise(t, t->order[i]);
		if (!changed)
			break;
	}
	return 0;
}

/* The options as read, and what the rounds need. */
struct params {
	const bvhlab_host *host;
	bvhlab_build_ctx *ctx;
	const bvhlab_build_input *input;
	int64_t size, rounds, max_leaf;
	bool leaves;
};

/* The rounds over the tree as it is now, with their scratch: the
 * leaves_run stage. */
static int optimise(void *arg, bvhlab_build_output *tree)
{
	const struct params *o = arg;
	treelet t = { .nodes = tree->nodes, .node_count = tree->node_count,
	              .size = (uint32_t)o->size, .max_leaf = (uint32_t)o->max_leaf };
	size_t n = tree->node_count;
	uint32_t *scratch;
	team_host th;
	int rc;

	if (n < 5)
		return 0; /* no treelet of three leaves */
	scratch = malloc(2 * n * sizeof(*scratch));
	t.order = malloc(n * sizeof(*t.order));
	t.task_end = malloc(n * sizeof(*t.task_end));
	t.cost = malloc(n * sizeof(*t.cost));
	t.prims = malloc(n * sizeof(*t.prims));
	if (!t.order || !t.task_end || !t.cost || !t.prims || !scratch) {
		o->host->set_error(o->ctx, "out of memory for %zu nodes", n);
		rc = -ENOMEM;
		goto out;
	}
	team_host_init(&th, o->host, o->ctx);
	rc = rounds(&t, o->rounds, scratch, o->input->threads, &th);
	if (rc < 0)
		o->host->set_error(o->ctx, "cannot start the threads");
out:
	free(t.order);
	free(t.task_end);
	free(t.cost);
	free(t.prims);
	free(scratch);
	return rc;
}

static const plugin_option options[] = {
	PLUGIN_OPTION(struct params, size, I64, .name = "size",
	              .help = "leaves of a treelet: every binary tree over them is tried (7, as "
	                      "Karras & Aila; 8 takes three times as long)",
	              .def_int = 7, .min = 3, .max = TREELET_MAX),
	PLUGIN_OPTION(struct params, rounds, I64, .name = "rounds",
	              .help = "most passes over every node (a pass that rewrites nothing ends it)",
	              .def_int = 3, .min = 1, .max = 100),
	LEAVES_OPTIONS(struct params),
};
PLUGIN_DECLS(options, struct params, NULL)

static int refine(const bvhlab_host *host, bvhlab_build_ctx *ctx,
                  const bvhlab_build_input *input, bvhlab_build_output *tree)
{
	struct params o;
	int rc;

	/* The options first: the copy sets the whole struct, the rest zero. */
	if ((rc = PLUGIN_OPTIONS_GET(host, ctx, input, &o)) < 0)
		return rc;
	o.host = host;
	o.ctx = ctx;
	o.input = input;
	/* the costs assume the final cut, so it is made with or without splitting */
	return leaves_run(host, ctx, input, tree, o.leaves, true, (uint32_t)o.max_leaf, optimise,
	                  &o);
}

LEAVES_STAGE_PLUGIN(options,
	.name = "treelet",
	.summary = "refinement: every shape of small treelets tried by dynamic programming, "
	           "the best kept (Karras & Aila 2013); parallel over subtrees, deterministic",
	.peak_bytes_per_prim = 144 /* beyond the tree: measured 105-131 */)
