/*
 * ploc, and hploc with argument "hploc": on generated scenes (coincident
 * centroids, needles, duplicates, 1 to 3 triangles) and on the shared
 * meshes, with radius 1, 4 and 16 (hploc: its threshold the same) and
 * with and without collapse, every build is valid, traces like brute
 * force, keeps leaves within max_leaf, and is the same tree, node for
 * node, for 1, 2 and 8 threads and when repeated. Collapse never raises
 * the SAH cost. Under ThreadSanitizer the scenes shrink.
 */
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include <bvhlab/bvhlab.h>

#include "testutil.h"

#define FIXTURE_SEED 15
#include "scene_fixture.h"
#include "refine_scenes.h"

#define RAYS 256
#define RAY_SEED 1515

/* After the 1-thread tree: 1 again, 2 and 8, and 2 once more. */
static const uint32_t thread_counts[] = { 1, 2, 8, 2 };
#define THREAD_COUNTS (sizeof(thread_counts) / sizeof(thread_counts[0]))

static bvhlab_plugin *plugin;
static const char *builder = "ploc"; /* or "hploc", from the command line */

struct setup {
	uint32_t radius;
	bool collapse;
};

/* A setup_build_fn: setup is a struct setup. */
static int build_valid(const char *name, const bvhlab_build_input *in, const void *setup,
                       uint32_t threads, bvhlab_tree *tree)
{
	const struct setup *s = setup;
	bvhlab_options opts;
	bvhlab_error err = { { 0 } };
	int rc = bvhlab_options_init(&opts, bvhlab_plugin_builder(plugin));

	if (rc == 0)
		rc = bvhlab_options_set_int(&opts, "radius", s->radius, &err);
	if (rc == 0 && strcmp(builder, "hploc") == 0)
		rc = bvhlab_options_set_int(&opts, "threshold", s->radius, &err);
	if (rc == 0)
		rc = bvhlab_options_set_bool(&opts, "collapse", s->collapse, &err);
	if (rc == 0)
		rc = bvhlab_build(plugin, &opts, in, threads, tree, &err);
	if (rc == 0)
		rc = bvhlab_validate_tree(tree, in, false, &err);
	if (rc != 0) {
		fprintf(stderr, "%s radius=%u collapse=%d threads=%u: %s\n", name, s->radius,
		        s->collapse, threads, err.message);
		CHECK(!"valid build");
	}
	bvhlab_options_finish(&opts);
	return rc;
}

/* The 1-thread tree in full, every other thread count against it;
 * returns its SAH cost. */
static double check_radius(const char *name, const bvhlab_scene *scene,
                           const bvhlab_build_input *in, uint32_t radius, bool collapse,
                           uint32_t rays)
{
	struct setup s = { .radius = radius, .collapse = collapse };
	struct setup_check c = { .build = build_valid, .setup = &s, .collapse = collapse,
	                         .most = collapse ? 8 : 1, .threads = thread_counts,
	                         .thread_count = THREAD_COUNTS, .ray_seed = RAY_SEED };

	return check_threads_same(name, scene, in, &c, rays);
}

static void test_scene(const char *name, bvhlab_scene *scene, uint32_t rays)
{
	static const uint32_t radii[] = { 1, 4, 16 };

	compare_collapse(name, scene, rays, "radius", radii, sizeof(radii) / sizeof(radii[0]),
	                 check_radius);
}

static void test_descriptor(void)
{
	const bvhlab_builder *b = bvhlab_plugin_builder(plugin);
	bvhlab_options opts;
	bvhlab_error err = { { 0 } };

	bool h = strcmp(builder, "hploc") == 0;

	CHECK(strcmp(b->name, builder) == 0);
	CHECK(b->flags & BVHLAB_BUILDER_DETERMINISTIC);
	CHECK(b->build != NULL);
	CHECK(bvhlab_builder_refine(b) == NULL);
	CHECK_INT(bvhlab_options_init(&opts, b), 0);
	CHECK_INT(opts.values[bvhlab_options_find(&opts, "radius")].i, h ? 8 : 16);
	CHECK(bvhlab_options_set_int(&opts, "radius", 0, &err) < 0);
	CHECK(bvhlab_options_set_int(&opts, "radius", h ? 33 : 65, &err) < 0);
	if (h) {
		CHECK_INT(opts.values[bvhlab_options_find(&opts, "threshold")].i, 16);
		CHECK(bvhlab_options_set_int(&opts, "threshold", 0, &err) < 0);
		CHECK(bvhlab_options_set_int(&opts, "threshold", 33, &err) < 0);
	}
	bvhlab_options_finish(&opts);
}

static void test_shared(const char *file, bvhlab_scene *scene)
{
	test_scene(file, scene, 64);
}

int main(int argc, char **argv)
{
	static const char *const shared[] = { "stanford-bunny.obj", "horse.ply", "ogre.obj",
	                                      "igea.ply" };

	if (argc > 1)
		builder = argv[1];
	if (!plugin_loads(builder, &plugin))
		return test_finish();
	test_descriptor();
	test_scene("soup", generate("soup", SCALE(20000, 3000), 0, 0), RAYS);
	test_scene("icosphere", generate("icosphere", 0, SCALE(30, 10), 0), RAYS);
	test_scene("stadium", generate("stadium", SCALE(20000, 3000), 0, 0), RAYS);
	test_scene("identical", identical_scene(SCALE(3000, 600)), RAYS);
	test_scene("needles", needle_scene(SCALE(5000, 800)), RAYS);
	test_scene("one", generate("soup", 1, 0, 0), RAYS);
	test_scene("two", generate("soup", 2, 0, 0), RAYS);
	test_scene("three", generate("soup", 3, 0, 0), RAYS);
	(void)for_shared(shared, sizeof(shared) / sizeof(shared[0]), 1, test_shared);
	bvhlab_plugin_close(plugin);
	return test_finish();
}
