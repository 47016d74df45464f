/*
 * bvhlab_validate_tree on a valid tree and on deliberately broken ones, each
 * caught with its own message; bvhlab_validate_rays on a valid tree and on
 * one whose leaf lost a primitive.
 */
#include <errno.h>
#include <math.h>
#include <stdarg.h>

#include "testutil.h"
#include "tree_fixture.h"

static fixture fx;

static int validate(const bvhlab_tree *t, bool allow_duplicates, bvhlab_error *err)
{
	return bvhlab_validate_tree(t, &fx.input, allow_duplicates, err);
}

static void expect(const bvhlab_tree *t, bool allow_duplicates, const char *needle)
{
	bvhlab_error err;

	CHECK_INT(validate(t, allow_duplicates, &err), -EINVAL);
	CHECK_CONTAINS(err.message, needle);
}

/* expect(t, false, the message printf would make of fmt and the rest). */
static void expectf(const bvhlab_tree *t, const char *fmt, ...) BVHLAB_PRINTF(2, 3);

static void expectf(const bvhlab_tree *t, const char *fmt, ...)
{
	char needle[256];
	va_list ap;

	va_start(ap, fmt);
	vsnprintf(needle, sizeof(needle), fmt, ap);
	va_end(ap);
	expect(t, false, needle);
}

/* The n-th leaf (in node order) with at least min_count primitives. */
static uint32_t find_leaf(const bvhlab_tree *t, uint32_t min_count, uint32_t nth)
{
	uint32_t i;

	for (i = 0; i < t->node_count; i++)
		if (t->nodes[i].count >= min_count && nth-- == 0)
			return i;
	fprintf(stderr, "no such leaf\n");
	exit(1);
}

/* The n-th inner node other than the root. */
static uint32_t find_inner(const bvhlab_tree *t, uint32_t nth)
{
	uint32_t i;

	for (i = 1; i < t->node_count; i++)
		if (t->nodes[i].count == 0 && nth-- == 0)
			return i;
	fprintf(stderr, "no such inner node\n");
	exit(1);
}

static void test_valid(void)
{
	bvhlab_tree t;
	bvhlab_error err;

	CHECK_INT(validate(&fx.tree, false, &err), 0);
	CHECK_INT(err.message[0], '\0');
	CHECK_INT(validate(&fx.tree, true, &err), 0);
	tree_permute(&t, &fx.tree, 7, NULL);
	CHECK_INT(validate(&t, false, &err), 0);
	bvhlab_tree_finish(&t);
}

static void test_counts(void)
{
	bvhlab_tree t;

	tree_copy(&t, &fx.tree, 0);
	t.node_count = 0;
	expect(&t, false, "no nodes");
	expect(&t, false, "did build() set output->node_count?"); /* the likely cause */
	t.node_count = t.node_capacity + 1;
	expect(&t, false, "node_count");
	expect(&t, false, "exceeds node_capacity");
	t.node_count = fx.tree.node_count;
	t.index_count = t.index_capacity + 1;
	expect(&t, false, "exceeds index_capacity");
	bvhlab_tree_finish(&t);
}

/* Removes prim_index slot s: the leaf holding it shrinks, later ranges move. */
static void remove_slot(bvhlab_tree *t, uint32_t s)
{
	uint32_t i;

	memmove(t->prim_index + s, t->prim_index + s + 1,
	        (t->index_count - s - 1) * sizeof(uint32_t));
	t->index_count--;
	for (i = 0; i < t->node_count; i++) {
		bvhlab_node *n = &t->nodes[i];

		if (n->count && s >= n->first && s < n->first + n->count)
			n->count--;
		else if (n->count && n->first > s)
			n->first--;
	}
}

static void test_missing_primitive(void)
{
	bvhlab_tree t;
	char needle[128];
	uint32_t leaf, prim;

	tree_copy(&t, &fx.tree, 0);
	leaf = find_leaf(&t, 2, 3);
	prim = t.prim_index[t.nodes[leaf].first + 1];
	remove_slot(&t, t.nodes[leaf].first + 1);
	snprintf(needle, sizeof(needle), "primitive %u is referenced by no leaf", prim);
	expect(&t, false, needle);
	expect(&t, true, needle); /* allowed duplicates never excuse a missing one */
	bvhlab_tree_finish(&t);
}

static void test_duplicate(void)
{
	bvhlab_tree t;
	bvhlab_error err;
	char ab[64], ba[64];
	uint32_t last = 0, other, prim, i;

	tree_copy(&t, &fx.tree, 4);
	for (i = 0; i < t.node_count; i++) /* the leaf whose range ends the array */
		if (t.nodes[i].count && t.nodes[i].first + t.nodes[i].count == t.index_count)
			last = i;
	other = find_leaf(&t, 1, 0);
	CHECK(other != last);
	prim = t.prim_index[t.nodes[other].first];
	t.prim_index[t.index_count++] = prim;
	t.nodes[last].count++;
	fixture_refit_node(&t, &fx.input, 0);
	expectf(&t, "primitive %u referenced twice (leaves ", prim);
	validate(&t, false, &err);
	snprintf(ab, sizeof(ab), "leaves %u and %u)", other, last);
	snprintf(ba, sizeof(ba), "leaves %u and %u)", last, other);
	CHECK(strstr(err.message, ab) || strstr(err.message, ba));
	CHECK_INT(validate(&t, true, &err), 0);
	bvhlab_tree_finish(&t);
}

static void test_box_one_ulp(void)
{
	bvhlab_tree t;
	uint32_t leaf, s, prim = UINT32_MAX, child;
	float old;

	tree_copy(&t, &fx.tree, 0);
	leaf = find_leaf(&t, 2, 1);
	for (s = t.nodes[leaf].first; prim == UINT32_MAX; s++)
		if (fx.boxes[t.prim_index[s]].hi[0] == t.nodes[leaf].hi[0])
			prim = t.prim_index[s];
	t.nodes[leaf].hi[0] = nextafterf(t.nodes[leaf].hi[0], -INFINITY);
	expectf(&t, "node %u: box does not contain primitive %u", leaf, prim);
	bvhlab_tree_finish(&t);

	tree_copy(&t, &fx.tree, 0);
	old = t.nodes[0].lo[1];
	t.nodes[0].lo[1] = nextafterf(old, INFINITY);
	child = t.nodes[t.nodes[0].first].lo[1] == old ? t.nodes[0].first : t.nodes[0].first + 1;
	expectf(&t, "node 0: box does not contain child %u", child);
	bvhlab_tree_finish(&t);
}

static void test_nan(void)
{
	bvhlab_tree t;
	uint32_t leaf;

	tree_copy(&t, &fx.tree, 0);
	leaf = find_leaf(&t, 1, 5);
	t.nodes[leaf].lo[2] = NAN;
	expectf(&t, "node %u: box has NaN", leaf);
	bvhlab_tree_finish(&t);

	/* An infinite root box contains every child, yet makes the SAH cost NaN. */
	tree_copy(&t, &fx.tree, 0);
	t.nodes[0].lo[0] = -INFINITY;
	expect(&t, false, "node 0: box has NaN or an infinite bound");
	bvhlab_tree_finish(&t);
}

static void test_cycle_and_sharing(void)
{
	bvhlab_tree t;
	uint32_t x, y;

	tree_copy(&t, &fx.tree, 0);
	x = find_inner(&t, 4);
	t.nodes[x].first = 0; /* back to the root */
	expect(&t, false, "node 0 reachable twice (cycle or shared child");
	bvhlab_tree_finish(&t);

	tree_copy(&t, &fx.tree, 0);
	x = find_inner(&t, 6);
	t.nodes[x].first = t.nodes[0].first; /* an ancestor's children */
	expectf(&t, "node %u reachable twice", t.nodes[0].first);
	bvhlab_tree_finish(&t);

	tree_copy(&t, &fx.tree, 0);
	x = t.nodes[0].first; /* siblings: neither is the other's ancestor */
	y = x + 1;
	CHECK(t.nodes[x].count == 0 && t.nodes[y].count == 0);
	t.nodes[y].first = t.nodes[x].first; /* shared children */
	fixture_refit_node(&t, &fx.input, 0); /* boxes right: only the sharing is wrong */
	expectf(&t, "node %u reachable twice", t.nodes[x].first);
	bvhlab_tree_finish(&t);
}

static void test_orphan(void)
{
	bvhlab_tree t;

	tree_copy(&t, &fx.tree, 4);
	t.nodes[t.node_count] = t.nodes[find_leaf(&t, 1, 0)];
	t.node_count++;
	expectf(&t, "node %u is not reachable from the root (orphan)", t.node_count - 1);
	bvhlab_tree_finish(&t);
}

static void test_ranges(void)
{
	bvhlab_tree t;
	uint32_t x, leaf;

	tree_copy(&t, &fx.tree, 0);
	x = find_inner(&t, 3);
	t.nodes[x].first = t.node_count - 1; /* second child just past the end */
	expectf(&t, "node %u: child index %u out of range", x, t.node_count);
	expect(&t, false, "is the last one counted in node_count?");
	t.nodes[x].first = UINT32_MAX;
	expectf(&t, "node %u: child index %u out of range", x, UINT32_MAX);
	bvhlab_tree_finish(&t);

	tree_copy(&t, &fx.tree, 0);
	leaf = find_leaf(&t, 2, 2);
	t.nodes[leaf].first = t.index_count - 1;
	expectf(&t, "node %u: leaf range [%u, %u) exceeds index_count %u", leaf,
	        t.index_count - 1, t.index_count - 1 + t.nodes[leaf].count, t.index_count);
	t.nodes[leaf].first = UINT32_MAX; /* no wrap-around */
	expectf(&t, "node %u: leaf range", leaf);
	bvhlab_tree_finish(&t);

	/* The likely causes: index_count never set; a range one too long. */
	tree_copy(&t, &fx.tree, 0);
	t.index_count = 0;
	expect(&t, false, "exceeds index_count 0: did build() set output->index_count?");
	t.index_count = fx.tree.index_count;
	for (leaf = 0; leaf < t.node_count; leaf++)
		if (t.nodes[leaf].count && t.nodes[leaf].first + t.nodes[leaf].count == t.index_count)
			break;
	CHECK(leaf < t.node_count);
	t.nodes[leaf].count++;
	expectf(&t, "node %u: leaf range [%u, %u) exceeds index_count %u: a leaf range off by one?",
	        leaf, t.nodes[leaf].first, t.index_count + 1, t.index_count);
	bvhlab_tree_finish(&t);

	tree_copy(&t, &fx.tree, 0);
	leaf = find_leaf(&t, 1, 4);
	t.prim_index[t.nodes[leaf].first] = fx.input.prim_count + 7;
	expectf(&t, "node %u: prim_index[%u] = %u out of range", leaf, t.nodes[leaf].first,
	        fx.input.prim_count + 7);
	bvhlab_tree_finish(&t);
}

static void test_slots(void)
{
	bvhlab_tree t;
	uint32_t a, b;

	tree_copy(&t, &fx.tree, 4);
	a = find_leaf(&t, 1, 0);
	b = find_leaf(&t, 1, 3);
	t.nodes[b].first = t.nodes[a].first;
	t.nodes[b].count = 1;
	fixture_refit_node(&t, &fx.input, 0);
	expectf(&t, "prim_index slot %u used by two leaves", t.nodes[a].first);
	bvhlab_tree_finish(&t);

	tree_copy(&t, &fx.tree, 4);
	t.prim_index[t.index_count++] = 0;
	expectf(&t, "prim_index slot %u is used by no leaf", t.index_count - 1);
	bvhlab_tree_finish(&t);
}

static void test_deep_tree(void)
{
	fixture chain;
	bvhlab_error err;

	fixture_chain(&chain, 5000);
	CHECK_INT(bvhlab_validate_tree(&chain.tree, &chain.input, false, &err), 0);
	chain.tree.nodes[4000].first = 1; /* a cycle deep down */
	CHECK_INT(bvhlab_validate_tree(&chain.tree, &chain.input, false, &err), -EINVAL);
	CHECK_CONTAINS(err.message, "node 1 reachable twice");
	fixture_free(&chain);
}

/* Four separate triangles in a plane: nothing occludes anything, so a ray
 * aimed at the dropped triangle's centroid must hit it in brute force. */
static void test_rays(void)
{
	fixture g, big;
	bvhlab_error err;
	uint64_t mismatches = 99, again = 0;
	uint32_t leaf;

	fixture_grid(&g, 2, 1, 0.3f);
	fixture_build(&g, 2);
	CHECK_INT(bvhlab_validate_rays(&g.tree, &g.scene, 256, 1, &mismatches, &err), 0);
	CHECK_INT(mismatches, 0);
	leaf = find_leaf(&g.tree, 2, 0);
	g.tree.nodes[leaf].count--;
	CHECK_INT(bvhlab_validate_rays(&g.tree, &g.scene, 256, 1, &mismatches, &err), 0);
	CHECK(mismatches > 0);
	CHECK_INT(bvhlab_validate_rays(&g.tree, &g.scene, 256, 1, &again, &err), 0);
	CHECK_INT(again, mismatches); /* seeded: reproducible */
	CHECK_INT(bvhlab_validate_tree(&g.tree, &g.input, false, &err), -EINVAL);
	CHECK_CONTAINS(err.message, "is referenced by no leaf");
	fixture_free(&g);

	/* Large enough for the threaded path. */
	fixture_soup(&big, 20000, 3, 100.0f, 4.0f);
	fixture_build(&big, 4);
	CHECK_INT(bvhlab_validate_rays(&big.tree, &big.scene, 512, 9, &mismatches, &err), 0);
	CHECK_INT(mismatches, 0);
	CHECK_INT(bvhlab_validate_rays(&big.tree, &big.scene, 0, 9, &mismatches, &err), 0);
	CHECK_INT(mismatches, 0);
	fixture_free(&big);
}

int main(void)
{
	fixture_soup(&fx, 64, 42, 10.0f, 2.0f);
	fixture_build(&fx, 2);
	test_valid();
	test_counts();
	test_missing_primitive();
	test_duplicate();
	test_box_one_ulp();
	test_nan();
	test_cycle_and_sharing();
	test_orphan();
	test_ranges();
	test_slots();
	test_deep_tree();
	test_rays();
	fixture_free(&fx);
	return test_finish();
}
