/*
 * sbvh: top-down SAH with object and spatial splits (Stich, Friedrich &
 * Dietrich 2009, "Spatial Splits in Bounding Volume Hierarchies").
 *
 * At every node the builder bins the references' centroids (object
 * split); when the two children of the best object split overlap by more
 * than alpha times the root's area and by at least `overlap` of the
 * node's own area, it also bins the node's box with each
 * reference clipped exactly into the bins it crosses (spatial split), and
 * takes the cheaper. A spatial split cuts the references it crosses into
 * two, unless leaving one whole on one side is cheaper (reference
 * unsplitting). References may number at most split_factor times the
 * triangles (see sbvh.h for how that budget is shared out).
 *
 * Leaf boxes hold only the parts of their triangles that lie in them, so
 * the descriptor declares spatial splits: the harness then judges the
 * tree by coverage (core/validate_clip.c).
 */
#include <errno.h>
#include <math.h>
#include <stdlib.h>
#include <string.h>

#include <bvhlab/aabb.h>

#include "plugin_options.h"
#include "sbvh.h"

static const plugin_option options[] = {
	PLUGIN_OPTION(sbvh_options, split_factor, DOUBLE, .name = "split_factor",
	              .help = "most references, in triangles: room for spatial splits' "
	                      "duplicates",
	              .def_float = 1.3, .min = 1.0, .max = 8.0),
	PLUGIN_OPTION(sbvh_options, alpha, DOUBLE, .name = "alpha",
	              .help = "try spatial splits where the object split's children overlap by "
	                      "more than alpha * root area (Stich's alpha; 1 turns them off)",
	              .def_float = 1e-5, .min = 0.0, .max = 1.0),
	PLUGIN_OPTION(sbvh_options, overlap, DOUBLE, .name = "overlap",
	              .help = "try spatial splits only where those children also overlap by at "
	                      "least this share of the node's own area (0: alpha alone)",
	              .def_float = 0.1, .min = 0.0, .max = 1.0),
	PLUGIN_OPTION(sbvh_options, bins, U32, .name = "bins",
	              .help = "object and spatial bins per axis",
	              .def_int = 32, .min = 2, .max = SBVH_MAX_BINS),
	PLUGIN_MAX_LEAF(sbvh_options, max_leaf, U32, SBVH_MAX_LEAF, "most references in a leaf"),
	PLUGIN_OPTION(sbvh_options, parallel_min, U32, .name = "parallel_min",
	              .help = "nodes of at least this many references are split by all threads "
	                      "together; smaller ones are built as one-thread tasks",
	              .def_int = 32768, .min = 2, .max = UINT32_MAX),
	PLUGIN_OPTION(sbvh_options, presplit, DOUBLE, .name = "presplit",
	              .help = "share of the budget's room spent before the build cutting the "
	                      "references with the largest boxes in two (early split clipping); "
	                      "the rest is left to spatial splits",
	              .def_float = 0.0, .min = 0.0, .max = 1.0),
	PLUGIN_OPTION(sbvh_options, lookahead, U32, .name = "lookahead",
	              .help = "nodes of at least this many references (and split by all threads "
	                      "together) also take a spatial split that the greedy SAH turns "
	                      "down when its children, split once more, cost less than the "
	                      "object split's",
	              .def_int = 65536, .min = 2, .max = UINT32_MAX),
};
PLUGIN_DECLS(options, sbvh_options, NULL)

/* Room for the whole budget: at most 2 * refs - 1 nodes and refs slots. */
static int reserve(const bvhlab_host *host, bvhlab_build_ctx *ctx, bvhlab_build_output *out,
                   uint32_t capacity)
{
	uint64_t nodes = 2 * (uint64_t)capacity - 1;

	if (nodes > UINT32_MAX) {
		host->set_error(ctx, "%u references need more than 2^32 nodes", capacity);
		return -EOVERFLOW;
	}
	if (out->node_capacity >= nodes && out->index_capacity >= capacity)
		return 0;
	if (host->grow_output(ctx, out, (uint32_t)nodes, capacity) < 0) {
		host->set_error(ctx, "cannot grow the output to %llu nodes, %u references",
		                (unsigned long long)nodes, capacity);
		return -ENOMEM;
	}
	return 0;
}

/* Every triangle one reference with its whole box. */
static void init_refs(sbvh_build *B)
{
	const bvhlab_build_input *in = B->in;

	for (uint32_t i = 0; i < in->prim_count; i++) {
		sbvh_ref *r = &B->refs[0][i];
		*r = (sbvh_ref){ .prim = i };
		memcpy(r->lo, in->prim_bounds[i].lo, sizeof(r->lo));
		memcpy(r->hi, in->prim_bounds[i].hi, sizeof(r->hi));
	}
}

/* The root job over refs[0][0 .. count). */
static void init_root(const sbvh_build *B, uint32_t count, sbvh_job *root)
{
	*root = (sbvh_job){ .end = count, .rend = B->capacity };
	sbvh_job_empty(root);
	for (uint32_t i = 0; i < count; i++)
		sbvh_job_grow(root, &B->refs[0][i]);
}

static int build(const bvhlab_host *host, bvhlab_build_ctx *ctx,
                 const bvhlab_build_input *input, bvhlab_build_output *output)
{
	sbvh_build B = { .in = input, .threads = input->threads ? input->threads : 1 };
	sbvh_job root;
	double want;
	int rc = PLUGIN_OPTIONS_GET(host, ctx, input, &B.opt);

	if (rc < 0)
		return rc;
	team_host_init(&B.th, host, ctx);
	/* Over boxes (a top level) there is no triangle to clip: object
	 * splits only, with no room for duplicates, so no spatial split and
	 * no pre-split is ever tried (sbvh_job_has_room is false). */
	bool boxes = input->prim_kind == BVHLAB_PRIM_BOXES;
	want = boxes ? input->prim_count : ceil(B.opt.split_factor * input->prim_count);
	B.capacity = want >= (double)UINT32_MAX / 2 ? UINT32_MAX / 2 : (uint32_t)want;
	if (B.capacity < input->prim_count)
		B.capacity = input->prim_count;
	rc = reserve(host, ctx, output, B.capacity);
	if (rc < 0)
		return rc;
	B.out = output;
	B.refs[0] = malloc((size_t)B.capacity * sizeof(sbvh_ref));
	B.refs[1] = malloc((size_t)B.capacity * sizeof(sbvh_ref));
	if (!B.refs[0] || !B.refs[1]) {
		host->set_error(ctx, "out of memory for 2 x %u references", B.capacity);
		rc = -ENOMEM;
		goto out;
	}
	init_refs(&B);
	uint32_t count = input->prim_count;
	if (B.opt.presplit > 0.0 && !boxes) {
		uint32_t room = B.capacity - count;
		rc = sbvh_presplit(&B, count, count + (uint32_t)(B.opt.presplit * room), &count);
		if (rc < 0) {
			host->set_error(ctx, "out of memory pre-splitting");
			goto out;
		}
	}
	init_root(&B, count, &root);
	B.root_area = bvhlab_box_area(root.lo, root.hi);
	atomic_init(&B.next_node, 1);
	atomic_init(&B.next_slot, 0);
	atomic_init(&B.spatial, 0);
	rc = sbvh_build_all(&B, &root);
	if (rc < 0) {
		host->set_error(ctx, "out of memory building (%d)", rc);
		goto out;
	}
	output->node_count = atomic_load(&B.next_node);
	output->index_count = atomic_load(&B.next_slot);
	host->log(ctx, BVHLAB_LOG_DEBUG, "%u references for %u triangles, %llu spatial splits",
	          output->index_count, input->prim_count,
	          (unsigned long long)atomic_load(&B.spatial));
out:
	free(B.refs[0]);
	free(B.refs[1]);
	return rc;
}

PLUGIN_WITH_OPTIONS(options, .name = "sbvh",
	.summary = "SAH with object and spatial splits (Stich et al. 2009): exact triangle "
	           "clipping, reference unsplitting, split_factor budget; parallel, deterministic",
	.flags = BVHLAB_BUILDER_PARALLEL | BVHLAB_BUILDER_DETERMINISTIC |
	         BVHLAB_BUILDER_SPATIAL_SPLITS | BVHLAB_BUILDER_BOXES,
	.build = build,
	.peak_bytes_per_prim = 320 /* measured 129-157; splits vary */)
