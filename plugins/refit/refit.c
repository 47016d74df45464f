/*
 * refit: the update plugin (ABI 1.4). After the primitives moved, every
 * leaf's box becomes the union of its primitives' new boxes and every
 * inner node's the union of its children's; the shape of the tree is kept.
 *
 * It streams: the tree is kept in a layout where every cut subtree's
 * descendants are one contiguous span of the node array, children after
 * their parents, and the leaves' references in node order (refit.h). The
 * threads take spans from a shared counter and sweep each from its end
 * (refit_sweep.c); the calling thread then refits the few nodes above the
 * cut. A tree in another layout is rewritten into this one at its update
 * (refit_layout.c): same shape, same leaves, node order and prim_index
 * changed. A refit alone pays that once, at its first frame; the frames
 * after it stream. On igea subdivided once (lbvh's tree) an update went
 * from 31 ms a thread, walking lbvh's node order, to 6.5 (docs/animation.md).
 *
 * No node is written by two threads (the spans are disjoint, and a sweep
 * that meets a child outside its own span reads inside it instead and
 * fails), and a box is a min/max of the same values whoever computes it,
 * so the tree is the same bit for bit, node order included, for any
 * thread count (DETERMINISTIC). The threads are the host's executor's
 * (team.h), placed and pinned by the host.
 */
#include <errno.h>
#include <stdlib.h>
#include <string.h>

#include <bvhlab/aabb.h>
#include <bvhlab/builder.h>

#include "refit.h"

/* Nodes per thread below which starting one costs more than it saves. */
#define NODES_PER_THREAD 32768

static void fault(refit *r, enum refit_fault f)
{
	unsigned none = FAULT_NONE;
	atomic_compare_exchange_strong(&r->fault, &none, (unsigned)f);
}

static void member(void *arg, unsigned t)
{
	refit *r = arg;
	struct refit_scratch w;
	uint32_t lo, hi;
	(void)t;
	while (!atomic_load_explicit(&r->fault, memory_order_relaxed) &&
	       team_next_block(&r->next, r->span_count, 1, &lo, &hi)) {
		enum refit_fault f = refit_sweep(r, r->spans[lo], &w);
		if (f != FAULT_NONE)
			fault(r, f);
	}
}

/* Every span, on up to `threads` threads. */
static enum refit_fault sweep_spans(refit *r, uint32_t threads, int *rc)
{
	atomic_store(&r->next, 0);
	atomic_store(&r->fault, FAULT_NONE);
	if (threads > 1 && r->span_count > 1)
		*rc = team_run_on(&r->team, &r->th, threads, member, r);
	else
		member(r, 0);
	return (enum refit_fault)atomic_load(&r->fault);
}

/* The roots of the cut, then the nodes above it, deepest first (the top
 * is listed in pre-order). */
static enum refit_fault refit_top(refit *r)
{
	for (uint32_t k = 0; k < r->root_count; k++) {
		bvhlab_node *n = &r->nodes[r->roots[k]];
		if (!n->count)
			refit_inner(r, n);
		else if (!refit_leaf(r, n))
			return FAULT_PRIM;
	}
	for (uint32_t k = r->top_count; k-- > 0;)
		refit_inner(r, &r->nodes[r->top[k]]);
	return FAULT_NONE;
}

/* Sweeps the tree as it is laid out, or rewrites it first when it is not
 * the streamed layout. */
static enum refit_fault refit_tree(refit *r, uint32_t threads, int *rc)
{
	enum refit_fault f = refit_plan(r);
	if (f == FAULT_NONE)
		f = sweep_spans(r, threads, rc);
	if (f == FAULT_LAYOUT && *rc == 0) {
		f = refit_relayout(r);
		if (f == FAULT_NONE)
			f = refit_plan(r);
		if (f == FAULT_NONE)
			f = sweep_spans(r, threads, rc);
		/* A rewritten tree is in the layout: a shape the rewrite missed. */
		f = f == FAULT_LAYOUT ? FAULT_SHAPE : f;
	}
	return f == FAULT_NONE && *rc == 0 ? refit_top(r) : f;
}

static const char *fault_text(unsigned f)
{
	return f == FAULT_PRIM    ? "a leaf references a primitive past the input's, or a slot "
	                            "past index_count (another triangle count?)"
	       : f == FAULT_SHAPE ? "an inner node's children are out of range, or the tree "
	                            "has a cycle"
	                          : "out of memory";
}

static int update(const bvhlab_host *host, bvhlab_build_ctx *ctx,
                  const bvhlab_build_input *input, bvhlab_build_output *tree)
{
	refit *r = calloc(1, sizeof(*r));
	uint32_t threads = input->threads, most = 1 + tree->node_count / NODES_PER_THREAD;
	enum refit_fault f = FAULT_SHAPE;
	int rc = 0;
	if (!r) {
		host->set_error(ctx, "out of memory");
		return -ENOMEM;
	}
	*r = (refit){.host = host, .ctx = ctx, .boxes = input->prim_bounds,
	             .prim_count = input->prim_count, .out = tree, .nodes = tree->nodes,
	             .node_count = tree->node_count, .prim_index = tree->prim_index,
	             .index_count = tree->index_count};
	team_host_init(&r->th, host, ctx);
	threads = threads < most ? threads : most;
	threads = threads > TEAM_MAX_THREADS ? TEAM_MAX_THREADS : threads;
	if (tree->node_count)
		f = refit_tree(r, threads, &rc);
	tree->node_count = r->node_count;
	tree->index_count = r->index_count;
	if (rc < 0)
		host->set_error(ctx, "cannot set up the thread team");
	else if (f != FAULT_NONE) {
		host->set_error(ctx, "cannot refit: %s", fault_text(f));
		rc = f == FAULT_MEMORY ? -ENOMEM : -EINVAL;
	}
	free(r);
	return rc;
}

BVHLAB_PLUGIN(
	.name = "refit",
	.summary = "updates a tree after its primitives moved: boxes recomputed bottom-up, "
	           "shape kept; streams spans of a layout it rewrites the tree into once "
	           "(parallel, deterministic)",
	.flags = BVHLAB_BUILDER_PARALLEL | BVHLAB_BUILDER_DETERMINISTIC,
	.update = update)
