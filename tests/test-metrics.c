/*
 * bvhlab_tree_stats_compute on hand-computable trees (SAH cost, counts,
 * depth, histogram, memory), on a zero-area root, on a chain deeper than
 * the depth walk's fixed stack, and on a built tree checked against an
 * independent recursive computation, in two node orders.
 */
#include <math.h>

#include "testutil.h"
#include "tree_fixture.h"

#define CLOSE(a, b) (fabs((a) - (b)) <= 1e-12 * fmax(1.0, fabs(b)))

static bvhlab_node box_node(float x0, float y0, float z0, float x1, float y1, float z1,
                            uint32_t first, uint32_t count)
{
	return (bvhlab_node){ { x0, y0, z0 }, first, { x1, y1, z1 }, count };
}

/* The stats of a tree over caller-filled nodes, prim_index 0, 1, ...
 * (unchecked here). */
static bvhlab_tree_stats hand_stats(const bvhlab_node *nodes, uint32_t n, uint32_t refs)
{
	bvhlab_tree_stats s;
	bvhlab_tree t;

	if (bvhlab_tree_init(&t, n, refs) < 0)
		exit(1);
	memcpy(t.nodes, nodes, n * sizeof(bvhlab_node));
	for (uint32_t i = 0; i < refs; i++)
		t.prim_index[i] = i;
	t.node_count = n;
	t.index_count = refs;
	bvhlab_tree_stats_compute(&t, &s);
	bvhlab_tree_finish(&t);
	return s;
}

static void test_single_leaf(void)
{
	bvhlab_node nodes[1] = { box_node(0, 0, 0, 1, 2, 3, 0, 5) };
	bvhlab_tree_stats s;
	uint32_t k;

	s = hand_stats(nodes, 1, 5);
	CHECK(s.sah_cost == 5.0); /* SA(leaf) * 5 / SA(root) */
	CHECK_INT(s.nodes, 1);
	CHECK_INT(s.leaves, 1);
	CHECK_INT(s.max_depth, 0);
	CHECK(s.avg_leaf_size == 5.0 && s.refs == 5);
	CHECK_INT(s.memory_bytes, 32 + 5 * 4);
	for (k = 0; k < BVHLAB_LEAF_HISTOGRAM; k++)
		CHECK_INT(s.leaf_histogram[k], k == 4);
}

/* Root [0,2]x[0,1]x[0,1] (area 10) over two unit cubes (area 6 each) with
 * 1 and 3 primitives: (10 + 6 * 1 + 6 * 3) / 10 = 3.4. */
static void test_two_boxes(void)
{
	bvhlab_node nodes[3] = {
		box_node(0, 0, 0, 2, 1, 1, 1, 0),
		box_node(0, 0, 0, 1, 1, 1, 0, 1),
		box_node(1, 0, 0, 2, 1, 1, 1, 3),
	};
	bvhlab_tree_stats s;

	s = hand_stats(nodes, 3, 4);
	CHECK(CLOSE(s.sah_cost, 3.4));
	CHECK_INT(s.nodes, 3);
	CHECK_INT(s.leaves, 2);
	CHECK_INT(s.max_depth, 1);
	CHECK(s.avg_leaf_size == 2.0 && s.refs == 4);
	CHECK_INT(s.leaf_histogram[0], 1);
	CHECK_INT(s.leaf_histogram[2], 1);
	CHECK_INT(s.memory_bytes, 3 * 32 + 4 * 4);
}

/*
 * Three levels, children stored before their parent's siblings and a leaf
 * over 16 primitives: root [0,4]x[0,1]x[0,1] (area 18); inner A
 * [0,2]x[0,1]x[0,1] (10) over unit cubes with 2 and 20 primitives (6 each);
 * leaf B [2,4]x[0,1]x[0,1] (10) with 1.
 * cost = (18 + 10 + 6 * 2 + 6 * 20 + 10 * 1) / 18 = 170 / 18.
 */
static void test_three_levels(void)
{
	bvhlab_node nodes[5] = {
		box_node(0, 0, 0, 4, 1, 1, 3, 0),
		box_node(0, 0, 0, 1, 1, 1, 0, 2),
		box_node(1, 0, 0, 2, 1, 1, 2, 20),
		box_node(2, 0, 0, 4, 1, 1, 22, 1), /* B */
		box_node(0, 0, 0, 2, 1, 1, 1, 0),  /* A */
	};
	bvhlab_tree_stats s;

	s = hand_stats(nodes, 5, 23);
	CHECK(CLOSE(s.sah_cost, 170.0 / 18.0));
	CHECK_INT(s.leaves, 3);
	CHECK_INT(s.max_depth, 2);
	CHECK(CLOSE(s.avg_leaf_size, 23.0 / 3.0));
	CHECK_INT(s.leaf_histogram[0], 1);
	CHECK_INT(s.leaf_histogram[1], 1);
	CHECK_INT(s.leaf_histogram[15], 0);
	CHECK_INT(s.leaf_histogram[16], 1); /* more than 16 */
}

/* A root of zero area: every node counts with ratio 1, cost = inner + refs.
 * A flat root still has area and follows the formula. */
static void test_zero_area(void)
{
	bvhlab_node point[3] = {
		box_node(1, 1, 1, 1, 1, 1, 1, 0),
		box_node(1, 1, 1, 1, 1, 1, 0, 2),
		box_node(1, 1, 1, 1, 1, 1, 2, 3),
	};
	bvhlab_node line[3] = {
		box_node(0, 1, 2, 5, 1, 2, 1, 0),
		box_node(0, 1, 2, 2, 1, 2, 0, 2),
		box_node(3, 1, 2, 5, 1, 2, 2, 3),
	};
	bvhlab_node flat[3] = { /* area 2 * 2 * 1 = 4; children 2 each */
		box_node(0, 0, 0, 2, 1, 0, 1, 0),
		box_node(0, 0, 0, 1, 1, 0, 0, 2),
		box_node(1, 0, 0, 2, 1, 0, 2, 3),
	};
	bvhlab_tree_stats s;

	s = hand_stats(point, 3, 5);
	CHECK(s.sah_cost == 6.0);
	s = hand_stats(line, 3, 5);
	CHECK(s.sah_cost == 6.0);
	CHECK(isfinite(s.sah_cost));
	s = hand_stats(flat, 3, 5);
	CHECK(CLOSE(s.sah_cost, (4.0 + 2.0 * 2 + 2.0 * 3) / 4.0));
}

static void test_chain(void)
{
	bvhlab_tree_stats s;
	fixture f;

	fixture_chain(&f, 3000); /* the depth walk's stack must grow */
	bvhlab_tree_stats_compute(&f.tree, &s);
	CHECK_INT(s.max_depth, 2999);
	CHECK_INT(s.leaves, 3000);
	CHECK_INT(s.leaf_histogram[0], 3000);
	CHECK_INT(s.nodes, 5999);
	fixture_free(&f);
}

static double area(const bvhlab_node *n)
{
	double x = (double)n->hi[0] - n->lo[0], y = (double)n->hi[1] - n->lo[1];
	double z = (double)n->hi[2] - n->lo[2];

	return 2.0 * (x * y + y * z + z * x);
}

/* Reference: recursive sum of the cost terms, depth and leaf count. */
static double reference(const bvhlab_tree *t, uint32_t node, uint32_t depth,
                        uint32_t *max_depth, uint32_t *leaves)
{
	const bvhlab_node *n = &t->nodes[node];

	*max_depth = depth > *max_depth ? depth : *max_depth;
	if (n->count) {
		++*leaves;
		return area(n) * n->count;
	}
	return area(n) + reference(t, n->first, depth + 1, max_depth, leaves) +
	       reference(t, n->first + 1, depth + 1, max_depth, leaves);
}

static void test_built_tree(void)
{
	bvhlab_tree_stats s, p;
	bvhlab_tree permuted;
	uint32_t depth = 0, leaves = 0, sum = 0, k;
	double cost;
	fixture f;

	fixture_soup(&f, 5000, 3, 100.0f, 3.0f);
	fixture_build(&f, 3);
	cost = reference(&f.tree, 0, 0, &depth, &leaves) / area(&f.tree.nodes[0]);
	bvhlab_tree_stats_compute(&f.tree, &s);
	CHECK(fabs(s.sah_cost - cost) <= 1e-9 * cost);
	CHECK(s.sah_cost > 1.0);
	CHECK_INT(s.max_depth, depth);
	CHECK_INT(s.leaves, leaves);
	CHECK_INT(s.nodes, f.tree.node_count);
	CHECK(CLOSE(s.avg_leaf_size, 5000.0 / leaves));
	for (k = 0; k < BVHLAB_LEAF_HISTOGRAM; k++)
		sum += s.leaf_histogram[k];
	CHECK_INT(sum, leaves);
	CHECK_INT(s.leaf_histogram[3] + s.leaf_histogram[4], 0);
	CHECK_INT(s.memory_bytes, (uint64_t)f.tree.node_count * 32 + 5000 * 4);

	tree_permute(&permuted, &f.tree, 99, NULL);
	bvhlab_tree_stats_compute(&permuted, &p);
	CHECK(fabs(p.sah_cost - s.sah_cost) <= 1e-12 * s.sah_cost); /* sum order differs */
	CHECK_INT(p.max_depth, s.max_depth);
	CHECK(memcmp(p.leaf_histogram, s.leaf_histogram, sizeof(s.leaf_histogram)) == 0);
	bvhlab_tree_finish(&permuted);
	fixture_free(&f);
}

int main(void)
{
	test_single_leaf();
	test_two_boxes();
	test_three_levels();
	test_zero_area();
	test_chain();
	test_built_tree();
	return test_finish();
}
