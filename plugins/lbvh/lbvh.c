/*
 * lbvh: a parallel LBVH builder. Primitives are sorted along a Morton curve
 * of their centroids and the hierarchy is emitted from the sorted codes
 * (Karras 2012); an SAH pass then collapses small subtrees into leaves.
 * The phases are described in lbvh.h.
 *
 * This file: options, scratch memory, the thread team, build().
 */
#include <errno.h>
#include <stdlib.h>
#include <string.h>
#include <time.h>

#include "big_alloc.h"
#include "lbvh.h"

static const bvhlab_option_decl options[] = {
	{ .name = "bits", .type = BVHLAB_OPTION_INT,
	  .help = "Morton code length: 30 (10 bits per axis) or 63 (21 bits per axis)",
	  .def_int = 63, .min = 30, .max = 63 },
	{ .name = "collapse", .type = BVHLAB_OPTION_BOOL,
	  .help = "turn subtrees of at most max_leaf primitives into leaves where the SAH "
	          "says a leaf is cheaper (off: one primitive per leaf)",
	  .def_bool = true },
	{ .name = "max_leaf", .type = BVHLAB_OPTION_INT,
	  .help = "most primitives in a collapsed leaf (8, as the SAH builders)",
	  .def_int = 8, .min = 1, .max = 64 },
	{ .name = "c_trav", .type = BVHLAB_OPTION_FLOAT,
	  .help = "SAH cost of traversing an inner node (> 0), for collapse",
	  .def_float = 1.0, .min = 1e-6, .max = 1e6 },
	{ .name = "c_isect", .type = BVHLAB_OPTION_FLOAT,
	  .help = "SAH cost of intersecting one primitive (> 0), for collapse",
	  .def_float = 1.0, .min = 1e-6, .max = 1e6 },
};

#define OPTION_COUNT (sizeof(options) / sizeof(options[0]))

/* Below this many primitives per thread, more threads cost more than they
 * save (thread start and barriers are tens of microseconds). */
#define MIN_PRIMS_PER_THREAD 512

static double now_ms(void)
{
	struct timespec ts;

	clock_gettime(CLOCK_MONOTONIC, &ts);
	return ts.tv_sec * 1e3 + ts.tv_nsec / 1e6;
}

static int read_options(const bvhlab_host *host, bvhlab_build_ctx *ctx, lbvh *b)
{
	int64_t bits, max_leaf;
	double c_trav, c_isect;
	int rc;

	if ((rc = host->option_int(ctx, "bits", &bits)) < 0 ||
	    (rc = host->option_bool(ctx, "collapse", &b->collapse)) < 0 ||
	    (rc = host->option_int(ctx, "max_leaf", &max_leaf)) < 0 ||
	    (rc = host->option_float(ctx, "c_trav", &c_trav)) < 0 ||
	    (rc = host->option_float(ctx, "c_isect", &c_isect)) < 0) {
		host->set_error(ctx, "cannot read the options");
		return rc;
	}
	if (bits != 30 && bits != 63) {
		host->set_error(ctx, "option bits: %lld, expected 30 or 63", (long long)bits);
		return -EINVAL;
	}
	if (max_leaf < 1 || max_leaf > 64 || !(c_trav > 0) || !(c_isect > 0)) {
		host->set_error(ctx, "options max_leaf, c_trav or c_isect out of range");
		return -EINVAL;
	}
	b->bits = (unsigned)bits;
	b->max_leaf = (uint32_t)max_leaf;
	b->c_trav = (float)c_trav;
	b->c_isect = (float)c_isect;
	return 0;
}

/* Nodes past the tree's 2n - 1 that hold the hierarchy's scratch (see
 * scratch_alloc()); 0 when that would not fit a uint32_t count. */
static uint32_t spare_nodes(uint32_t n, bool collapse);

/*
 * Room for the tree, and past it for the scratch of the hierarchy, which
 * the host keeps between builds: a fresh mapping would be paged in (and
 * zeroed by the kernel) at every build. Without that room the scratch is
 * mapped afresh (scratch_alloc()).
 */
static int ensure_capacity(const bvhlab_host *host, bvhlab_build_ctx *ctx,
                           const lbvh *b, bvhlab_build_output *out)
{
	uint32_t nodes = 2 * b->n - 1, spare = spare_nodes(b->n, b->collapse);

	if (spare && out->node_capacity < nodes + spare)
		(void)host->grow_output(ctx, out, nodes + spare, b->n); /* fine if refused */
	if (out->node_capacity >= nodes && out->index_capacity >= b->n)
		return 0;
	if (host->grow_output(ctx, out, nodes, b->n) < 0) {
		host->set_error(ctx, "cannot grow the output to %u nodes", nodes);
		return -ENOMEM;
	}
	return 0;
}

/* ---- scratch ------------------------------------------------------------ */

struct scratch {
	void *region;      /* one huge-page mapping (big_alloc), or NULL */
	void *small;       /* hist, bucket, count */
};

static size_t align64(size_t x)
{
	return (x + 63) & ~(size_t)63;
}

/*
 * The sort's buffers live in the output node array when it is large enough
 * (always but for a few primitives): the host keeps that array between
 * builds, so it is paged in already, and the tree is written into it only
 * after the sort. Fresh pages cost more than the sort passes themselves.
 */
static size_t sort_size(size_t n)
{
	return 3 * align64(8 * n);
}

static void place_sort(lbvh *b, char *p)
{
	size_t k8 = align64(8 * (size_t)b->n);

	b->sort.codes = (uint64_t *)(void *)p;
	b->sort.keys[0] = (uint64_t *)(void *)(p + k8);
	b->sort.keys[1] = (uint64_t *)(void *)(p + 2 * k8);
}

/* The hierarchy's arrays; node_flags only with collapse. */
static size_t tree_size(size_t n, bool collapse)
{
	return align64(n + 2 * LCP_PAD) + align64(8 * n) + 2 * align64(4 * n) +
	       (collapse ? align64(n) : 0);
}

static uint32_t spare_nodes(uint32_t n, bool collapse)
{
	uint64_t spare = (tree_size(n, collapse) + 64 + sizeof(bvhlab_node) - 1) /
	                 sizeof(bvhlab_node);

	return 2 * (uint64_t)n - 1 + spare > UINT32_MAX ? 0 : (uint32_t)spare;
}

static void place_tree(lbvh *b, char *p)
{
	size_t n = b->n;

	b->lcp = (uint8_t *)p + LCP_PAD;
	p += align64(n + 2 * LCP_PAD);
	b->parent = (uint32_t *)(void *)p;
	p += align64(8 * n);
	b->end = (uint32_t *)(void *)p;
	p += align64(4 * n);
	b->visits = (atomic_uint *)(void *)p;
	p += align64(4 * n);
	b->node_flags = b->collapse ? (uint8_t *)p : NULL;
}

/*
 * The hierarchy's arrays go past the tree in the output when the host
 * gave the room (ensure_capacity()), else into the fresh mapping; there
 * the arrival counters and flags start zeroed, in the output the sort
 * phase zeroes them (scratch_dirty).
 */
static int scratch_alloc(lbvh *b, const bvhlab_build_output *out, struct scratch *s)
{
	size_t sort = sort_size(b->n), tree = tree_size(b->n, b->collapse);
	size_t hist = (size_t)b->threads * MORTON_TOP_RADIX * sizeof(uint32_t) +
	              (MORTON_TOP_RADIX + 1) * sizeof(uint32_t);
	uint32_t nodes = 2 * b->n - 1, spare = spare_nodes(b->n, b->collapse);
	bool sort_out = (size_t)out->node_capacity * sizeof(bvhlab_node) >= sort;
	bool tree_out = spare && out->node_capacity >= nodes + spare;
	uintptr_t past = (uintptr_t)(out->nodes + nodes);

	size_t region = (tree_out ? 0 : tree) + (sort_out ? 0 : sort);

	/* Zero-filled, which the arrival counters rely on when they live here;
	 * the threads touch it first, each its own chunk, sharing the faults. */
	s->region = region ? big_alloc(region) : NULL;
	s->small = malloc(hist + (size_t)b->threads * 3 * sizeof(uint32_t));
	if ((region && !s->region) || !s->small)
		return -ENOMEM;
	b->scratch_dirty = tree_out;
	place_tree(b, tree_out ? (char *)((past + 63) & ~(uintptr_t)63) : (char *)s->region);
	place_sort(b, sort_out ? (char *)out->nodes : (char *)s->region + (tree_out ? 0 : tree));
	b->sort.hist = s->small;
	b->sort.bucket = (uint32_t *)(void *)(b->sort.hist + b->threads);
	b->count = b->sort.bucket + MORTON_TOP_RADIX + 1;
	return 0;
}

static void scratch_free(struct scratch *s)
{
	big_free(s->region);
	free(s->small);
}

/* ---- the team ------------------------------------------------------------ */

static void run_phases(void *arg, unsigned t)
{
	static void (*const phase[])(lbvh *, unsigned) = {
		lbvh_sort, lbvh_karras, lbvh_bounds, lbvh_compact,
	};
	lbvh *b = arg;

	for (size_t k = 0; k < sizeof(phase) / sizeof(phase[0]); k++) {
		phase[k](b, t);
		if (t == 0)
			b->phase_ms[k] = now_ms();
	}
}

static unsigned team_size(const bvhlab_build_input *in)
{
	uint32_t most = in->prim_count / MIN_PRIMS_PER_THREAD;
	uint32_t want = in->threads < most ? in->threads : most;

	return want < 1 ? 1 : want > TEAM_MAX_THREADS ? TEAM_MAX_THREADS : want;
}

/* ---- build --------------------------------------------------------------- */

static void single_leaf(const bvhlab_build_input *in, bvhlab_build_output *out)
{
	bvhlab_node *root = &out->nodes[0];

	for (int k = 0; k < 3; k++) {
		root->lo[k] = in->prim_bounds[0].lo[k];
		root->hi[k] = in->prim_bounds[0].hi[k];
	}
	root->first = 0;
	root->count = 1;
	out->prim_index[0] = 0;
	out->node_count = 1;
	out->index_count = 1;
}

static void log_phases(const bvhlab_host *host, bvhlab_build_ctx *ctx, const lbvh *b,
                       double start)
{
	host->log(ctx, BVHLAB_LOG_DEBUG,
	          "%u prims, %u threads: setup %.2f, sort %.2f, karras %.2f, "
	          "bounds %.2f, compact %.2f ms", b->n, b->team.threads, b->phase_ms[4] - start,
	          b->phase_ms[0] - b->phase_ms[4], b->phase_ms[1] - b->phase_ms[0],
	          b->phase_ms[2] - b->phase_ms[1], b->phase_ms[3] - b->phase_ms[2]);
}

static int build_team(const bvhlab_host *host, bvhlab_build_ctx *ctx, lbvh *b,
                      bvhlab_build_output *out)
{
	struct scratch s = { 0 };
	double start = now_ms();
	int rc;

	b->threads = team_size(b->in);
	b->sort.n = b->n;
	b->sort.bits = b->bits;
	b->sort.centroids = b->in->centroids;
	b->sort.centroid_bounds = b->in->centroid_bounds;
	if ((rc = scratch_alloc(b, out, &s)) < 0) {
		host->set_error(ctx, "out of memory for the scratch of %u primitives", b->n);
		goto out;
	}
	b->phase_ms[4] = now_ms();
	if ((rc = team_run(&b->team, b->threads, host->hardware_threads(ctx), run_phases,
	                   b)) < 0) {
		host->set_error(ctx, "cannot set up the thread team");
		goto out;
	}
	out->node_count = b->node_count;
	out->index_count = b->n;
	log_phases(host, ctx, b, start);
out:
	scratch_free(&s);
	return rc;
}

static int build(const bvhlab_host *host, bvhlab_build_ctx *ctx,
                 const bvhlab_build_input *input, bvhlab_build_output *output)
{
	lbvh b = { .in = input, .n = input->prim_count };
	int rc;

	if (input->prim_count == 0 || input->prim_count > UINT32_MAX / 2) {
		host->set_error(ctx, "cannot build over %u primitives", input->prim_count);
		return -EINVAL;
	}
	if ((rc = read_options(host, ctx, &b)) < 0 ||
	    (rc = ensure_capacity(host, ctx, &b, output)) < 0)
		return rc;
	if (input->prim_count == 1) {
		single_leaf(input, output);
		return 0;
	}
	b.nodes = output->nodes;
	b.prim_index = output->prim_index;
	return build_team(host, ctx, &b, output);
}

BVHLAB_PLUGIN(.name = "lbvh", .flags = BVHLAB_BUILDER_PARALLEL | BVHLAB_BUILDER_DETERMINISTIC,
	.summary = "parallel LBVH: Morton codes, radix sort, Karras 2012 emission, SAH collapse",
	.option_count = OPTION_COUNT, .options = options, .build = build)
