/*
 * hlbvh: SAH over Morton clusters (see hlbvh.h). This file: options,
 * scratch, the team's phases, build().
 */
#include <errno.h>
#include <stdlib.h>
#include <string.h>

#include "hlbvh.h"
#include "morton_front.h"
#include "sah_split.h"

static const plugin_option options[] = {
	SAH_OPTIONS(hlbvh_options),
	PLUGIN_OPTION(hlbvh_options, cluster, U32, .name = "cluster",
	              .help = "most primitives in a Morton cluster: each is built whole by exact "
	                      "SAH, and the clusters are the primitives of the SAH top",
	              .def_int = 32, .min = 2, .max = SAH_SMALL_MAX),
};

static int check_options(const bvhlab_host *host, bvhlab_build_ctx *ctx, void *opt)
{
	return sah_options_resolve(host, ctx, &((hlbvh_options *)opt)->sah);
}
PLUGIN_DECLS(options, hlbvh_options, check_options)

/* ---- scratch ------------------------------------------------------------ */

/* The sorted records and the cluster bounds; past the tree in the output
 * when the host gives the room, which it keeps between builds (fresh
 * pages cost more than the gather itself). */
static size_t work_size(size_t n)
{
	return morton_align64(sizeof(sah_prim) * n) + morton_align64(4 * (n + 1));
}

static uint32_t spare_nodes(uint32_t n)
{
	return big_spare_nodes(n, work_size(n));
}

/* The sort's buffers go into the output's nodes, which only the top
 * writes, after the gather read the sort for the last time. */
static int scratch_alloc(hlbvh *h, morton_scratch *s, unsigned threads)
{
	uint32_t *counts;
	char *at = morton_scratch_place(s, h->out, h->n, work_size(h->n), spare_nodes(h->n),
	                                &h->sort, threads, 0, &counts, NULL);

	if (!at)
		return -ENOMEM;
	h->sorted = (sah_prim *)(void *)at;
	h->bounds = (uint32_t *)(void *)(at + morton_align64(sizeof(sah_prim) * h->n));
	return 0;
}

/* The per-cluster arrays, once the cut has counted the clusters. */
static int cluster_alloc(hlbvh *h)
{
	size_t cc = h->cluster_count;

	h->cbox = malloc(cc * sizeof(*h->cbox));
	h->ccen = malloc(3 * cc * sizeof(*h->ccen));
	h->slot = malloc(cc * sizeof(*h->slot));
	return h->cbox && h->ccen && h->slot ? 0 : -ENOMEM;
}

static void cluster_free(hlbvh *h)
{
	free(h->cbox);
	free(h->ccen);
	free(h->slot);
}

/* ---- phases -------------------------------------------------------------- */

/* Member 0's serial steps between barriers; a failure (out of memory)
 * leaves h->rc set and the other members skip the rest with it. */
static void serial_step(hlbvh *h, int step)
{
	if (h->rc == 0 && step == 0) {
		hlbvh_cut(h);
		h->rc = cluster_alloc(h);
	} else if (h->rc == 0) {
		h->rc = hlbvh_top(h);
	}
	atomic_store_explicit(&h->next, 0, memory_order_relaxed);
	h->ms[1 + step] = morton_now_ms();
}

static void run_phases(void *arg, unsigned t)
{
	hlbvh *h = arg;

	morton_sort_team(&h->sort, &h->team, t, NULL, NULL);
	if (t == 0)
		serial_step(h, 0);
	team_sync(&h->team);
	if (h->rc == 0)
		hlbvh_gather(h, t);
	team_sync(&h->team);
	if (t == 0)
		serial_step(h, 1);
	team_sync(&h->team);
	if (h->rc == 0)
		hlbvh_bottom(h, t);
}

/* ---- build --------------------------------------------------------------- */

static int build_team(const bvhlab_host *host, bvhlab_build_ctx *ctx, hlbvh *h)
{
	unsigned threads = morton_team_size(h->in);
	morton_scratch s = { 0 };
	team_host th;
	int rc;

	h->sort.n = h->n;
	h->sort.bits = 63;
	h->sort.centroids = h->in->centroids;
	h->sort.centroid_bounds = h->in->centroid_bounds;
	h->ms[0] = morton_now_ms();
	if ((rc = scratch_alloc(h, &s, threads)) < 0) {
		host->set_error(ctx, "out of memory for the scratch of %u primitives", h->n);
		goto out;
	}
	team_host_init(&th, host, ctx);
	h->th = &th;
	if ((rc = team_run_on(&h->team, &th, threads, run_phases, h)) < 0) {
		host->set_error(ctx, "cannot set up the thread team");
		goto out;
	}
	if ((rc = h->rc) < 0) {
		host->set_error(ctx, "out of memory for the top over %u clusters", h->cluster_count);
		goto out;
	}
	h->out->node_count = atomic_load(&h->bottom.node_counter);
	h->out->index_count = h->n;
	host->log(ctx, BVHLAB_LOG_DEBUG, "%u prims, %u clusters, %u threads: sort and cut "
	          "%.2f, gather and top %.2f, bottom %.2f ms", h->n, h->cluster_count,
	          h->team.threads, h->ms[1] - h->ms[0], h->ms[2] - h->ms[1],
	          morton_now_ms() - h->ms[2]);
out:
	cluster_free(h);
	morton_scratch_free(&s);
	return rc;
}

static int build(const bvhlab_host *host, bvhlab_build_ctx *ctx,
                 const bvhlab_build_input *input, bvhlab_build_output *output)
{
	hlbvh h = { .in = input, .out = output, .n = input->prim_count };
	int rc;

	if (input->prim_count == 0 || input->prim_count > UINT32_MAX / 2) {
		host->set_error(ctx, "cannot build over %u primitives", input->prim_count);
		return -EINVAL;
	}
	if ((rc = PLUGIN_OPTIONS_GET(host, ctx, input, &h.opt)) < 0 ||
	    (rc = big_ensure_output(host, ctx, h.n, spare_nodes(h.n), output)) < 0)
		return rc;
	if (input->prim_count == 1) {
		morton_single_leaf(input, output);
		return 0;
	}
	return build_team(host, ctx, &h);
}

PLUGIN_PARALLEL_BUILDER(options, 0, .name = "hlbvh",
	.summary = "SAH over Morton clusters (HLBVH, Garanzha et al. 2011): each cluster "
	           "built whole by exact SAH, the SAH top over the clusters",
	.peak_bytes_per_prim = 200 /* measured 78-178 */)
