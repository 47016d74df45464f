/*
 * treelet: the refinement plugin (see treelet.h). This file: options,
 * scratch, the rounds and their threads, refine().
 */
#include <errno.h>
#include <stdlib.h>

#include "leaves.h"
#include "treelet.h"

static const bvhlab_option_decl options[] = {
	{ .name = "size", .type = BVHLAB_OPTION_INT,
	  .help = "leaves of a treelet: every binary tree over them is tried (7, as Karras "
	          "& Aila; 8 takes three times as long)",
	  .def_int = 7, .min = 3, .max = TREELET_MAX },
	{ .name = "rounds", .type = BVHLAB_OPTION_INT,
	  .help = "most passes over every node (a pass that rewrites nothing ends it)",
	  .def_int = 3, .min = 1, .max = 100 },
	LEAVES_OPTION_DECLS,
};

#define OPTION_COUNT (sizeof(options) / sizeof(options[0]))

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
                  uint32_t cpus)
{
	uint32_t task_nodes = t->node_count / TASK_SHARE;

	task_nodes = task_nodes < TASK_MIN ? TASK_MIN : task_nodes;
	for (int64_t r = 0; r < count; r++) {
		int rc;

		treelet_plan(t, task_nodes, scratch);
		atomic_store_explicit(&t->next, 0, memory_order_relaxed);
		atomic_store_explicit(&t->changed, 0, memory_order_relaxed);
		if ((rc = team_run(&t->team, threads, cpus, member, t)) < 0)
			return rc;
		uint64_t changed = atomic_load_explicit(&t->changed, memory_order_relaxed);
		for (uint32_t i = t->top_begin; i < t->top_end; i++)
			changed += treelet_optimise(t, t->order[i]);
		if (!changed)
			break;
	}
	return 0;
}

/* The rounds over the tree as it is now, with their scratch. */
static int optimise(const bvhlab_host *host, bvhlab_build_ctx *ctx, uint32_t size,
                    uint32_t max_leaf, int64_t count, const bvhlab_build_input *input,
                    bvhlab_build_output *tree)
{
	treelet t = { .nodes = tree->nodes, .node_count = tree->node_count, .size = size,
	              .max_leaf = max_leaf };
	size_t n = tree->node_count;
	uint32_t *scratch = malloc(2 * n * sizeof(*scratch));
	int rc;

	t.order = malloc(n * sizeof(*t.order));
	t.task_end = malloc(n * sizeof(*t.task_end));
	t.cost = malloc(n * sizeof(*t.cost));
	t.prims = malloc(n * sizeof(*t.prims));
	if (!t.order || !t.task_end || !t.cost || !t.prims || !scratch) {
		host->set_error(ctx, "out of memory for %zu nodes", n);
		rc = -ENOMEM;
		goto out;
	}
	rc = rounds(&t, count, scratch, input->threads, host->hardware_threads(ctx));
	if (rc < 0)
		host->set_error(ctx, "cannot start the threads");
out:
	free(t.order);
	free(t.task_end);
	free(t.cost);
	free(t.prims);
	free(scratch);
	return rc;
}

static int refine(const bvhlab_host *host, bvhlab_build_ctx *ctx,
                  const bvhlab_build_input *input, bvhlab_build_output *tree)
{
	leaves_saved s = { 0 };
	int64_t size, count, max_leaf;
	bool leaves;
	int rc;

	if ((rc = host->option_int(ctx, "size", &size)) < 0 ||
	    (rc = host->option_int(ctx, "rounds", &count)) < 0 ||
	    (rc = host->option_bool(ctx, "leaves", &leaves)) < 0 ||
	    (rc = host->option_int(ctx, "max_leaf", &max_leaf)) < 0) {
		host->set_error(ctx, "cannot read the options");
		return rc;
	}
	if (size < 3 || size > TREELET_MAX || count < 1 || max_leaf < 1 || max_leaf > 64) {
		host->set_error(ctx, "options out of range");
		return -EINVAL;
	}
	/* the costs assume the final cut, so it is made with or without splitting */
	if ((rc = leaves_save(&s, tree)) < 0) {
		host->set_error(ctx, "out of memory for a copy of the tree");
		goto out;
	}
	if (leaves)
		leaves_split(host, ctx, input, tree);
	/* fewer than 5 nodes: no treelet of three leaves */
	if (tree->node_count >= 5 &&
	    (rc = optimise(host, ctx, (uint32_t)size, (uint32_t)max_leaf, count, input, tree)) < 0)
		goto out;
	if ((rc = leaves_collapse_or_restore(&s, tree, (uint32_t)max_leaf)) < 0)
		host->set_error(ctx, "out of memory for the collapse");
out:
	leaves_finish(&s);
	return rc;
}

BVHLAB_PLUGIN(
	.name = "treelet",
	.summary = "refinement: every shape of small treelets tried by dynamic programming, "
	           "the best kept (Karras & Aila 2013); parallel over subtrees, deterministic",
	.flags = BVHLAB_BUILDER_PARALLEL | BVHLAB_BUILDER_DETERMINISTIC,
	.option_count = OPTION_COUNT,
	.options = options,
	.build = NULL,
	.refine = refine)
