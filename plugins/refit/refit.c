/*
 * refit: the update plugin (ABI 1.4). After the primitives moved, every
 * leaf's box becomes the union of its primitives' new boxes and every
 * inner node's the union of its children's; the shape of the tree is kept.
 * One pass reads the primitive boxes the host computed and rewrites the
 * nodes in place: no scratch beyond a cut of the tree and one stack per
 * thread.
 *
 * The threads first refit every leaf, taking blocks of the node array in
 * turn: the gathers of primitive boxes, the costly part, run in parallel
 * and without a chain of dependent loads. Where every inner node's
 * children come after it (top-down builders' trees), one thread then
 * sweeps the array from its end to its start, meeting children before
 * their parents: every node read in order, not chased down the tree.
 * Other trees (lbvh's: half of its inner nodes on igea have children
 * before them) get their inner nodes refitted by subtrees: the top is cut,
 * breadth first, into at least CUT_PER_THREAD subtrees per thread; the
 * threads take whole subtrees from a shared counter and walk each in
 * post-order (an explicit stack, so a deep tree needs no deep recursion;
 * each node's children prefetched as it is opened), then the calling
 * thread refits the few nodes above the cut, deepest level first. On igea
 * subdivided once (lbvh's tree), the leaf pass and the prefetch took one
 * thread's refit from 255 to 143-215 ms on the loaded 2-core machine.
 * Either way no node is written by two threads, and a box is a min/max of
 * the same values whoever computes it, so the tree is the same bit for
 * bit for any thread count (DETERMINISTIC).
 */
#include <errno.h>
#include <stdatomic.h>
#include <stdlib.h>
#include <string.h>

#include <bvhlab/aabb.h>
#include <bvhlab/builder.h>

#include "team.h"

/* Subtrees per thread: enough that one slow thread (another process on
 * its CPU) holds the rest up by a small share. */
#define CUT_PER_THREAD 16
#define CUT_MAX (2 * CUT_PER_THREAD * TEAM_MAX_THREADS)
/* Nodes per thread below which starting one costs more than it saves. */
#define NODES_PER_THREAD 32768
/* Nodes of the array a thread takes at a time in the leaf pass. */
#define SWEEP_BLOCK 4096

enum refit_fault { FAULT_NONE, FAULT_SHAPE, FAULT_PRIM, FAULT_MEMORY };

typedef struct refit {
	const bvhlab_host *host;
	bvhlab_build_ctx *ctx;
	const bvhlab_aabb *boxes; /* [prim_count] the primitives' new boxes */
	uint32_t prim_count;
	bvhlab_node *nodes;
	uint32_t node_count;
	const uint32_t *prim_index;
	uint32_t index_count;
	uint32_t roots[CUT_MAX]; /* the subtrees below the cut */
	uint32_t root_count;
	uint32_t top[CUT_MAX];   /* the inner nodes above it, breadth first */
	uint32_t top_count;
	atomic_uint next;        /* the next subtree (or block of nodes) to take */
	atomic_uint fault;       /* enum refit_fault: the first problem met */
	atomic_bool unordered;   /* some inner node's children come before it */
	team team;
} refit;

/* One entry of a thread's post-order stack: the node, and whether its
 * children are done. */
struct entry {
	uint32_t node;
	uint32_t children_done;
};

struct stack {
	struct entry *e;
	size_t size, cap;
};

static bool push(struct stack *s, uint32_t node, uint32_t done)
{
	if (s->size == s->cap) {
		size_t cap = s->cap ? 2 * s->cap : 256;
		struct entry *e = realloc(s->e, cap * sizeof(*e));
		if (!e)
			return false;
		s->e = e;
		s->cap = cap;
	}
	s->e[s->size++] = (struct entry){node, done};
	return true;
}

static void fault(refit *r, enum refit_fault f)
{
	unsigned none = FAULT_NONE;
	atomic_compare_exchange_strong(&r->fault, &none, (unsigned)f);
}

/* A leaf's box from its primitives; false for a reference out of range. */
static bool refit_leaf(refit *r, bvhlab_node *n)
{
	float lo[3], hi[3];
	if (n->first > r->index_count || n->count > r->index_count - n->first)
		return false;
	bvhlab_box_empty(lo, hi);
	for (uint32_t k = n->first; k < n->first + n->count; k++) {
		uint32_t p = r->prim_index[k];
		if (p >= r->prim_count)
			return false;
		for (int a = 0; a < 3; a++) {
			lo[a] = bvhlab_minf(r->boxes[p].lo[a], lo[a]);
			hi[a] = bvhlab_maxf(r->boxes[p].hi[a], hi[a]);
		}
	}
	memcpy(n->lo, lo, sizeof(lo));
	memcpy(n->hi, hi, sizeof(hi));
	return true;
}

/* An inner node's box from its two (refitted) children. */
static void refit_inner(refit *r, bvhlab_node *n)
{
	const bvhlab_node *a = &r->nodes[n->first], *b = &r->nodes[n->first + 1];
	for (int k = 0; k < 3; k++) {
		n->lo[k] = bvhlab_minf(a->lo[k], b->lo[k]);
		n->hi[k] = bvhlab_maxf(a->hi[k], b->hi[k]);
	}
}

static bool has_children(const refit *r, const bvhlab_node *n)
{
	return n->first < r->node_count && r->node_count - n->first >= 2;
}

/* Post-order over one subtree; a cycle shows as more expansions than nodes. */
static enum refit_fault refit_subtree(refit *r, uint32_t root, struct stack *s)
{
	uint64_t expanded = 0;
	s->size = 0;
	if (!push(s, root, 0))
		return FAULT_MEMORY;
	while (s->size) {
		struct entry e = s->e[--s->size];
		bvhlab_node *n = &r->nodes[e.node];
		if (n->count) {
			continue; /* the leaf pass did it */
		} else if (e.children_done) {
			refit_inner(r, n);
		} else {
			if (!has_children(r, n) || ++expanded > r->node_count)
				return FAULT_SHAPE;
			/* The children are read next: their line is on its way meanwhile. */
			__builtin_prefetch(&r->nodes[n->first]);
			if (!push(s, e.node, 1) || !push(s, n->first, 0) || !push(s, n->first + 1, 0))
				return FAULT_MEMORY;
		}
	}
	return FAULT_NONE;
}

/* The leaf pass of the ordered sweep; also notes an inner node whose
 * children are not after it (the sweep then cannot be used). */
static void leaves_member(void *arg, unsigned t)
{
	refit *r = arg;
	uint32_t lo, hi;
	bool unordered = false;
	if (BVHLAB_HOST_HAS(r->host, pin_thread))
		r->host->pin_thread(r->ctx, t);
	while (team_next_block(&r->next, r->node_count, SWEEP_BLOCK, &lo, &hi)) {
		for (uint32_t i = lo; i < hi; i++) {
			bvhlab_node *n = &r->nodes[i];
			if (n->count && !refit_leaf(r, n)) {
				fault(r, FAULT_PRIM);
				return;
			}
			unordered = unordered || (!n->count && (n->first <= i || !has_children(r, n)));
		}
	}
	if (unordered)
		atomic_store(&r->unordered, true);
}

/* Leaves in parallel, then inner nodes from the last to the first; false
 * when the tree's order does not allow it (nothing is then wrong yet). */
static int sweep(refit *r, unsigned threads, uint32_t cpus)
{
	int rc = 0;
	if (threads > 1)
		rc = team_run(&r->team, threads, cpus, leaves_member, r);
	else
		leaves_member(r, 0);
	if (rc < 0 || atomic_load(&r->fault) || atomic_load(&r->unordered))
		return rc;
	for (uint32_t i = r->node_count; i-- > 0;)
		if (!r->nodes[i].count)
			refit_inner(r, &r->nodes[i]);
	return 0;
}

static void member(void *arg, unsigned t)
{
	refit *r = arg;
	struct stack s = {0};
	uint32_t lo, hi;
	if (BVHLAB_HOST_HAS(r->host, pin_thread))
		r->host->pin_thread(r->ctx, t);
	while (team_next_block(&r->next, r->root_count, 1, &lo, &hi)) {
		enum refit_fault f = refit_subtree(r, r->roots[lo], &s);
		if (f != FAULT_NONE) {
			fault(r, f);
			break;
		}
	}
	free(s.e);
}

/* Cuts the tree breadth first until there are `want` subtrees (or only
 * leaves); a level that would overflow the arrays stops the cut. */
static bool cut(refit *r, uint32_t want)
{
	uint32_t level[CUT_MAX], next[CUT_MAX], count = 1, depth = 0;
	level[0] = 0;
	r->top_count = 0;
	while (count < want && depth++ < 64 && r->top_count + count <= CUT_MAX &&
	       2 * count <= CUT_MAX) {
		uint32_t m = 0, inner = 0;
		for (uint32_t k = 0; k < count; k++) {
			const bvhlab_node *n = &r->nodes[level[k]];
			if (n->count) {
				next[m++] = level[k];
				continue;
			}
			if (!has_children(r, n))
				return false;
			r->top[r->top_count++] = level[k];
			next[m++] = n->first;
			next[m++] = n->first + 1;
			inner++;
		}
		memcpy(level, next, m * sizeof(*level));
		count = m;
		if (!inner)
			break;
	}
	memcpy(r->roots, level, count * sizeof(*level));
	r->root_count = count;
	return true;
}

static const char *fault_text(unsigned f)
{
	return f == FAULT_PRIM    ? "a leaf references a primitive past the input's, or a slot "
	                            "past index_count (another triangle count?)"
	       : f == FAULT_SHAPE ? "an inner node's children are out of range, or the tree "
	                            "has a cycle"
	                          : "out of memory for the traversal stack";
}

static int update(const bvhlab_host *host, bvhlab_build_ctx *ctx,
                  const bvhlab_build_input *input, bvhlab_build_output *tree)
{
	refit *r = calloc(1, sizeof(*r));
	uint32_t threads = input->threads, most = 1 + tree->node_count / NODES_PER_THREAD;
	int rc = 0;
	if (!r) {
		host->set_error(ctx, "out of memory");
		return -ENOMEM;
	}
	*r = (refit){.host = host, .ctx = ctx, .boxes = input->prim_bounds,
	             .prim_count = input->prim_count, .nodes = tree->nodes,
	             .node_count = tree->node_count, .prim_index = tree->prim_index,
	             .index_count = tree->index_count};
	threads = threads < most ? threads : most;
	threads = threads > TEAM_MAX_THREADS ? TEAM_MAX_THREADS : threads;
	if (tree->node_count)
		rc = sweep(r, threads, host->hardware_threads(ctx));
	atomic_store(&r->next, 0);
	if (rc < 0 || atomic_load(&r->fault) || (tree->node_count && !atomic_load(&r->unordered))) {
		/* swept, or failed */
	} else if (tree->node_count == 0 || !cut(r, threads > 1 ? CUT_PER_THREAD * threads : 1)) {
		fault(r, FAULT_SHAPE);
	} else if (threads > 1) {
		rc = team_run(&r->team, threads, host->hardware_threads(ctx), member, r);
	} else {
		member(r, 0);
	}
	for (uint32_t k = r->top_count; rc == 0 && !atomic_load(&r->fault) && k-- > 0;)
		refit_inner(r, &r->nodes[r->top[k]]);
	if (rc < 0)
		host->set_error(ctx, "cannot set up the thread team");
	else if (atomic_load(&r->fault)) {
		host->set_error(ctx, "cannot refit: %s", fault_text(atomic_load(&r->fault)));
		rc = atomic_load(&r->fault) == FAULT_MEMORY ? -ENOMEM : -EINVAL;
	}
	free(r);
	return rc;
}

BVHLAB_PLUGIN(
	.name = "refit",
	.summary = "updates a tree after its primitives moved: boxes recomputed bottom-up, "
	           "shape kept (parallel over subtrees, deterministic)",
	.flags = BVHLAB_BUILDER_PARALLEL | BVHLAB_BUILDER_DETERMINISTIC,
	.update = update)
