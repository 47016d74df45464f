/*
 * End-point overlap on hand-made trees with a known answer:
 *
 * Two triangles in the plane z = 0, each alone in a leaf under the root:
 * A = (0,0) (2,0) (0,2), area 2, box [0,2]^2; B = (1,1) (3,1) (3,3), area 2,
 * box [1,3]^2. B's part inside A's box is the triangle (1,1) (2,1) (2,2),
 * area 1/2; A's part inside B's box is the single point (1,1), area 0. The
 * root holds both, so it counts nothing. With a leaf's cost its primitive
 * count (1): EPO = (1/2 * 1) / (2 + 2) = 0.125.
 *
 * The same two triangles moved apart overlap nowhere: EPO exactly 0.
 * Sampled, so the first is checked within a bound far wider than the
 * sampling error (0.0013 for 65536 points), and the same seed must give
 * the same value twice.
 */
#include <errno.h>
#include <math.h>

#include <bvhlab/epo.h>

#include "testutil.h"
#include "tree_fixture.h"

static void two_triangles(fixture *f, float shift)
{
	static const float v[6][2] = {{0, 0}, {2, 0}, {0, 2}, {1, 1}, {3, 1}, {3, 3}};
	fixture_alloc(f, 6, 2);
	for (int i = 0; i < 6; i++) {
		f->scene.vertices[3 * i] = v[i][0] + (i >= 3 ? shift : 0.0f);
		f->scene.vertices[3 * i + 1] = v[i][1];
		f->scene.vertices[3 * i + 2] = 0.0f;
		f->scene.indices[i] = (uint32_t)i;
	}
	fixture_prepare(f);
	fixture_build(f, 1); /* root over two one-triangle leaves */
}

static void test_known_overlap(void)
{
	fixture f;
	double epo = -1, again = -1;
	two_triangles(&f, 0.0f);
	CHECK_INT(f.tree.node_count, 3);
	CHECK_INT(bvhlab_tree_epo(&f.tree, &f.scene, 65536, 42, &epo), 0);
	printf("overlapping pair: EPO %.5f (exact 0.125)\n", epo);
	CHECK(fabs(epo - 0.125) < 0.01);
	CHECK_INT(bvhlab_tree_epo(&f.tree, &f.scene, 65536, 42, &again), 0);
	CHECK(epo == again);
	CHECK_INT(bvhlab_tree_epo(&f.tree, &f.scene, 0, 42, &again), -EINVAL);
	fixture_free(&f);
}

static void test_no_overlap(void)
{
	fixture f;
	double epo = -1;
	two_triangles(&f, 5.0f);
	CHECK_INT(bvhlab_tree_epo(&f.tree, &f.scene, 4096, 1, &epo), 0);
	CHECK(epo == 0.0);
	fixture_free(&f);
}

/* A grid with shared edges: boxes of neighbouring leaves touch, and the
 * points on a shared edge lie in both. Such points have no area, so the
 * overlap is a small fraction of a leaf's cost; shuffling the node order
 * changes nothing. */
static void test_grid(void)
{
	fixture f;
	bvhlab_tree shuffled;
	double a = -1, b = -1;
	fixture_grid(&f, 16, 16, 0.0f);
	fixture_build(&f, 2);
	CHECK_INT(bvhlab_tree_epo(&f.tree, &f.scene, 20000, 3, &a), 0);
	tree_permute(&shuffled, &f.tree, 9, NULL);
	CHECK_INT(bvhlab_tree_epo(&shuffled, &f.scene, 20000, 3, &b), 0);
	printf("grid: EPO %.5f, shuffled %.5f\n", a, b);
	CHECK(a >= 0 && a == b);
	bvhlab_tree_finish(&shuffled);
	fixture_free(&f);
}

int main(void)
{
	test_known_overlap();
	test_no_overlap();
	test_grid();
	return test_finish();
}
