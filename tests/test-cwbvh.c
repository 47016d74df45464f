/*
 * The compressed 8-wide encoder (core/trace/cwbvh.c) on the CPU, no device
 * needed: lbvh's binary tree and its 4- and 8-wide collapses (the
 * wide_collapse test stage) over generated scenes, needles and the bunny.
 * Decoding every node as the kernel does (cwbvh_node.h):
 *   - each child's quantised box holds its exact box, and is the tightest
 *     the grid allows (one step in on any plane would cut into it);
 *   - the inner children are the nodes child_base + rank, each node
 *     reached once; the leaf ranges are the tree's leaves, each once, so
 *     every triangle slot is reached once;
 *   - an 8-wide tree is encoded as built (each node's children the
 *     tree node's own); a narrower one collapsed greedily (no inner child
 *     left that would still fit in the free slots);
 * and by hand: boxes of extreme size, far from the origin, flat along an
 * axis; a leaf root; an empty tree; links that leave the array, a cycle
 * and a box that is not finite refused by message.
 */
#include <errno.h>
#include <math.h>
#include <stdlib.h>
#include <string.h>

#include <bvhlab/bvhlab.h>

#include "testutil.h"

#define FIXTURE_SEED 41
#include "scene_fixture.h"

#include "trace/cwbvh.h"
#include "tree/tree_view.h"

static bvhlab_plugin *lbvh, *collapser;

/* The decoded box of slot s holds lo..hi, and no plane can move a grid
 * step in. */
static void check_box(const cw_node *n, int s, const float *lo, const float *hi)
{
	for (int k = 0; k < 3; k++) {
		uint8_t a = n->qlo[k][s], b = n->qhi[k][s];
		CHECK(cw_plane(n, k, a) <= lo[k] && cw_plane(n, k, b) >= hi[k]);
		if (a < 255)
			CHECK(cw_plane(n, k, (uint8_t)(a + 1)) > lo[k]);
		if (b > 0)
			CHECK(cw_plane(n, k, (uint8_t)(b - 1)) < hi[k]);
	}
}

/* Node j's slots against the tree: boxes, links, leaves; seen counts. */
static void check_node(const bvhlab_tree *t, const struct cwbvh *c, uint32_t j,
                       uint32_t *node_seen, uint32_t *leaf_seen, const uint32_t *leaf_at)
{
	const cw_node *n = &c->nodes[j];
	uint32_t used = 0, inner = 0, src[CW_WIDTH];
	for (uint32_t s = 0; s < CW_WIDTH; s++) {
		if (n->meta[s] == 0)
			continue;
		uint32_t i = cw_child(n, s);
		const bvhlab_node *exact;
		if (cw_is_inner(n->meta[s])) {
			CHECK(i == n->child_base + inner++ && i < c->node_count && i > j);
			if (i >= c->node_count)
				return;
			node_seen[i]++;
			exact = &t->nodes[c->source[i]];
		} else {
			CHECK(i < c->leaf_count && (n->meta[s] & 31u) < CW_WIDTH);
			if (i >= c->leaf_count)
				return;
			leaf_seen[i]++;
			uint32_t first = c->leaves[i][0];
			CHECK(first < t->index_count && leaf_at[first] != UINT32_MAX);
			if (first >= t->index_count || leaf_at[first] == UINT32_MAX)
				return;
			exact = &t->nodes[leaf_at[first]];
			CHECK_INT(c->leaves[i][1], tree_leaf_count(exact));
		}
		src[used++] = (uint32_t)(exact - t->nodes);
		check_box(n, (int)s, exact->lo, exact->hi);
	}
	CHECK_INT(inner, (uint32_t)__builtin_popcount(n->imask));
	const bvhlab_node *own = &t->nodes[c->source[j]];
	if (tree_width(t) > 4 && !tree_is_leaf(own)) { /* as built */
		CHECK_INT(used, tree_child_count(own));
		for (uint32_t u = 0; u < used; u++)
			CHECK(src[u] >= tree_child(own, 0) && src[u] < tree_children_end(own));
	}
	for (uint32_t u = 0; tree_width(t) <= 4 && u < used; u++) { /* greedy: nothing fits */
		const bvhlab_node *ch = &t->nodes[src[u]];
		CHECK(tree_is_leaf(ch) || used - 1 + tree_child_count(ch) > CW_WIDTH);
	}
}

/* Encodes t and checks every node and that each node and leaf is reached
 * once; prints the layout's size. */
static void check_tree(const char *what, const bvhlab_tree *t, uint32_t triangles)
{
	struct cwbvh c;
	bvhlab_error err = { { 0 } };
	CHECK_INT(cwbvh_encode(t, &c, &err), 0);
	uint32_t *node_seen = calloc(c.node_count + 1, sizeof(uint32_t));
	uint32_t *leaf_seen = calloc(c.leaf_count + 1, sizeof(uint32_t));
	uint32_t *leaf_at = malloc((t->index_count + 1) * sizeof(uint32_t)), leaves = 0, slots = 0;
	CHECK(node_seen && leaf_seen && leaf_at);
	memset(leaf_at, 0xff, (t->index_count + 1) * sizeof(uint32_t));
	for (uint32_t i = 0; i < t->node_count; i++)
		if (tree_is_leaf(&t->nodes[i])) {
			leaf_at[tree_leaf_first(&t->nodes[i])] = i;
			leaves++;
		}
	node_seen[0] = 1;
	for (uint32_t j = 0; j < c.node_count; j++)
		check_node(t, &c, j, node_seen, leaf_seen, leaf_at);
	for (uint32_t j = 0; j < c.node_count; j++)
		CHECK_INT(node_seen[j], 1);
	CHECK_INT(c.leaf_count, leaves);
	for (uint32_t i = 0; i < c.leaf_count; i++) {
		CHECK_INT(leaf_seen[i], 1);
		slots += c.leaves[i][1];
	}
	CHECK_INT(slots, t->index_count);
	printf("  %s: %u-wide tree of %u nodes -> %u compressed nodes, %u leaves, depth %u, "
	       "%.1f bytes a triangle\n", what, tree_width(t), t->node_count, c.node_count,
	       c.leaf_count, c.depth, (double)cwbvh_bytes(&c) / triangles);
	free(node_seen);
	free(leaf_seen);
	free(leaf_at);
	cwbvh_free(&c);
}

static void test_scene(const char *name, bvhlab_scene *scene)
{
	bvhlab_prims prims;
	bvhlab_error err = { { 0 } };
	bvhlab_tree bin = { 0 };
	const char *none[] = { NULL };
	if (!scene)
		return;
	CHECK_INT(bvhlab_prims_init(&prims, scene, &err), 0);
	CHECK_INT(build_with(lbvh, none, &prims.input, 1, &bin, &err), 0);
	check_tree(name, &bin, scene->triangle_count);
	for (uint32_t w = 4; w <= 8; w += 4) {
		bvhlab_tree wide;
		bvhlab_options opts;
		char item[16];
		snprintf(item, sizeof(item), "width=%u", w);
		tree_dup(&wide, &bin);
		CHECK_INT(bvhlab_options_init(&opts, bvhlab_plugin_builder(collapser)), 0);
		CHECK_INT(bvhlab_options_parse(&opts, item, &err), 0);
		CHECK_INT(bvhlab_refine(collapser, &opts, &prims.input, 1, &wide, &err), 0);
		bvhlab_options_finish(&opts);
		check_tree(name, &wide, scene->triangle_count);
		bvhlab_tree_finish(&wide);
	}
	bvhlab_tree_finish(&bin);
	bvhlab_prims_finish(&prims);
	bvhlab_scene_destroy(scene);
}

static void set_box(bvhlab_node *n, float lo0, float lo1, float lo2, float hi0, float hi1,
                    float hi2)
{
	n->lo[0] = lo0, n->lo[1] = lo1, n->lo[2] = lo2;
	n->hi[0] = hi0, n->hi[1] = hi1, n->hi[2] = hi2;
}

/* A root over 8 leaves of awkward boxes, each a leaf of one slot. */
static void test_by_hand(void)
{
	bvhlab_node nodes[9];
	uint32_t prim_index[8] = { 0, 1, 2, 3, 4, 5, 6, 7 };
	bvhlab_tree t = { .nodes = nodes, .node_count = 9, .prim_index = prim_index,
	                  .index_count = 8, .width = 8 };
	set_box(&nodes[1], 1e30f, -1e-30f, 5.0f, 1e30f, 1e-30f, 5.0f);       /* flat in x and z */
	set_box(&nodes[2], -3e30f, 0.1f, 5.0f, -2.9e30f, 0.1000001f, 5.0f);
	set_box(&nodes[3], 0.0f, 0.3f, 5.0f, 1.0f, 0.30000001f, 5.0f);
	set_box(&nodes[4], 123456.7f, -7.0f, 5.0f, 123456.8f, 7.0f, 5.0f);
	set_box(&nodes[5], 1e29f, 1e-38f, 5.0f, 2e30f, 2e-38f, 5.0f);
	set_box(&nodes[6], -1.0f, -1.0f, 5.0f, -1.0f, -1.0f, 5.0f);
	set_box(&nodes[7], 0.5f, 0.5f, 5.0f, 0.5f, 0.5f, 5.0f);
	set_box(&nodes[8], 3e29f, 6.5f, 5.0f, 3e29f, 6.5f, 5.0f);
	nodes[0] = (bvhlab_node){ { -3e30f, -7.0f, 5.0f }, 1, { 2e30f, 7.0f, 5.0f },
	                          BVHLAB_NODE_INNER | 8 };
	for (uint32_t i = 1; i < 9; i++) {
		nodes[i].first = i - 1;
		nodes[i].count = 1;
	}
	check_tree("by hand", &t, 8);
	/* one leaf: a root node of one leaf slot */
	bvhlab_tree one = { .nodes = &nodes[3], .node_count = 1, .prim_index = prim_index,
	                    .index_count = 1 };
	nodes[3].first = 0;
	check_tree("leaf root", &one, 1);
	struct cwbvh c;
	bvhlab_error err = { { 0 } };
	bvhlab_tree none = { .nodes = nodes, .node_count = 0 };
	CHECK_INT(cwbvh_encode(&none, &c, &err), 0);
	CHECK_INT(c.node_count, 0);
	cwbvh_free(&c);
	cwbvh_free(NULL);
	nodes[3].first = 2;
	nodes[0].first = 2; /* the last child leaves the array */
	CHECK_INT(cwbvh_encode(&t, &c, &err), -EINVAL);
	CHECK_CONTAINS(err.message, "cwbvh: the tree's links do not make a tree");
	nodes[0].first = 1;
	nodes[4] = (bvhlab_node){ { 0, 0, 0 }, 4, { 1, 1, 1 }, BVHLAB_NODE_INNER | 2 }; /* a cycle */
	CHECK_INT(cwbvh_encode(&t, &c, &err), -EINVAL);
	set_box(&nodes[4], 0.0f, NAN, 0.0f, 1.0f, 1.0f, 1.0f);
	nodes[4].first = 3, nodes[4].count = 1;
	CHECK_INT(cwbvh_encode(&t, &c, &err), -EINVAL);
	CHECK_CONTAINS(err.message, "or a box is not finite");
}

int main(void)
{
	static const struct scene_sizes sizes = { 3000, 6, 1500, 25, 40 };
	if (!plugin_loads("lbvh", &lbvh) || !plugin_loads("wide_collapse", &collapser))
		return test_finish();
	test_by_hand();
	for_generated(&sizes, test_scene);
	test_scene("needles", generate("needles", 300, 0, 0));
	test_scene("bunny", load_shared("stanford-bunny.obj"));
	bvhlab_plugin_close(lbvh);
	bvhlab_plugin_close(collapser);
	return test_finish();
}
