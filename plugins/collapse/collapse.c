/*
 * collapse: the refinement stage (see collapse.h). This file: options, the
 * greedy method, and the wide tree written out breadth first from either
 * method's decisions.
 */
#include <errno.h>
#include <stdlib.h>
#include <string.h>

#include <bvhlab/aabb.h>

#include "collapse.h"
#include "plugin_options.h"

static const plugin_option options[] = {
	PLUGIN_OPTION(struct collapse_params, width, I64, .name = "width",
	              .help = "children per wide node: 4 or 8", .def_int = 8, .min = 4, .max = 8,
	              .choices = "4|8"),
	PLUGIN_OPTION(struct collapse_params, method, CHOICE, .name = "method",
	              .help = "sah (the SAH-optimal conversion by dynamic programming, Ylitie "
	                      "et al. 2017) or greedy (open the inner child of largest area "
	                      "until width children, as Embree and tinybvh; binary leaves stay "
	                      "leaves, the limits and costs below are sah's)",
	              .def_string = "sah", .choices = "sah|greedy"),
	PLUGIN_MAX_LEAF(struct collapse_params, max_leaf, U32, 64,
	                "sah: most references in a wide leaf merged from a subtree (a binary "
	                "leaf larger than this stays as it is)"),
	PLUGIN_OPTION(struct collapse_params, c_node, DOUBLE, .name = "c_node",
	              .help = "sah: cost of visiting a wide node, whatever its children "
	                      "(a node of k children costs c_node + c_trav * k / 2)",
	              .def_float = 0.0, .min = 0.0, .max = 1e6),
	PLUGIN_C_TRAV(struct collapse_params, c_trav, DOUBLE, 0.0,
	              "sah: cost of a binary inner node, one half per child box tested (the "
	              "defaults are the reported wide SAH's)"),
	PLUGIN_C_ISECT(struct collapse_params, c_isect, DOUBLE,
	               "sah: cost of intersecting one primitive"),
};
PLUGIN_DECLS(options, struct collapse_params, NULL)

/* ---- greedy ---------------------------------------------------------------- */

/* The binary children of n, the inner one of largest area opened in turn
 * (the first of equal ones) until there are `width` or none is inner. */
static uint32_t greedy_children(const struct collapse *c, uint32_t n, uint32_t *list)
{
	const bvhlab_node *bin = c->bin;
	uint32_t k = 2;
	list[0] = bin[n].first;
	list[1] = bin[n].first + 1;
	while (k < c->width) {
		int best = -1;
		double best_area = -1.0;
		for (uint32_t i = 0; i < k; i++) {
			double a = bvhlab_box_area(bin[list[i]].lo, bin[list[i]].hi);
			if (bin[list[i]].count == 0 && a > best_area)
				best = (int)i, best_area = a;
		}
		if (best < 0)
			break;
		uint32_t open = list[best];
		list[best] = bin[open].first;
		list[k++] = bin[open].first + 1;
	}
	return k;
}

uint32_t collapse_children(const struct collapse *c, uint32_t n, uint32_t *list)
{
	if (!c->choice)
		return greedy_children(c, n, list);
	return collapse_sah_forest(c, n, c->choice[(size_t)n * c->width], list);
}

bool collapse_is_leaf(const struct collapse *c, uint32_t n)
{
	return c->choice ? c->choice[(size_t)n * c->width] == 0 : c->bin[n].count != 0;
}

/* ---- the wide tree ------------------------------------------------------------ */

struct emit {
	const struct collapse *c;
	const uint32_t *old_index; /* the binary tree's prim_index */
	bvhlab_build_output *tree;
	uint32_t (*queue)[2];      /* (binary node, wide slot) */
	uint32_t head, tail, used, slots;
};

/* A wide leaf: every reference of the binary leaves under n, in order. A
 * merged subtree holds at most 64 references, so at most 64 leaves and a
 * stack of 66 suffices; -EINVAL past it (links that are not a tree). */
static int emit_leaf(struct emit *e, uint32_t n, bvhlab_node *out)
{
	uint32_t stack[66], sp = 0, first = e->slots;
	stack[sp++] = n;
	while (sp > 0) {
		const bvhlab_node *b = &e->c->bin[stack[--sp]];
		if (b->count == 0) {
			if (sp + 2 > 66)
				return -EINVAL;
			stack[sp++] = b->first + 1;
			stack[sp++] = b->first;
			continue;
		}
		if ((uint64_t)e->slots + b->count > e->tree->index_capacity)
			return -EINVAL;
		memcpy(e->tree->prim_index + e->slots, e->old_index + b->first,
		       (size_t)b->count * sizeof(uint32_t));
		e->slots += b->count;
	}
	out->first = first;
	out->count = e->slots - first;
	return 0;
}

static int emit_node(struct emit *e, uint32_t n, uint32_t slot)
{
	bvhlab_node *out = &e->tree->nodes[slot];
	uint32_t list[BVHLAB_MAX_WIDTH];
	*out = e->c->bin[n];
	if (collapse_is_leaf(e->c, n))
		return emit_leaf(e, n, out);
	uint32_t k = collapse_children(e->c, n, list);
	if (e->used + k > e->c->count)
		return -EINVAL;
	out->first = e->used;
	out->count = k == 2 ? 0 : BVHLAB_NODE_INNER | k;
	for (uint32_t i = 0; i < k; i++) {
		e->queue[e->tail][0] = list[i];
		e->queue[e->tail++][1] = e->used++;
	}
	return 0;
}

/* Breadth first, so each wide node's children are consecutive. */
static int emit(struct emit *e)
{
	int rc = 0;
	e->queue[0][0] = 0, e->queue[0][1] = 0;
	e->tail = e->used = 1;
	while (rc == 0 && e->head < e->tail) {
		uint32_t n = e->queue[e->head][0], slot = e->queue[e->head++][1];
		rc = emit_node(e, n, slot);
	}
	e->tree->node_count = e->used;
	e->tree->index_count = e->slots;
	return rc;
}

/* ---- refine ------------------------------------------------------------------ */

/* Every inner node's children inside the array, none the root, none wide:
 * what the walks above rely on (the host hands over a binary tree, but not
 * necessarily a validated one). */
static bool links_fit(const bvhlab_node *bin, uint32_t count)
{
	for (uint32_t i = 0; i < count; i++) {
		if (bin[i].count & BVHLAB_NODE_INNER)
			return false;
		if (bin[i].count == 0 && (bin[i].first == 0 || bin[i].first >= count - 1))
			return false;
	}
	return true;
}

static int convert(const struct collapse_params *o, bvhlab_build_output *tree)
{
	size_t n = tree->node_count, refs = tree->index_count;
	bvhlab_node *bin = malloc(n * sizeof(*bin));
	uint32_t *old_index = malloc(refs * sizeof(*old_index));
	uint32_t (*queue)[2] = malloc(n * sizeof(*queue));
	struct collapse c = { .bin = bin, .count = tree->node_count, .width = (uint32_t)o->width };
	struct emit e = { .c = &c, .old_index = old_index, .tree = tree, .queue = queue };
	int rc = bin && old_index && queue ? 0 : -ENOMEM;
	if (rc == 0) {
		memcpy(bin, tree->nodes, n * sizeof(*bin));
		memcpy(old_index, tree->prim_index, refs * sizeof(*old_index));
		rc = links_fit(bin, c.count) ? 0 : -EINVAL;
	}
	if (rc == 0 && o->method == COLLAPSE_SAH)
		rc = collapse_sah_plan(&c, o);
	if (rc == 0)
		rc = emit(&e);
	free(bin);
	free(old_index);
	free(queue);
	free(c.choice);
	return rc;
}

static int refine(const bvhlab_host *host, bvhlab_build_ctx *ctx,
                  const bvhlab_build_input *input, bvhlab_build_output *tree)
{
	struct collapse_params o;
	int rc = PLUGIN_OPTIONS_GET(host, ctx, input, &o);
	if (rc < 0)
		return rc;
	if (tree->width > 2) {
		host->set_error(ctx, "collapse: the tree is %u-wide already", tree->width);
		return -EINVAL;
	}
	rc = tree->node_count ? convert(&o, tree) : 0;
	if (rc == 0)
		tree->width = (uint32_t)o.width;
	else if (rc == -ENOMEM)
		host->set_error(ctx, "collapse: out of memory for %u nodes", tree->node_count);
	else
		host->set_error(ctx, "collapse: the tree's links are not a binary tree");
	return rc;
}

PLUGIN_WITH_OPTIONS(options,
	.name = "collapse",
	.summary = "refinement: binary tree to 4- or 8-wide, SAH-optimal by dynamic programming "
	           "(Ylitie et al. 2017) or greedy (Embree, tinybvh)",
	.flags = BVHLAB_BUILDER_DETERMINISTIC,
	.build = NULL,
	.refine = refine)
