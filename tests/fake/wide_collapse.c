/*
 * A test refinement stage that turns any binary tree into a 4- or 8-wide
 * one (ABI 1.5 open tree), so the core's judges can be tried on wide trees
 * made from a real builder's: each wide node takes its binary node's two
 * children and keeps replacing the inner child of largest surface area by
 * its own two until it has `width` children (the greedy collapse of
 * Embree's and tinybvh's wide layouts). Boxes and leaves are the binary
 * tree's own, so a ray finds the same closest hit in both.
 */
#include <errno.h>
#include <stdlib.h>
#include <string.h>

#include <bvhlab/builder.h>

static const bvhlab_option_decl options[] = {
	{.name = "width", .type = BVHLAB_OPTION_INT, .help = "children per inner node, 2 to 8",
	 .def_int = 4, .min = 2, .max = BVHLAB_MAX_WIDTH},
};

static float half_area(const bvhlab_node *n)
{
	float d[3];
	for (int k = 0; k < 3; k++)
		d[k] = n->hi[k] - n->lo[k];
	return d[0] * d[1] + d[1] * d[2] + d[2] * d[0];
}

/* The binary children of `node` gathered up to `width`, into list. */
static uint32_t gather(const bvhlab_node *bin, uint32_t node, uint32_t width, uint32_t *list)
{
	uint32_t n = 2;
	list[0] = bin[node].first;
	list[1] = bin[node].first + 1;
	while (n < width) {
		int best = -1;
		for (uint32_t i = 0; i < n; i++)
			if (bin[list[i]].count == 0 &&
			    (best < 0 || half_area(&bin[list[i]]) > half_area(&bin[list[best]])))
				best = (int)i;
		if (best < 0)
			break;
		uint32_t open = list[best];
		list[best] = bin[open].first;
		list[n++] = bin[open].first + 1;
	}
	return n;
}

/* Breadth first: a queue of (binary node, wide slot) pairs. */
static int collapse(const bvhlab_node *bin, uint32_t count, uint32_t width,
                    bvhlab_build_output *tree, uint32_t (*queue)[2])
{
	uint32_t head = 0, tail = 0, used = 1, list[BVHLAB_MAX_WIDTH];
	for (uint32_t i = 0; i < count; i++)
		if (bin[i].count == 0 && (bin[i].first == 0 || bin[i].first >= count - 1))
			return -EINVAL;
	queue[tail][0] = 0, queue[tail++][1] = 0;
	while (head < tail) {
		uint32_t node = queue[head][0], slot = queue[head++][1];
		bvhlab_node *out = &tree->nodes[slot];
		*out = bin[node];
		if (bin[node].count != 0)
			continue;
		uint32_t n = gather(bin, node, width, list);
		if (used + n > count)
			return -EINVAL;
		out->first = used;
		out->count = n == 2 ? 0 : BVHLAB_NODE_INNER | n;
		for (uint32_t i = 0; i < n; i++)
			queue[tail][0] = list[i], queue[tail++][1] = used++;
	}
	tree->node_count = used;
	return 0;
}

static int refine(const bvhlab_host *host, bvhlab_build_ctx *ctx,
                  const bvhlab_build_input *input, bvhlab_build_output *tree)
{
	int64_t width = 4;
	(void)input;
	host->option_int(ctx, "width", &width);
	if (tree->width != 2) {
		host->set_error(ctx, "wide_collapse: the tree is %u-wide already", tree->width);
		return -EINVAL;
	}
	uint32_t count = tree->node_count;
	bvhlab_node *bin = malloc((size_t)count * sizeof(*bin));
	uint32_t (*queue)[2] = malloc((size_t)count * sizeof(*queue));
	int r = bin && queue ? 0 : -ENOMEM;
	if (r == 0) {
		memcpy(bin, tree->nodes, (size_t)count * sizeof(*bin));
		r = collapse(bin, count, (uint32_t)width, tree, queue);
	}
	if (r == 0)
		tree->width = (uint32_t)width;
	else
		host->set_error(ctx, r == -ENOMEM ? "wide_collapse: out of memory"
		                                  : "wide_collapse: the tree's links are not a tree");
	free(bin);
	free(queue);
	return r;
}

BVHLAB_PLUGIN(.name = "wide_collapse",
              .summary = "test stage: a binary tree collapsed greedily into a 2- to 8-wide one",
              .flags = BVHLAB_BUILDER_DETERMINISTIC, .option_count = 1, .options = options,
              .refine = refine)
