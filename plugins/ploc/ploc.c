/*
 * ploc: a parallel PLOC builder (Meister & Bittner 2018) with lbvh's SAH
 * collapse. The phases are described in ploc.h.
 *
 * This file: options, scratch memory, the first clusters, build().
 */
#include <errno.h>
#include <stdlib.h>
#include <string.h>
#include <time.h>

#include <bvhlab/aabb.h>

#include "big_alloc.h"
#include "ploc.h"

static const bvhlab_option_decl options[] = {
	{ .name = "radius", .type = BVHLAB_OPTION_INT,
	  .help = "search radius: clusters on either side, in Morton order, that each "
	          "cluster compares with",
	  .def_int = 16, .min = 1, .max = PLOC_MAX_RADIUS },
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
 * save. */
#define MIN_PRIMS_PER_THREAD 512

static double now_ms(void)
{
	struct timespec ts;

	clock_gettime(CLOCK_MONOTONIC, &ts);
	return ts.tv_sec * 1e3 + ts.tv_nsec / 1e6;
}

static int read_options(const bvhlab_host *host, bvhlab_build_ctx *ctx, ploc *p)
{
	int64_t radius, bits, max_leaf;
	double c_trav, c_isect;
	int rc;

	if ((rc = host->option_int(ctx, "radius", &radius)) < 0 ||
	    (rc = host->option_int(ctx, "bits", &bits)) < 0 ||
	    (rc = host->option_bool(ctx, "collapse", &p->collapse)) < 0 ||
	    (rc = host->option_int(ctx, "max_leaf", &max_leaf)) < 0 ||
	    (rc = host->option_float(ctx, "c_trav", &c_trav)) < 0 ||
	    (rc = host->option_float(ctx, "c_isect", &c_isect)) < 0) {
		host->set_error(ctx, "cannot read the options");
		return rc;
	}
	if ((bits != 30 && bits != 63) || radius < 1 || radius > PLOC_MAX_RADIUS ||
	    max_leaf < 1 || max_leaf > 64 || !(c_trav > 0) || !(c_isect > 0)) {
		host->set_error(ctx, "options out of range (bits 30 or 63, radius 1..%d, "
		                "max_leaf 1..64, costs > 0)", PLOC_MAX_RADIUS);
		return -EINVAL;
	}
	p->sort.bits = (unsigned)bits;
	p->radius = (uint32_t)radius;
	p->max_leaf = (uint32_t)max_leaf;
	p->c_trav = (float)c_trav;
	p->c_isect = (float)c_isect;
	return 0;
}

/* ---- scratch ------------------------------------------------------------ */

static size_t align64(size_t x)
{
	return (x + 63) & ~(size_t)63;
}

/* The sort's buffers: in the output's first nodes, which only the emit
 * phase writes, after the sort is read for the last time. */
static size_t sort_size(size_t n)
{
	return 3 * align64(8 * n);
}

/* Clusters (two sets of ten arrays), nn, the merge tree, desc, place and
 * iter_first: past the tree in the output when the host gives the room,
 * which it keeps between builds (fresh pages cost more than a phase). */
static size_t work_size(size_t n)
{
	return 20 * align64(4 * n) + align64(4 * n) + align64(sizeof(bvhlab_node) * (2 * n)) +
	       align64(4 * 2 * n) + align64(sizeof(struct place) * 2 * n) + align64(4 * n);
}

static uint32_t spare_nodes(uint32_t n)
{
	uint64_t spare = (work_size(n) + 64 + sizeof(bvhlab_node) - 1) / sizeof(bvhlab_node);

	return 2 * (uint64_t)n - 1 + spare > UINT32_MAX ? 0 : (uint32_t)spare;
}

static char *take(char **at, size_t bytes)
{
	char *p = *at;

	*at += align64(bytes);
	return p;
}

static void place_clusters(struct clusters *c, char **at, size_t n)
{
	for (int a = 0; a < 3; a++) {
		c->lo[a] = (float *)(void *)take(at, 4 * n);
		c->hi[a] = (float *)(void *)take(at, 4 * n);
	}
	c->first = (uint32_t *)(void *)take(at, 4 * n);
	c->info = (uint32_t *)(void *)take(at, 4 * n);
	c->cost = (float *)(void *)take(at, 4 * n);
	c->desc = (uint32_t *)(void *)take(at, 4 * n);
}

static void place_work(ploc *p, char *at)
{
	size_t n = p->n;

	place_clusters(&p->cl[0], &at, n);
	place_clusters(&p->cl[1], &at, n);
	p->nn = (uint32_t *)(void *)take(&at, 4 * n);
	p->tree = (bvhlab_node *)(void *)take(&at, sizeof(bvhlab_node) * 2 * n);
	p->desc = (uint32_t *)(void *)take(&at, 4 * 2 * n);
	p->place = (struct place *)(void *)take(&at, sizeof(struct place) * 2 * n);
	p->iter_first = (uint32_t *)(void *)take(&at, 4 * n);
}

static void place_sort(ploc *p, char *at)
{
	size_t n = p->n;

	p->sort.codes = (uint64_t *)(void *)take(&at, 8 * n);
	p->sort.keys[0] = (uint64_t *)(void *)take(&at, 8 * n);
	p->sort.keys[1] = (uint64_t *)(void *)take(&at, 8 * n);
}

struct scratch {
	void *region; /* big_alloc, when the output has no room */
	void *small;  /* hist, bucket, count */
};

static int ensure_capacity(const bvhlab_host *host, bvhlab_build_ctx *ctx, const ploc *p,
                           bvhlab_build_output *out)
{
	uint32_t nodes = 2 * p->n - 1, spare = spare_nodes(p->n);

	if (spare && out->node_capacity < nodes + spare)
		(void)host->grow_output(ctx, out, nodes + spare, p->n); /* fine if refused */
	if (out->node_capacity >= nodes && out->index_capacity >= p->n)
		return 0;
	if (host->grow_output(ctx, out, nodes, p->n) < 0) {
		host->set_error(ctx, "cannot grow the output to %u nodes", nodes);
		return -ENOMEM;
	}
	return 0;
}

static int scratch_alloc(ploc *p, const bvhlab_build_output *out, struct scratch *s)
{
	size_t sort = sort_size(p->n), work = work_size(p->n);
	size_t hist = (size_t)p->threads * MORTON_TOP_RADIX * sizeof(uint32_t) +
	              (MORTON_TOP_RADIX + 1) * sizeof(uint32_t);
	uint32_t nodes = 2 * p->n - 1, spare = spare_nodes(p->n);
	bool sort_out = (size_t)nodes * sizeof(bvhlab_node) >= sort;
	bool work_out = spare && out->node_capacity >= nodes + spare;
	uintptr_t past = (uintptr_t)(out->nodes + nodes);
	size_t region = (work_out ? 0 : work) + (sort_out ? 0 : sort);

	s->region = region ? big_alloc(region) : NULL;
	s->small = malloc(hist + (size_t)p->threads * 2 * sizeof(uint32_t));
	if ((region && !s->region) || !s->small)
		return -ENOMEM;
	place_work(p, work_out ? (char *)((past + 63) & ~(uintptr_t)63) : (char *)s->region);
	place_sort(p, sort_out ? (char *)out->nodes : (char *)s->region + (work_out ? 0 : work));
	p->sort.hist = s->small;
	p->sort.bucket = (uint32_t *)(void *)(p->sort.hist + p->threads);
	p->count = p->sort.bucket + MORTON_TOP_RADIX + 1;
	return 0;
}

static void scratch_free(struct scratch *s)
{
	big_free(s->region);
	free(s->small);
}

/* ---- phases -------------------------------------------------------------- */

/* One cluster per primitive, in sorted order: a primitive record. */
static void first_clusters(ploc *p, unsigned t)
{
	struct clusters *c = &p->cl[0];
	uint32_t lo, hi;

	team_chunk(p->team.threads, t, p->n, &lo, &hi);
	for (uint32_t k = lo; k < hi; k++) {
		uint32_t id = morton_id(&p->sort, k);
		const bvhlab_aabb *box = &p->in->prim_bounds[id];

		for (int a = 0; a < 3; a++) {
			c->lo[a][k] = box->lo[a];
			c->hi[a][k] = box->hi[a];
		}
		c->first[k] = id;
		c->info[k] = 1 | REC_PRIM;
		c->cost[k] = p->c_isect * bvhlab_aabb_half_area(box);
		c->desc[k] = 0;
	}
}

static void run_phases(void *arg, unsigned t)
{
	ploc *p = arg;

	if (t == 0)
		p->phase_ms[3] = now_ms();
	if (t == 0)
		morton_sort_init(&p->sort);
	morton_codes(&p->sort, p->team.threads, t);
	team_sync(&p->team);
	morton_scatter(&p->sort, p->team.threads, t);
	team_sync(&p->team);
	morton_sort_buckets(&p->sort, NULL, NULL);
	team_sync(&p->team);
	first_clusters(p, t);
	team_sync(&p->team);
	if (t == 0)
		p->phase_ms[0] = now_ms();
	ploc_cluster(p, t);
	if (t == 0)
		p->phase_ms[1] = now_ms();
	ploc_emit(p, t);
	if (t == 0)
		p->phase_ms[2] = now_ms();
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

static unsigned team_size(const bvhlab_build_input *in)
{
	uint32_t most = in->prim_count / MIN_PRIMS_PER_THREAD;
	uint32_t want = in->threads < most ? in->threads : most;

	return want < 1 ? 1 : want > TEAM_MAX_THREADS ? TEAM_MAX_THREADS : want;
}

static int build_team(const bvhlab_host *host, bvhlab_build_ctx *ctx, ploc *p,
                      bvhlab_build_output *out)
{
	struct scratch s = { 0 };
	double start = now_ms();
	int rc;

	p->threads = team_size(p->in);
	p->sort.n = p->n;
	p->sort.centroids = p->in->centroids;
	p->sort.centroid_bounds = p->in->centroid_bounds;
	if ((rc = scratch_alloc(p, out, &s)) < 0) {
		host->set_error(ctx, "out of memory for the scratch of %u primitives", p->n);
		goto out;
	}
	p->nodes = out->nodes;
	p->prim_index = out->prim_index;
	if ((rc = team_run(&p->team, p->threads, host->hardware_threads(ctx), run_phases, p)) < 0) {
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
	scratch_free(&s);
	return rc;
}

static int build(const bvhlab_host *host, bvhlab_build_ctx *ctx,
                 const bvhlab_build_input *input, bvhlab_build_output *output)
{
	ploc p = { .in = input, .n = input->prim_count };
	int rc;

	if (input->prim_count == 0 || input->prim_count > REC_PRIMS) {
		host->set_error(ctx, "cannot build over %u primitives", input->prim_count);
		return -EINVAL;
	}
	if ((rc = read_options(host, ctx, &p)) < 0 ||
	    (rc = ensure_capacity(host, ctx, &p, output)) < 0)
		return rc;
	if (input->prim_count == 1) {
		single_leaf(input, output);
		return 0;
	}
	return build_team(host, ctx, &p, output);
}

BVHLAB_PLUGIN(
	.name = "ploc",
	.summary = "parallel locally-ordered clustering (Meister & Bittner 2018) from Morton "
	           "order, SAH collapse",
	.flags = BVHLAB_BUILDER_PARALLEL | BVHLAB_BUILDER_DETERMINISTIC,
	.option_count = OPTION_COUNT,
	.options = options,
	.build = build)
