/*
 * ploc: a parallel PLOC builder (Meister & Bittner 2018) with lbvh's SAH
 * collapse. The phases are described in ploc.h.
 *
 * This file: options, scratch memory, the first clusters, build() on
 * morton_build.
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
static int scratch_alloc(void *arg, bvhlab_build_output *out, morton_scratch *s)
{
	ploc *p = arg;
	char *work = morton_scratch_place(s, out, p->n, work_size(p->n), spare_nodes(p->n),
	                                  &p->sort, p->threads, 2, &p->count, NULL);

	if (!work)
		return -ENOMEM;
	place_work(p, work);
	p->nodes = out->nodes;
	p->prim_index = out->prim_index;
	p->emit_cut = p->n / (PLOC_EMIT_TASKS * p->threads);
	p->emit_cut = p->emit_cut ? p->emit_cut : 1;
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

MORTON_PHASE_FN(ploc, first_clusters)
MORTON_PHASE_FN(ploc, ploc_cluster)
MORTON_PHASE_FN(ploc, ploc_emit)

static const morton_phase phases[] = {
	{ "cluster", ploc_cluster_phase }, { "emit", ploc_emit_phase }, { NULL, NULL },
};

/* ---- build --------------------------------------------------------------- */

MORTON_BUILD_FN(ploc, .max_prims = REC_PRIMS, .spare = spare_nodes(b.n), .place = scratch_alloc,
                .sorted = first_clusters_phase, .phases = phases, .count = &b.iterations,
                .count_name = "iterations")

PLUGIN_PARALLEL_BUILDER(options, BVHLAB_BUILDER_BOXES, .name = "ploc",
	.summary = "parallel locally-ordered clustering (Meister & Bittner 2018) from Morton "
	           "order, SAH collapse",
	.peak_bytes_per_prim = 256 /* measured 190-232 */)
