/*
 * hlbvh: SAH over Morton clusters (see hlbvh.h). This file: options,
 * scratch, the phases, build() on morton_build.
 */
#include <errno.h>
#include <stdlib.h>
#include <string.h>

#include "hlbvh.h"
#include "morton_front.h"
#include "sah_split.h"

static const plugin_option options[] = {
	SAH_OPTIONS(hlbvh),
	PLUGIN_OPTION(hlbvh, cluster, U32, .name = "cluster",
	              .help = "most primitives in a Morton cluster: each is built whole by exact "
	                      "SAH, and the clusters are the primitives of the SAH top",
	              .def_int = 32, .min = 2, .max = SAH_SMALL_MAX),
};

static int check_options(const bvhlab_host *host, bvhlab_build_ctx *ctx, void *opt)
{
	return sah_options_resolve(host, ctx, &((hlbvh *)opt)->sah);
}
PLUGIN_DECLS(options, hlbvh, check_options)

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
static int scratch_alloc(void *arg, bvhlab_build_output *out, morton_scratch *s)
{
	hlbvh *h = arg;
	uint32_t *counts;
	char *at = morton_scratch_place(s, out, h->n, work_size(h->n), spare_nodes(h->n),
	                                &h->sort, h->threads, 0, &counts, NULL);

	if (!at)
		return -ENOMEM;
	h->out = out;
	h->sort.bits = 63;
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

static void cluster_free(void *arg)
{
	hlbvh *h = arg;

	free(h->cbox);
	free(h->ccen);
	free(h->slot);
}

/* ---- phases -------------------------------------------------------------- */

/* Member 0's serial steps, each with the team's barrier after it; a
 * failure (out of memory) leaves h->rc set and every member skips the
 * rest with it. */
static void cut(hlbvh *h, unsigned t)
{
	if (t == 0) {
		hlbvh_cut(h);
		h->rc = cluster_alloc(h);
		atomic_store_explicit(&h->next, 0, memory_order_relaxed);
	}
	team_sync(&h->team);
}

static void gather(hlbvh *h, unsigned t)
{
	if (h->rc == 0)
		hlbvh_gather(h, t);
	team_sync(&h->team);
}

static void top(hlbvh *h, unsigned t)
{
	if (t == 0) {
		if (h->rc == 0)
			h->rc = hlbvh_top(h);
		atomic_store_explicit(&h->next, 0, memory_order_relaxed);
	}
	team_sync(&h->team);
}

/* The last phase: the team's end is its barrier. */
static void bottom(hlbvh *h, unsigned t)
{
	if (h->rc == 0)
		hlbvh_bottom(h, t);
}

MORTON_PHASE_FN(hlbvh, cut)
MORTON_PHASE_FN(hlbvh, gather)
MORTON_PHASE_FN(hlbvh, top)
MORTON_PHASE_FN(hlbvh, bottom)

static const morton_phase phases[] = {
	{ "cut", cut_phase }, { "gather", gather_phase }, { "top", top_phase },
	{ "bottom", bottom_phase }, { NULL, NULL },
};

/* ---- build --------------------------------------------------------------- */

static int finish(void *arg, const bvhlab_host *host, bvhlab_build_ctx *ctx)
{
	hlbvh *h = arg;

	if (h->rc < 0) {
		host->set_error(ctx, "out of memory for the top over %u clusters", h->cluster_count);
		return h->rc;
	}
	h->node_count = atomic_load(&h->bottom.node_counter);
	return 0;
}

MORTON_BUILD_FN(hlbvh, .max_prims = UINT32_MAX / 2, .spare = spare_nodes(b.n),
                .place = scratch_alloc, .phases = phases, .count = &b.cluster_count,
                .count_name = "clusters", .th = &b.th, .finish = finish,
                .cleanup = cluster_free)

PLUGIN_PARALLEL_BUILDER(options, 0, .name = "hlbvh",
	.summary = "SAH over Morton clusters (HLBVH, Garanzha et al. 2011): each cluster "
	           "built whole by exact SAH, the SAH top over the clusters",
	.peak_bytes_per_prim = 200 /* measured 78-178 */)
