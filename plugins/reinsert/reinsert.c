/*
 * reinsert: the refinement plugin (see reinsert.h). This file: options,
 * scratch, the iterations, refine().
 */
#include <errno.h>
#include <stdlib.h>
#include <string.h>

#include "leaves.h"
#include "plugin_options.h"
#include "reinsert.h"

struct params {
	double batch, min_gain;
	int64_t iterations, max_visits, max_leaf;
	int measure; /* enum reinsert_measure */
	bool leaves, children;
};

static const plugin_option options[] = {
	PLUGIN_OPTION(struct params, batch, DOUBLE, .name = "batch",
	              .help = "fraction of the nodes (chosen by measure) searched for a better "
	                      "place in each iteration",
	              .def_float = 0.05, .min = 1e-6, .max = 1.0),
	PLUGIN_OPTION(struct params, iterations, I64, .name = "iterations",
	              .help = "most iterations (candidates chosen anew in each)",
	              .def_int = 8, .min = 1, .max = 1000),
	PLUGIN_OPTION(struct params, min_gain, DOUBLE, .name = "min_gain",
	              .help = "stop after an iteration that lowers the SAH by less than this "
	                      "fraction of it (0: run every iteration)",
	              .def_float = 0.001, .min = 0.0, .max = 1.0),
	PLUGIN_OPTION(struct params, measure, CHOICE, .name = "measure",
	              .help = "which nodes a batch takes: bittner (those that hold their "
	                      "children worst, Bittner et al.'s measure) or area (the largest, "
	                      "as madmann91/bvh's reinsertion optimiser: the top of the tree "
	                      "first)",
	              .def_string = "bittner", .choices = "bittner|area"),
	PLUGIN_OPTION(struct params, children, BOOL, .name = "children",
	              .help = "also try Bittner et al.'s move for each inner candidate: take it "
	                      "and its parent out and put its two children back apart, where "
	                      "each costs least",
	              .def_bool = true),
	LEAVES_OPTIONS(struct params),
	PLUGIN_OPTION(struct params, max_visits, I64, .name = "max_visits",
	              .help = "most nodes one candidate's search may look at",
	              .def_int = 4096, .min = 16, .max = 1 << 24),
};
PLUGIN_DECLS(options, struct params, NULL)

/* ---- iterations ----------------------------------------------------------- */

static void find_parents(reinsert *r)
{
	r->parent[0] = NO_NODE;
	for (uint32_t x = 0; x < r->node_count; x++)
		if (r->nodes[x].count == 0)
			r->parent[r->nodes[x].first] = r->parent[r->nodes[x].first + 1] = x;
}

static double inner_area(const reinsert *r)
{
	double sum = 0;

	for (uint32_t x = 0; x < r->node_count; x++)
		sum += node_cost(&r->nodes[x]);
	return sum;
}

static int by_gain(const void *a, const void *b)
{
	const struct move *x = a, *y = b;

	if (x->gain != y->gain)
		return x->gain < y->gain ? 1 : -1;
	return (x->node > y->node) - (x->node < y->node);
}

/* The moves by decreasing predicted gain; returns the exact change. */
static double apply(reinsert *r)
{
	uint32_t count = 0;
	double change = 0;

	for (uint32_t k = 0; k < r->cand_count; k++)
		if (r->moves[k].dest != NO_NODE && r->moves[k].gain > 0)
			r->moves[count++] = r->moves[k];
	qsort(r->moves, count, sizeof(*r->moves), by_gain);
	for (uint32_t k = 0; k < count; k++) {
		const struct move *m = &r->moves[k];
		change += m->dest2 == NO_NODE ? reinsert_try(r, m->node, m->dest)
		                              : reinsert_try_children(r, m->node, m->dest, m->dest2);
	}
	return change;
}

static void search_member(void *arg, unsigned t)
{
	(void)t;
	reinsert_search(arg);
}

static int iterate(reinsert *r, const struct params *o, uint32_t threads, const team_host *th)
{
	double total = inner_area(r);

	for (int64_t it = 0; it < o->iterations; it++) {
		double change;
		int rc;

		if ((rc = reinsert_choose(r, o->batch, threads, th)) < 0)
			return rc;
		atomic_store_explicit(&r->next, 0, memory_order_relaxed);
		if ((rc = team_run_on(&r->team, th, threads, search_member, r)) < 0)
			return rc;
		change = apply(r);
		if (-change < o->min_gain * total || change == 0)
			break;
		total += change;
	}
	return 0;
}

/* ---- refine ------------------------------------------------------------- */

static int optimise(const bvhlab_host *host, bvhlab_build_ctx *ctx, const struct params *o,
                    const bvhlab_build_input *input, bvhlab_build_output *tree)
{
	reinsert r = { .nodes = tree->nodes, .node_count = tree->node_count,
	               .max_visits = (uint32_t)o->max_visits, .children = o->children,
	               .measure = o->measure };
	size_t n = tree->node_count, blocks = n / CHOOSE_BLOCK + 1;
	uint32_t members = input->threads ? input->threads : 1;
	team_host th;
	int rc;

	team_host_init(&th, host, ctx);
	r.parent = malloc(n * sizeof(*r.parent));
	r.cand = malloc(n * sizeof(*r.cand));
	r.moves = malloc(n * sizeof(*r.moves));
	r.keys = malloc(n * sizeof(*r.keys));
	r.hist = malloc((size_t)members * 65536 * sizeof(*r.hist));
	r.above = malloc(blocks * sizeof(*r.above));
	r.equal = malloc(blocks * sizeof(*r.equal));
	if (!r.parent || !r.cand || !r.moves || !r.keys || !r.hist || !r.above || !r.equal) {
		host->set_error(ctx, "out of memory for %zu nodes", n);
		rc = -ENOMEM;
		goto out;
	}
	find_parents(&r);
	if ((rc = iterate(&r, o, members, &th)) < 0)
		host->set_error(ctx, "cannot start the search threads");
out:
	free(r.parent);
	free(r.cand);
	free(r.moves);
	free(r.keys);
	free(r.hist);
	free(r.above);
	free(r.equal);
	return rc;
}

/* What optimise needs, as the leaves_run stage. */
struct stage {
	const bvhlab_host *host;
	bvhlab_build_ctx *ctx;
	const struct params *o;
	const bvhlab_build_input *input;
};

static int stage(void *arg, bvhlab_build_output *tree)
{
	const struct stage *st = arg;

	return tree->node_count < 3 ? 0 : optimise(st->host, st->ctx, st->o, st->input, tree);
}

static int refine(const bvhlab_host *host, bvhlab_build_ctx *ctx,
                  const bvhlab_build_input *input, bvhlab_build_output *tree)
{
	struct params o;
	struct stage st = { .host = host, .ctx = ctx, .o = &o, .input = input };
	int rc;

	if ((rc = PLUGIN_OPTIONS_GET(host, ctx, input, &o)) < 0)
		return rc;
	if (tree->node_count < 3 && !(o.leaves && tree->node_count == 1 && tree->nodes[0].count > 1))
		return 0; /* nothing can move */
	return leaves_run(host, ctx, input, tree, o.leaves, false, (uint32_t)o.max_leaf, stage, &st);
}

LEAVES_STAGE_PLUGIN(options,
	.name = "reinsert",
	.summary = "refinement: parallel search, exact one-thread application of subtree "
	           "reinsertions (Bittner et al. 2013, Meister & Bittner 2018)",
	.peak_bytes_per_prim = 160 /* beyond the tree: measured 108-136 */)
