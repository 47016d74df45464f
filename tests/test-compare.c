/*
 * bvhlab_tree_compare: the same tree in another node, child and prim_index
 * order compares equal; a changed box, a changed leaf primitive set or a
 * changed shape is found and located by its path in the first tree.
 */
#include <errno.h>
#include <math.h>

#include "testutil.h"
#include "tree_fixture.h"

static fixture fx;

/* Follows "LRL..." from the root of t (L = first, R = first + 1). */
static uint32_t node_at(const bvhlab_tree *t, const char *path)
{
	uint32_t node = 0;

	for (; *path; path++)
		node = t->nodes[node].first + (*path == 'R');
	return node;
}

/* The deepest path from the root along `pattern`, repeated, ending at a
 * node whose kind is `want_leaf`; written as "root.L.R..." into out. */
static uint32_t pick(const bvhlab_tree *t, const char *pattern, bool want_leaf, char *out,
                     size_t size)
{
	char path[256] = "";
	uint32_t node = 0, len = 0, plen = (uint32_t)strlen(pattern), i;
	int n;

	while (t->nodes[node].count == 0 && len + 1 < sizeof(path)) {
		uint32_t next = t->nodes[node].first + (pattern[len % plen] == 'R');

		if (!want_leaf && t->nodes[next].count)
			break;
		path[len] = pattern[len % plen];
		path[++len] = '\0';
		node = next;
	}
	n = snprintf(out, size, "root");
	for (i = 0; i < len; i++)
		n += snprintf(out + n, size - n, ".%c", path[i]);
	CHECK(node == node_at(t, path));
	return node;
}

static int compare(const bvhlab_tree *a, const bvhlab_tree *b, bvhlab_error *err)
{
	return bvhlab_tree_compare(a, b, err);
}

static void test_equal(void)
{
	bvhlab_tree p, q;
	bvhlab_error err;

	CHECK_INT(compare(&fx.tree, &fx.tree, &err), 0);
	CHECK_INT(err.message[0], '\0');
	tree_permute(&p, &fx.tree, 1, NULL);
	tree_permute(&q, &p, 2, NULL);
	CHECK(memcmp(p.nodes, fx.tree.nodes, p.node_count * sizeof(bvhlab_node)) != 0);
	CHECK_INT(compare(&fx.tree, &p, &err), 0);
	CHECK_INT(compare(&p, &fx.tree, &err), 0);
	CHECK_INT(compare(&p, &q, &err), 0);
	bvhlab_tree_finish(&p);
	bvhlab_tree_finish(&q);
}

static void test_box(void)
{
	uint32_t *map = fx_alloc(fx.tree.node_count * sizeof(uint32_t)), node;
	char path[512], needle[600];
	bvhlab_tree p;
	bvhlab_error err;

	tree_permute(&p, &fx.tree, 3, map);
	node = pick(&fx.tree, "LRR", false, path, sizeof(path));
	p.nodes[map[node]].hi[1] = nextafterf(p.nodes[map[node]].hi[1], INFINITY);
	snprintf(needle, sizeof(needle), "boxes differ at %s (", path);
	CHECK_INT(compare(&fx.tree, &p, &err), 1);
	CHECK_CONTAINS(err.message, needle);
	bvhlab_tree_finish(&p);

	tree_permute(&p, &fx.tree, 4, map);
	node = pick(&fx.tree, "RL", true, path, sizeof(path));
	p.nodes[map[node]].lo[0] = -p.nodes[map[node]].lo[0] - 1.0f;
	snprintf(needle, sizeof(needle), "boxes differ at %s (", path);
	CHECK_INT(compare(&fx.tree, &p, &err), 1);
	CHECK_CONTAINS(err.message, needle);
	bvhlab_tree_finish(&p);

	tree_copy(&p, &fx.tree, 0);
	p.nodes[0].lo[2] = nextafterf(p.nodes[0].lo[2], -INFINITY);
	CHECK_INT(compare(&fx.tree, &p, &err), 1);
	CHECK_CONTAINS(err.message, "boxes differ at root (");
	bvhlab_tree_finish(&p);
	free(map);
}

static void test_leaf_set(void)
{
	uint32_t *map = fx_alloc(fx.tree.node_count * sizeof(uint32_t)), node, other;
	char path[512], needle[600];
	bvhlab_tree p;
	bvhlab_error err;

	tree_permute(&p, &fx.tree, 5, map);
	node = pick(&fx.tree, "RRL", true, path, sizeof(path));
	other = pick(&fx.tree, "L", true, needle, sizeof(needle));
	p.prim_index[p.nodes[map[node]].first] = fx.tree.prim_index[fx.tree.nodes[other].first];
	snprintf(needle, sizeof(needle), "leaf primitive sets differ at %s (primitive ", path);
	CHECK_INT(compare(&fx.tree, &p, &err), 1);
	CHECK_CONTAINS(err.message, needle);
	bvhlab_tree_finish(&p);

	/* The same multiset in another order is no difference. */
	tree_copy(&p, &fx.tree, 0);
	node = pick(&fx.tree, "LLR", true, path, sizeof(path));
	if (p.nodes[node].count >= 2) {
		uint32_t *s = p.prim_index + p.nodes[node].first, x = s[0];

		s[0] = s[1];
		s[1] = x;
	}
	CHECK_INT(compare(&fx.tree, &p, &err), 0);
	bvhlab_tree_finish(&p);
	free(map);
}

/* Splits a leaf of >= 2 primitives into an inner node with the same box
 * over two leaves with that box too: only the shape differs. */
static void test_shape(void)
{
	char path[512], needle[600];
	bvhlab_tree p;
	bvhlab_error err;
	bvhlab_node *l;
	uint32_t node, half;

	tree_copy(&p, &fx.tree, 2);
	node = pick(&fx.tree, "LR", true, path, sizeof(path));
	l = &p.nodes[node];
	CHECK(l->count >= 2);
	half = l->count / 2;
	p.nodes[p.node_count] = *l;
	p.nodes[p.node_count].count = half;
	p.nodes[p.node_count + 1] = *l;
	p.nodes[p.node_count + 1].first += half;
	p.nodes[p.node_count + 1].count -= half;
	l->first = p.node_count;
	l->count = 0;
	p.node_count += 2;
	snprintf(needle, sizeof(needle), "leaf vs inner node at %s", path);
	CHECK_INT(compare(&fx.tree, &p, &err), 1);
	CHECK_CONTAINS(err.message, needle);
	snprintf(needle, sizeof(needle), "inner node vs leaf at %s", path);
	CHECK_INT(compare(&p, &fx.tree, &err), 1);
	CHECK_CONTAINS(err.message, needle);
	bvhlab_tree_finish(&p);
}

static void test_other_trees(void)
{
	bvhlab_tree empty = { 0 }, bad;
	bvhlab_error err;
	fixture g;

	g = fx;
	memset(&g.tree, 0, sizeof(g.tree));
	fixture_build(&g, 2); /* other leaf size: another tree */
	CHECK_INT(compare(&fx.tree, &g.tree, &err), 1);
	CHECK(err.message[0] != '\0');
	bvhlab_tree_finish(&g.tree);

	CHECK_INT(compare(&empty, &empty, &err), 0);
	CHECK_INT(compare(&empty, &fx.tree, &err), 1);
	CHECK_CONTAINS(err.message, "tree a is empty");

	tree_copy(&bad, &fx.tree, 0);
	bad.nodes[node_at(&bad, "LR")].first = 1; /* a cycle */
	CHECK_INT(compare(&fx.tree, &bad, &err), -EINVAL);
	CHECK_CONTAINS(err.message, "tree b: node");
	bad.nodes[node_at(&bad, "LR")].first = bad.node_count - 1;
	CHECK_INT(compare(&bad, &fx.tree, &err), -EINVAL);
	CHECK_CONTAINS(err.message, "child index out of range");
	bvhlab_tree_finish(&bad);
}

/* Hundreds of thousands of nodes, permuted: equal, then one ulp off deep down. */
static void test_large(void)
{
	uint32_t *map, node;
	char path[512], needle[600];
	bvhlab_tree p;
	bvhlab_error err;
	fixture big;

	fixture_soup(&big, 200000, 8, 1000.0f, 5.0f);
	fixture_build(&big, 1);
	map = fx_alloc(big.tree.node_count * sizeof(uint32_t));
	tree_permute(&p, &big.tree, 6, map);
	CHECK_INT(compare(&big.tree, &p, &err), 0);
	node = pick(&big.tree, "RLLRL", true, path, sizeof(path));
	p.nodes[map[node]].hi[2] = nextafterf(p.nodes[map[node]].hi[2], INFINITY);
	snprintf(needle, sizeof(needle), "boxes differ at %s (", path);
	CHECK_INT(compare(&big.tree, &p, &err), 1);
	CHECK_CONTAINS(err.message, needle);
	free(map);
	bvhlab_tree_finish(&p);
	fixture_free(&big);
}

int main(void)
{
	fixture_soup(&fx, 3000, 21, 40.0f, 3.0f);
	fixture_build(&fx, 4);
	test_equal();
	test_box();
	test_leaf_set();
	test_shape();
	test_other_trees();
	test_large();
	fixture_free(&fx);
	return test_finish();
}
