/*
 * ploc: a parallel PLOC builder (Meister & Bittner 2018) with lbvh's SAH
 * collapse. The phases are described in ploc.h.
 *
 * This file: options, scratch memory, the first clusters, build().
 */
#include <errno.h>
#include <string.h>

#include <bvhlab/aabb.h>

#include "morton_front.h"
#include "ploc.h"
#include "plugin_options.h"

static const plugin_option options[] = {
	PLUGIN_OPTION(ploc, radius, U32, .name = "radius",
	              .help = "search radius: clusters on either side, in Morton order, that "
	                      "each cluster compares with",
	              .def_int = 16, .min = 1, .max = PLOC_MAX_RADIUS),
	MORTON_OPTIONS(ploc, sort.bits),
};
PLUGIN_DECLS(options, ploc, NULL)

/* ---- scratch ------------------------------------------------------------ */

/* Clusters (two sets of six arrays and a record array), nn, the merge
 * tree, desc and the emit phase's tasks: past the tree in the output when
 * the host gives the room, which it keeps between builds (fresh pages
 * cost more than a phase). */
static size_t work_size(size_t n)
{
	return 2 * (6 * morton_align64(4 * n) + morton_align64(sizeof(struct cluster_meta) * n)) +
	       morton_align64(4 * n) +
	       morton_align64(sizeof(bvhlab_node) * (2 * n)) +
	       morton_align64(4 * 2 * n) + morton_align64(sizeof(struct place) * n);
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

static void place_clusters(struct clusters *c, char **at, size_t n)
{
	for (int a = 0; a < 3; a++) {
		c->lo[a] = (float *)(void *)take(at, 4 * n);
		c->hi[a] = (float *)(void *)take(at, 4 * n);
	}
	c->meta = (struct cluster_meta *)(void *)take(at, sizeof(*c->meta) * n);
}

static void place_work(ploc *p, char *at)
{
	size_t n = p->n;

	place_clusters(&p->cl[0], &at, n);
	place_clusters(&p->cl[1], &at, n);
	p->nn = (uint32_t *)(void *)take(&at, 4 * n);
	p->tree = (bvhlab_node *)(void *)take(&at, sizeof(bvhlab_node) * 2 * n);
	p->desc = (uint32_t *)(void *)take(&at, 4 * 2 * n);
	p->tasks = (struct place *)(void *)take(&at, sizeof(struct place) * n);
}

/* The sort's buffers: in the output's first nodes, which only the emit
 * phase writes, after the sort is read for the last time. */
static int scratch_alloc(ploc *p, const bvhlab_build_output *out, morton_scratch *s)
{
	char *work = morton_scratch_place(s, out, p->n, work_size(p->n), spare_nodes(p->n),
	                                  &p->sort, p->threads, 2, &p->count, NULL);

	if (!work)
		return -ENOMEM;
	place_work(p, work);
	return 0;
}

/* ---- phases -------------------------------------------------------------- */

/* Boxes read ahead of the gather by sorted position: in Morton order
 * they are scattered over the input, and no hardware prefetcher guesses
 * that pattern. */
#define GATHER_AHEAD 16

/* One cluster per primitive, in sorted order: a primitive record. */
static void first_clusters(ploc *p, unsigned t)
{
	struct clusters *c = &p->cl[0];
	uint32_t lo, hi;

	team_chunk(p->team.threads, t, p->n, &lo, &hi);
	for (uint32_t k = lo; k < hi; k++) {
		uint32_t id = morton_id(&p->sort, k);
		const bvhlab_aabb *box = &p->in->prim_bounds[id];

		if (k + GATHER_AHEAD < hi)
			__builtin_prefetch(&p->in->prim_bounds[morton_id(&p->sort, k + GATHER_AHEAD)]);
		for (int a = 0; a < 3; a++) {
			c->lo[a][k] = box->lo[a];
			c->hi[a][k] = box->hi[a];
		}
		c->meta[k] = (struct cluster_meta){id, 1 | REC_PRIM,
		                                   p->c_isect * bvhlab_aabb_half_area(box), 0};
	}
}

static void run_phases(void *arg, unsigned t)
{
	ploc *p = arg;

	if (t == 0)
		p->phase_ms[3] = morton_now_ms();
	morton_sort_team(&p->sort, &p->team, t, NULL, NULL);
	first_clusters(p, t);
	team_sync(&p->team);
	if (t == 0)
		p->phase_ms[0] = morton_now_ms();
	ploc_cluster(p, t);
	if (t == 0)
		p->phase_ms[1] = morton_now_ms();
	ploc_emit(p, t);
	if (t == 0)
		p->phase_ms[2] = morton_now_ms();
}

/* ---- build --------------------------------------------------------------- */

static int build_team(const bvhlab_host *host, bvhlab_build_ctx *ctx, ploc *p,
                      bvhlab_build_output *out)
{
	morton_scratch s = { 0 };
	double start = morton_now_ms();
	team_host th;
	int rc;

	p->threads = morton_team_size(p->in);
	p->emit_cut = p->n / (PLOC_EMIT_TASKS * p->threads);
	p->emit_cut = p->emit_cut ? p->emit_cut : 1;
	p->sort.n = p->n;
	p->sort.centroids = p->in->centroids;
	p->sort.centroid_bounds = p->in->centroid_bounds;
	if ((rc = scratch_alloc(p, out, &s)) < 0) {
		host->set_error(ctx, "out of memory for the scratch of %u primitives", p->n);
		goto out;
	}
	p->nodes = out->nodes;
	p->prim_index = out->prim_index;
	team_host_init(&th, host, ctx);
	if ((rc = team_run_on(&p->team, &th, p->threads, run_phases, p)) < 0) {
		host->set_error(ctx, "cannot set up the thread team");
		goto out;
	}
	out->node_count = p->node_count;
	out->index_count = p->n;
	host->log(ctx, BVHLAB_LOG_DEBUG, "%u prims, %u threads, %u iterations: setup %.2f, "
	          "sort %.2f, cluster %.2f, emit %.2f ms", p->n, p->team.threads, p->iterations,
	          p->phase_ms[3] - start, p->phase_ms[0] - p->phase_ms[3],
	          p->phase_ms[1] - p->phase_ms[0], p->phase_ms[2] - p->phase_ms[1]);
out:
	morton_scratch_free(&s);
	return rc;
}

static int build(const bvhlab_host *host, bvhlab_build_ctx *ctx,
                 const bvhlab_build_input *input, bvhlab_build_output *output)
{
	ploc p;
	int rc;

	if (input->prim_count == 0 || input->prim_count > REC_PRIMS) {
		host->set_error(ctx, "cannot build over %u primitives", input->prim_count);
		return -EINVAL;
	}
	/* The options first: the copy sets the whole struct, the rest zero. */
	if ((rc = PLUGIN_OPTIONS_GET(host, ctx, input, &p)) < 0)
		return rc;
	p.in = input;
	p.n = input->prim_count;
	if ((rc = big_ensure_output(host, ctx, p.n, spare_nodes(p.n), output)) < 0)
		return rc;
	if (input->prim_count == 1) {
		morton_single_leaf(input, output);
		return 0;
	}
	return build_team(host, ctx, &p, output);
}

PLUGIN_WITH_OPTIONS(options, .name = "ploc",
	.flags = BVHLAB_BUILDER_PARALLEL | BVHLAB_BUILDER_DETERMINISTIC |
	         BVHLAB_BUILDER_BOXES,
	.summary = "parallel locally-ordered clustering (Meister & Bittner 2018) from Morton "
	           "order, SAH collapse",
	.build = build,
	.peak_bytes_per_prim = 256 /* measured 190-232 */)
