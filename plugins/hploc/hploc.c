/*
 * hploc: H-PLOC (Benthin et al. 2024) on the CPU, with lbvh's SAH
 * collapse. The phases are described in hploc.h.
 *
 * This file: options, scratch memory, the first clusters, build() on
 * morton_build.
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

static int scratch_alloc(void *arg, bvhlab_build_output *out, morton_scratch *s)
{
	hploc *h = arg;
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
	h->out = out;
	h->merge = (hploc_params){ h->radius, h->collapse, h->max_leaf, h->c_trav, h->c_isect };
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

MORTON_PHASE_FN(hploc, first_clusters)
MORTON_PHASE_FN(hploc, hploc_climb)
MORTON_PHASE_FN(hploc, emit)

static const morton_phase phases[] = {
	{ "climb", hploc_climb_phase }, { "emit", emit_phase }, { NULL, NULL },
};

/* ---- build --------------------------------------------------------------- */

MORTON_BUILD_FN(hploc, .max_prims = HPLOC_PRIMS, .spare = spare_nodes(b.n), .place = scratch_alloc,
                .sorted = first_clusters_phase, .phases = phases)

PLUGIN_PARALLEL_BUILDER(options, 0, .name = "hploc",
	.summary = "H-PLOC (Benthin et al. 2024): PLOC merging inside the LBVH's subtrees, "
	           "bottom-up from Morton order, SAH collapse",
	.peak_bytes_per_prim = 192 /* measured 134-168 */)
