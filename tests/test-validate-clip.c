/*
 * Validation of spatial-split trees whose leaf boxes hold only part of a
 * triangle: the coverage check accepts a triangle split exactly between
 * two leaves (and one whose boxes are float-rounded a few ulps inwards),
 * and rejects a tree that drops part of a triangle, one whose reference
 * box misses its triangle, and clipped boxes from a builder without the
 * spatial-splits flag. Embree "high"'s real clipped trees are judged in
 * test-embree.c, whose suite runs without LeakSanitizer (TBB's workers).
 */
#include <errno.h>
#include <math.h>
#include <stdio.h>
#include <string.h>

#include <bvhlab/bvhlab.h>

#include "testutil.h"

/* Triangle 0 spans x in [0, 2]; triangle 1 sits at x in [3, 4]. */
static const float vertices[] = {
	0, 0, 0, 2, 0, 0, 0, 2, 0, /* area 2 */
	3, 0, 0, 4, 0, 0, 3, 1, 0,
};
static const uint32_t indices[] = { 0, 1, 2, 3, 4, 5 };

typedef struct fixture {
	bvhlab_build_input input;
	bvhlab_aabb bounds[2];
	float centroids[6];
	bvhlab_node nodes[3];
	uint32_t prim_index[3];
	bvhlab_tree tree;
} fixture;

static void set_box(bvhlab_node *n, float x0, float y0, float x1, float y1)
{
	n->lo[0] = x0, n->lo[1] = y0, n->lo[2] = 0;
	n->hi[0] = x1, n->hi[1] = y1, n->hi[2] = 0;
}

/*
 * Root with two leaves: leaf 1 holds triangle 0 clipped to x <= 1, leaf 2
 * holds triangle 0 clipped to x >= 1 and triangle 1: a valid split.
 */
static void fixture_init(fixture *f)
{
	memset(f, 0, sizeof(*f));
	for (int p = 0; p < 2; p++)
		for (int k = 0; k < 3; k++) {
			float lo = INFINITY, hi = -INFINITY;
			for (int j = 0; j < 3; j++) {
				float v = vertices[3 * indices[3 * p + j] + k];
				lo = v < lo ? v : lo;
				hi = v > hi ? v : hi;
			}
			f->bounds[p].lo[k] = lo, f->bounds[p].hi[k] = hi;
			f->centroids[3 * p + k] = 0.5f * (lo + hi);
		}
	f->input = (bvhlab_build_input){ .struct_size = sizeof(bvhlab_build_input),
	                                 .prim_count = 2, .prim_bounds = f->bounds,
	                                 .centroids = f->centroids, .vertices = vertices,
	                                 .vertex_count = 6, .indices = indices, .threads = 1 };
	set_box(&f->nodes[0], 0, 0, 4, 2);
	f->nodes[0].first = 1;
	set_box(&f->nodes[1], 0, 0, 1, 2);
	f->nodes[1].first = 0, f->nodes[1].count = 1;
	set_box(&f->nodes[2], 1, 0, 4, 1);
	f->nodes[2].first = 1, f->nodes[2].count = 2;
	f->prim_index[0] = 0, f->prim_index[1] = 0, f->prim_index[2] = 1;
	f->tree = (bvhlab_tree){ .nodes = f->nodes, .node_count = 3, .node_capacity = 3,
	                         .prim_index = f->prim_index, .index_count = 3,
	                         .index_capacity = 3 };
}

static void expect(const fixture *f, bool spatial, const char *needle)
{
	bvhlab_error err = { "" };
	int rc = bvhlab_validate_tree(&f->tree, &f->input, spatial, &err);
	if (!needle) {
		CHECK_INT(rc, 0);
		if (rc)
			fprintf(stderr, "  unexpected: %s\n", err.message);
		return;
	}
	CHECK_INT(rc, -EINVAL);
	CHECK_CONTAINS(err.message, needle);
}

static void test_split_triangle(void)
{
	fixture f;
	fixture_init(&f);
	expect(&f, true, NULL);
	/* Without the flag, today's rule: whole triangle boxes. */
	expect(&f, false, "box does not contain primitive 0");

	/* Float-rounded boxes: both pieces 2 ulps short of the plane x = 1,
	 * and the right one an ulp short at the bottom too. */
	fixture_init(&f);
	f.nodes[1].hi[0] = nextafterf(nextafterf(1.0f, 0.0f), 0.0f);
	f.nodes[2].lo[0] = nextafterf(nextafterf(1.0f, 2.0f), 2.0f);
	f.nodes[2].lo[1] = nextafterf(0.0f, 1.0f);
	expect(&f, true, NULL);

	/* A dropped piece: the right leaf no longer reaches down to x = 1, so
	 * the strip 1 <= x < 1.1 of triangle 0 (about 4.5 % of it) is lost. */
	fixture_init(&f);
	f.nodes[2].lo[0] = 1.1f;
	expect(&f, true, "primitive 0: its 2 reference(s)' leaf boxes leave 4.");
	/* A thinner one: 0.1 % of the triangle. */
	fixture_init(&f);
	f.nodes[2].lo[0] = 1.0f + 1.0f / 512;
	expect(&f, true, "primitive 0: its 2 reference(s)' leaf boxes leave 0.0");
	/* The piece dropped altogether: leaf 2 references triangle 1 twice
	 * (allowed) and triangle 0 not at all, so its half x > 1 is lost. */
	fixture_init(&f);
	f.prim_index[1] = 1;
	expect(&f, true, "primitive 0: its 1 reference(s)' leaf boxes leave 25% of its area");
}

static void test_missing_box(void)
{
	fixture f;
	/* Leaf 1 covers all of triangle 0; leaf 2's reference to it has a box
	 * (x from 2.5) that misses it: harmless to rays, but a wrong box. */
	fixture_init(&f);
	f.nodes[1].hi[0] = 2;
	f.nodes[2].lo[0] = 2.5f;
	f.nodes[0].hi[0] = 4;
	expect(&f, true, "node 2: box (2.5, 0, 0) - (4, 1, 0) misses primitive 0");
	/* The same with leaf 2 touching the triangle's corner at x = 2: fine. */
	f.nodes[2].lo[0] = 2.0f;
	expect(&f, true, NULL);
	/* A child sticking out of its parent is still caught first. */
	fixture_init(&f);
	f.nodes[2].hi[0] = 4.5f;
	expect(&f, true, "node 0: box does not contain child 2");
}

int main(void)
{
	test_split_triangle();
	test_missing_box();
	return test_finish();
}
