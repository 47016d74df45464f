/*
 * lbvh: a parallel LBVH builder. Primitives are sorted along a Morton curve
 * of their centroids and the hierarchy is emitted from the sorted codes
 * (Karras 2012); an SAH pass then collapses small subtrees into leaves.
 * The phases are described in lbvh.h.
 *
 * This file: options, scratch memory, the thread team, build().
 */
#include <errno.h>
#include <string.h>

#include "lbvh.h"
#include "morton_front.h"

static const plugin_option options[] = { MORTON_OPTIONS(lbvh, bits) };
PLUGIN_DECLS(options, lbvh, NULL)

/* Nodes past the tree's 2n - 1 that hold the hierarchy's scratch (see
 * scratch_alloc()); 0 when that would not fit a uint32_t count. */
static uint32_t spare_nodes(uint32_t n, bool collapse);

/*
 * Room for the tree, and past it for the scratch of the hierarchy (see
 * big_spare_nodes()). Without that room the scratch is mapped afresh
 * (scratch_alloc()).
 */
static int ensure_capacity(const bvhlab_host *host, bvhlab_build_ctx *ctx,
                           const lbvh *b, bvhlab_build_output *out)
{
	return big_ensure_output(host, ctx, b->n, spare_nodes(b->n, b->collapse), out);
}

/* ---- scratch ------------------------------------------------------------ */

/* The hierarchy's arrays; node_flags only with collapse. */
static size_t tree_size(size_t n, bool collapse)
{
	return morton_align64(n + 2 * LCP_PAD) + morton_align64(8 * n) +
	       2 * morton_align64(4 * n) + (collapse ? morton_align64(n) : 0);
}

static uint32_t spare_nodes(uint32_t n, bool collapse)
{
	return big_spare_nodes(n, tree_size(n, collapse));
}

static void place_tree(lbvh *b, char *p)
{
	size_t n = b->n;

	b->lcp = (uint8_t *)p + LCP_PAD;
	p += morton_align64(n + 2 * LCP_PAD);
	b->parent = (uint32_t *)(void *)p;
	p += morton_align64(8 * n);
	b->end = (uint32_t *)(void *)p;
	p += morton_align64(4 * n);
	b->visits = (atomic_uint *)(void *)p;
	p += morton_align64(4 * n);
	b->node_flags = b->collapse ? (uint8_t *)p : NULL;
}

/*
 * The hierarchy's arrays go past the tree in the output when the host
 * gave the room (ensure_capacity()), else into the fresh mapping; there
 * the arrival counters and flags start zeroed, in the output the sort
 * phase zeroes them (scratch_dirty).
 *
 * The sort's buffers live in the output node array when it is large enough
 * (always but for a few primitives): the host keeps that array between
 * builds, so it is paged in already, and the tree is written into it only
 * after the sort. Fresh pages cost more than the sort passes themselves.
 */
static int scratch_alloc(lbvh *b, const bvhlab_build_output *out, morton_scratch *s)
{
	char *tree = morton_scratch_place(s, out, b->n, tree_size(b->n, b->collapse),
	                                  spare_nodes(b->n, b->collapse), &b->sort, b->threads, 3,
	                                  &b->count, &b->scratch_dirty);

	if (!tree)
		return -ENOMEM;
	place_tree(b, tree);
	return 0;
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
			b->phase_ms[k] = morton_now_ms();
	}
}

/* ---- build --------------------------------------------------------------- */

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
	morton_scratch s = { 0 };
	double start = morton_now_ms();
	team_host th;
	int rc;

	b->threads = morton_team_size(b->in);
	b->sort.n = b->n;
	b->sort.bits = b->bits;
	b->sort.centroids = b->in->centroids;
	b->sort.centroid_bounds = b->in->centroid_bounds;
	if ((rc = scratch_alloc(b, out, &s)) < 0) {
		host->set_error(ctx, "out of memory for the scratch of %u primitives", b->n);
		goto out;
	}
	b->phase_ms[4] = morton_now_ms();
	team_host_init(&th, host, ctx);
	if ((rc = team_run_on(&b->team, &th, b->threads, run_phases, b)) < 0) {
		host->set_error(ctx, "cannot set up the thread team");
		goto out;
	}
	out->node_count = b->node_count;
	out->index_count = b->n;
	log_phases(host, ctx, b, start);
out:
	morton_scratch_free(&s);
	return rc;
}

static int build(const bvhlab_host *host, bvhlab_build_ctx *ctx,
                 const bvhlab_build_input *input, bvhlab_build_output *output)
{
	lbvh b;
	int rc;

	if (input->prim_count == 0 || input->prim_count > UINT32_MAX / 2) {
		host->set_error(ctx, "cannot build over %u primitives", input->prim_count);
		return -EINVAL;
	}
	/* The options first: the copy sets the whole struct, the rest zero. */
	if ((rc = PLUGIN_OPTIONS_GET(host, ctx, input, &b)) < 0)
		return rc;
	b.in = input;
	b.n = input->prim_count;
	if ((rc = ensure_capacity(host, ctx, &b, output)) < 0)
		return rc;
	if (input->prim_count == 1) {
		morton_single_leaf(input, output);
		return 0;
	}
	b.nodes = output->nodes;
	b.prim_index = output->prim_index;
	return build_team(host, ctx, &b, output);
}

PLUGIN_WITH_OPTIONS(options, .name = "lbvh",
	.flags = BVHLAB_BUILDER_PARALLEL | BVHLAB_BUILDER_DETERMINISTIC |
	         BVHLAB_BUILDER_BOXES,
	.summary = "parallel LBVH: Morton codes, radix sort, Karras 2012 emission, SAH collapse",
	.build = build,
	.peak_bytes_per_prim = 100 /* measured 86-88 per triangle (issue 44) */)
