/*
 * hploc: H-PLOC (Benthin et al. 2024) on the CPU, with lbvh's SAH
 * collapse. The phases are described in hploc.h.
 *
 * This file: options, scratch memory, the first clusters, build().
 */
#include <errno.h>
#include <string.h>

#include "hploc.h"
#include "morton_front.h"
#include "plugin_options.h"

static const plugin_option options[] = {
	HPLOC_OPTIONS(hploc),
	MORTON_OPTIONS(hploc, sort.bits),
};
PLUGIN_DECLS(options, hploc, NULL)

/* ---- scratch ------------------------------------------------------------ */

/* Clusters, records, idx, count, meet and the emit tasks: past the tree
 * in the output when the host gives the room (kept between builds), else
 * mapped. */
static size_t work_size(size_t n)
{
	return 2 * morton_align64(sizeof(hploc_cluster) * n) + 3 * morton_align64(4 * n) +
	       morton_align64(sizeof(hploc_place) * n);
}

static uint32_t spare_nodes(uint32_t n)
{
	return big_spare_nodes(n, work_size(n));
}

static char *take(char **at, size_t bytes)
{
	char *p = *at;

	*at += morton_align64(bytes);
	return p;
}

static int scratch_alloc(hploc *h, const bvhlab_build_output *out, morton_scratch *s)
{
	uint32_t *unused;
	size_t n = h->n;
	char *at = morton_scratch_place(s, out, h->n, work_size(n), spare_nodes(h->n), &h->sort,
	                                h->threads, 0, &unused, NULL);

	if (!at)
		return -ENOMEM;
	h->cl = (hploc_cluster *)(void *)take(&at, sizeof(hploc_cluster) * n);
	h->rec = (hploc_rec *)(void *)take(&at, sizeof(hploc_rec) * n);
	h->idx = (uint32_t *)(void *)take(&at, 4 * n);
	h->count = (uint32_t *)(void *)take(&at, 4 * n);
	h->meet = (atomic_uint *)(void *)take(&at, 4 * n);
	h->tasks = (hploc_place *)(void *)take(&at, sizeof(hploc_place) * n);
	return 0;
}

/* ---- phases -------------------------------------------------------------- */

/* One cluster per primitive, in sorted order, each its own range; no
 * arrival yet anywhere. */
static void first_clusters(hploc *h, unsigned t)
{
	uint32_t lo, hi;

	team_chunk(h->team.threads, t, h->n, &lo, &hi);
	for (uint32_t k = lo; k < hi; k++) {
		uint32_t id = morton_id(&h->sort, k);
		const bvhlab_aabb *b = &h->in->prim_bounds[id];
		hploc_cluster *c = &h->cl[k];

		memcpy(c->lo, b->lo, sizeof(c->lo));
		memcpy(c->hi, b->hi, sizeof(c->hi));
		c->node = HPLOC_LEAF | id;
		c->info = 1;
		c->cost = h->c_isect * hploc_half_area(c->lo, c->hi);
		c->desc = 0;
		h->idx[k] = k;
		h->count[k] = 1;
		atomic_init(&h->meet[k], HPLOC_NONE);
	}
}

/* The merge tree into the output: thread 0 the nodes above the subtrees
 * of at most n / (HPLOC_EMIT_TASKS x T) primitives, then the team those
 * subtrees. */
static void emit(hploc *h, unsigned t)
{
	hploc_tree tree = { h->n, h->rec, h->root, h->in->prim_bounds };
	uint32_t cut = h->n / (HPLOC_EMIT_TASKS * h->team.threads), lo, hi;

	if (t == 0) {
		h->task_count = hploc_emit_top(&tree, h->out, cut ? cut : 1, h->tasks,
		                               &h->node_count);
		atomic_store_explicit(&h->blocks, 0, memory_order_relaxed);
	}
	team_sync(&h->team);
	while (team_next_block(&h->blocks, h->task_count, 1, &lo, &hi))
		hploc_emit_task(&tree, h->out, h->tasks[lo]);
	team_sync(&h->team);
}

static void run_phases(void *arg, unsigned t)
{
	hploc *h = arg;

	if (t == 0)
		h->phase_ms[3] = morton_now_ms();
	morton_sort_team(&h->sort, &h->team, t, NULL, NULL);
	first_clusters(h, t);
	team_sync(&h->team);
	if (t == 0)
		h->phase_ms[0] = morton_now_ms();
	hploc_climb(h, t);
	if (t == 0)
		h->phase_ms[1] = morton_now_ms();
	emit(h, t);
	if (t == 0)
		h->phase_ms[2] = morton_now_ms();
}

/* ---- build --------------------------------------------------------------- */

static int build_team(const bvhlab_host *host, bvhlab_build_ctx *ctx, hploc *h,
                      bvhlab_build_output *out)
{
	morton_scratch s = { 0 };
	double start = morton_now_ms();
	team_host th;
	int rc;

	h->threads = morton_team_size(h->in);
	h->sort.n = h->n;
	h->sort.centroids = h->in->centroids;
	h->sort.centroid_bounds = h->in->centroid_bounds;
	if ((rc = scratch_alloc(h, out, &s)) < 0) {
		host->set_error(ctx, "out of memory for the scratch of %u primitives", h->n);
		goto out;
	}
	h->out = out;
	team_host_init(&th, host, ctx);
	if ((rc = team_run_on(&h->team, &th, h->threads, run_phases, h)) < 0) {
		host->set_error(ctx, "cannot set up the thread team");
		goto out;
	}
	out->node_count = h->node_count;
	out->index_count = h->n;
	host->log(ctx, BVHLAB_LOG_DEBUG, "%u prims, %u threads: setup %.2f, sort %.2f, "
	          "climb %.2f, emit %.2f ms", h->n, h->team.threads, h->phase_ms[3] - start,
	          h->phase_ms[0] - h->phase_ms[3], h->phase_ms[1] - h->phase_ms[0],
	          h->phase_ms[2] - h->phase_ms[1]);
out:
	morton_scratch_free(&s);
	return rc;
}

static int build(const bvhlab_host *host, bvhlab_build_ctx *ctx,
                 const bvhlab_build_input *input, bvhlab_build_output *output)
{
	hploc h;
	int rc;

	if (input->prim_count == 0 || input->prim_count > HPLOC_PRIMS) {
		host->set_error(ctx, "cannot build over %u primitives", input->prim_count);
		return -EINVAL;
	}
	/* The options first: the copy sets the whole struct, the rest zero. */
	if ((rc = PLUGIN_OPTIONS_GET(host, ctx, input, &h)) < 0)
		return rc;
	h.in = input;
	h.n = input->prim_count;
	if ((rc = big_ensure_output(host, ctx, h.n, spare_nodes(h.n), output)) < 0)
		return rc;
	h.merge = (hploc_params){ h.radius, h.collapse, h.max_leaf, h.c_trav, h.c_isect };
	if (input->prim_count == 1) {
		morton_single_leaf(input, output);
		return 0;
	}
	return build_team(host, ctx, &h, output);
}

PLUGIN_WITH_OPTIONS(options, .name = "hploc",
	.flags = BVHLAB_BUILDER_PARALLEL | BVHLAB_BUILDER_DETERMINISTIC,
	.summary = "H-PLOC (Benthin et al. 2024): PLOC merging inside the LBVH's subtrees, "
	           "bottom-up from Morton order, SAH collapse",
	.build = build,
	.peak_bytes_per_prim = 192 /* measured 134-168 */)
