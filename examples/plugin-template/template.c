/*
 * template: a minimal bvhlab builder plugin to copy and grow your own from.
 *
 * It splits each node's primitives at the middle of their centroid bounds
 * along the widest axis (half by count when that leaves a side empty) and
 * stops at max_leaf primitives. Build it out of tree against an installed
 * bvhlab (see meson.build beside this file and docs/writing-a-plugin.md),
 * then run it:  bvhlab build ./build/template.so icosphere:frequency=64
 */
#include <errno.h>

#include <bvhlab/aabb.h> /* box helpers, header-only */
#include <bvhlab/builder.h>

static const bvhlab_option_decl options[] = {
	{.name = "max_leaf", .type = BVHLAB_OPTION_INT,
	 .help = "most primitives in a leaf", .def_int = 4, .min = 1, .max = 64},
};

typedef struct job {
	const bvhlab_build_input *in;
	bvhlab_build_output *out;
	uint32_t max_leaf;
} job;

/* The node's box, and the bounds of its primitives' centroids. */
static void bounds(const job *j, bvhlab_node *n, uint32_t begin, uint32_t end, float *clo,
                   float *chi)
{
	bvhlab_box_empty(n->lo, n->hi);
	bvhlab_box_empty(clo, chi);
	for (uint32_t i = begin; i < end; i++) {
		uint32_t p = j->out->prim_index[i];
		const bvhlab_aabb *b = &j->in->prim_bounds[p];
		const float *c = &j->in->centroids[3 * (size_t)p];
		bvhlab_box_grow(n->lo, n->hi, b->lo, b->hi);
		bvhlab_box_grow(clo, chi, c, c);
	}
}

/* Moves the primitives with centroid[axis] < at to the front; the split index. */
static uint32_t partition(const job *j, uint32_t begin, uint32_t end, int axis, float at)
{
	uint32_t *idx = j->out->prim_index;
	uint32_t mid = begin;
	for (uint32_t i = begin; i < end; i++)
		if (j->in->centroids[3 * (size_t)idx[i] + axis] < at) {
			uint32_t t = idx[i];
			idx[i] = idx[mid];
			idx[mid++] = t;
		}
	return mid;
}

static void build_node(job *j, uint32_t node, uint32_t begin, uint32_t end)
{
	bvhlab_node *n = &j->out->nodes[node];
	float clo[3], chi[3];
	bounds(j, n, begin, end, clo, chi);
	if (end - begin <= j->max_leaf) {
		n->first = begin;
		n->count = end - begin;
		return;
	}
	int axis = 0;
	for (int k = 1; k < 3; k++)
		if (chi[k] - clo[k] > chi[axis] - clo[axis])
			axis = k;
	uint32_t mid = partition(j, begin, end, axis, 0.5f * (clo[axis] + chi[axis]));
	if (mid == begin || mid == end)
		mid = begin + (end - begin) / 2;
	/* Children are always a pair: nodes[first] and nodes[first + 1]. */
	n->first = j->out->node_count;
	n->count = 0;
	j->out->node_count += 2;
	build_node(j, n->first, begin, mid);
	build_node(j, n->first + 1, mid, end);
}

static int build(const bvhlab_host *host, bvhlab_build_ctx *ctx,
                 const bvhlab_build_input *input, bvhlab_build_output *output)
{
	int64_t max_leaf;
	int rc = host->option_int(ctx, "max_leaf", &max_leaf);
	if (rc < 0) {
		host->set_error(ctx, "cannot read option max_leaf");
		return rc;
	}
	/* The host allocated 2N-1 nodes and N indices: enough for this builder,
	 * whose leaves are never empty. Spatial splits would need grow_output. */
	if (output->node_capacity < 2 * (uint64_t)input->prim_count - 1 ||
	    output->index_capacity < input->prim_count) {
		host->set_error(ctx, "output buffers smaller than 2N-1 nodes, N indices");
		return -EINVAL;
	}
	/* pin_thread came in ABI 1.1: a host built before it has no such field.
	 * This builder runs on the calling thread only, as worker 0. */
	if (BVHLAB_HOST_HAS(host, pin_thread) && host->pin_thread(ctx, 0) < 0)
		host->log(ctx, BVHLAB_LOG_WARN, "could not pin the build thread; running unpinned");
	job j = {.in = input, .out = output, .max_leaf = (uint32_t)max_leaf};
	for (uint32_t i = 0; i < input->prim_count; i++)
		output->prim_index[i] = i;
	output->node_count = 1;
	build_node(&j, 0, 0, input->prim_count);
	output->index_count = input->prim_count;
	return 0;
}

BVHLAB_PLUGIN(.name = "template", .flags = BVHLAB_BUILDER_DETERMINISTIC,
	.summary = "template plugin: middle split of the centroid bounds",
	.option_count = sizeof(options) / sizeof(options[0]), .options = options, .build = build)
