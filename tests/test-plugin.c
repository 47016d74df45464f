/*
 * Plugin loading: every way a plugin can be unusable gives one clear error
 * naming it; a good plugin loads by name and by path and builds.
 */
#include <errno.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <unistd.h>

#include <bvhlab/bvhlab.h>

#include "testutil.h"

#define FAKE_DIR BVHLAB_TEST_BUILDDIR "/fake"

static void expect_open_error(const char *name, int code, const char *needle)
{
	bvhlab_plugin *p = (bvhlab_plugin *)1;
	bvhlab_error err = {{0}};
	int r = bvhlab_plugin_open(name, &p, &err);
	CHECK_INT(r, code);
	CHECK(p == NULL);
	CHECK_CONTAINS(err.message, needle);
	CHECK_CONTAINS(err.message, strrchr(name, '/') ? strrchr(name, '/') + 1 : name);
}

static void test_broken_plugins(void)
{
	expect_open_error("no_such_plugin", -ENOENT, "not found on the search path");
	expect_open_error("fake_noentry", -ENOEXEC, "no entry point 'bvhlab_plugin_entry'");
	expect_open_error("fake_abi2", -ENOTSUP, "built for ABI 2.0");
	expect_open_error("fake_short", -EINVAL, "struct_size 16 is smaller");
	expect_open_error("fake_nobuild", -EINVAL, "no build function");
	expect_open_error("fake_nulldesc", -ENOTSUP, "returned no builder");
	expect_open_error("fake_badopt", -EINVAL, "option 5 has no name or an unknown type");
	expect_open_error("/nonexistent/dir/x.so", -ENOENT, "cannot load");
}

static void test_not_a_library(void)
{
	char dir[] = "/tmp/bvhlab-test-XXXXXX";
	CHECK(mkdtemp(dir) != NULL);
	char path[256];
	snprintf(path, sizeof(path), "%s/garbage.so", dir);
	FILE *f = fopen(path, "w");
	CHECK(f != NULL);
	fputs("this is not an ELF file\n", f);
	fclose(f);
	expect_open_error(path, -ENOEXEC, "cannot load");
	unlink(path);
	rmdir(dir);
}

/* A 2-triangle scene's build input, by hand. */
static void tiny_input(bvhlab_build_input *in, bvhlab_aabb boxes[2], float cents[6])
{
	static const float verts[] = {0, 0, 0, 1, 0, 0, 0, 1, 0, 2, 2, 2};
	static const uint32_t idx[] = {0, 1, 2, 1, 2, 3};
	boxes[0] = (bvhlab_aabb){{0, 0, 0}, {1, 1, 0}};
	boxes[1] = (bvhlab_aabb){{0, 0, 0}, {2, 2, 2}};
	const float c[6] = {0.5f, 0.5f, 0, 1, 1, 1};
	memcpy(cents, c, sizeof(c));
	*in = (bvhlab_build_input){
		.struct_size = sizeof(*in), .prim_count = 2, .prim_bounds = boxes,
		.centroids = cents, .bounds = {{0, 0, 0}, {2, 2, 2}},
		.centroid_bounds = {{0.5f, 0.5f, 0}, {1, 1, 1}}, .vertices = verts,
		.vertex_count = 4, .indices = idx, .threads = 1};
}

static int build_with(bvhlab_plugin *p, const char *assignment, bvhlab_tree *tree,
                      bvhlab_error *err)
{
	bvhlab_build_input in;
	bvhlab_aabb boxes[2];
	float cents[6];
	tiny_input(&in, boxes, cents);
	bvhlab_options opts;
	CHECK_INT(bvhlab_options_init(&opts, bvhlab_plugin_builder(p)), 0);
	if (assignment)
		CHECK_INT(bvhlab_options_parse(&opts, assignment, err), 0);
	int r = bvhlab_build(p, &opts, &in, 1, tree, err);
	if (r == 0)
		CHECK_INT(bvhlab_validate_tree(tree, &in, false, err), 0);
	bvhlab_options_finish(&opts);
	return r;
}

static void test_good_plugin(void)
{
	bvhlab_plugin *p = NULL;
	bvhlab_error err = {{0}};
	CHECK_INT(bvhlab_plugin_open("fake_good", &p, &err), 0);
	if (!p)
		return;
	CHECK(strcmp(bvhlab_plugin_builder(p)->name, "fake_good") == 0);
	CHECK_CONTAINS(bvhlab_plugin_path(p), "fake_good.so");
	bvhlab_tree tree = {0};
	CHECK_INT(build_with(p, NULL, &tree, &err), 0);
	CHECK_INT(tree.node_count, 1);
	CHECK_INT(build_with(p, "fail=error", &tree, &err), -EIO);
	CHECK_CONTAINS(err.message, "builder 'fake_good': asked to fail");
	CHECK_INT(build_with(p, "fail=silent", &tree, &err), -EIO);
	CHECK_CONTAINS(err.message, "builder 'fake_good' failed (Input/output error) without");
	CHECK_INT(build_with(p, "fail=positive", &tree, &err), -EPROTO);
	CHECK_CONTAINS(err.message, "returned 1; the ABI allows 0 or a negative errno");
	CHECK_INT(tree.phase_count, 0);
	bvhlab_tree_finish(&tree);
	bvhlab_plugin_close(p);

	/* The same file by path. */
	CHECK_INT(bvhlab_plugin_open(FAKE_DIR "/fake_good.so", &p, &err), 0);
	bvhlab_plugin_close(p);
	bvhlab_plugin_close(NULL);
}

/* ABI 1.3 phases: reports add up by name, in the order first reported, a
 * build starts with none, and a report that breaks the rules fails the
 * build naming the phase. */
static void test_phases(void)
{
	bvhlab_plugin *p = NULL;
	bvhlab_error err = {{0}};
	bvhlab_tree tree = {0};
	CHECK_INT(bvhlab_plugin_open("fake_good", &p, &err), 0);
	if (!p)
		return;
	CHECK_INT(build_with(p, "phases=two", &tree, &err), 0);
	CHECK_INT(tree.phase_count, 2);
	CHECK(strcmp(tree.phases[0].name, "upload") == 0 && tree.phases[0].ms == 1.5);
	CHECK(strcmp(tree.phases[1].name, "device") == 0 && tree.phases[1].ms == 2.5);
	CHECK_INT(build_with(p, NULL, &tree, &err), 0);
	CHECK_INT(tree.phase_count, 0);
	CHECK_INT(build_with(p, "phases=bad_name", &tree, &err), -EPROTO);
	CHECK_CONTAINS(err.message, "builder 'fake_good' reported phase 'Device Time'");
	CHECK_INT(build_with(p, "phases=negative", &tree, &err), -EPROTO);
	CHECK_CONTAINS(err.message, "reported phase 'device' (-1 ms)");
	CHECK_INT(build_with(p, "phases=too_many", &tree, &err), -EPROTO);
	CHECK_CONTAINS(err.message, "'p8' (more than 8 phases)");
	CHECK_INT(build_with(p, "phases=huge", &tree, &err), -EPROTO);
	CHECK_CONTAINS(err.message, "'device' (2e+12 ms): times are finite, >= 0 and at most 1e12");
	CHECK_INT(build_with(p, "phases=long", &tree, &err), -EPROTO);
	CHECK_CONTAINS(err.message, "'device' (5000 ms) in a build that took");
	CHECK_CONTAINS(err.message, "a phase is part of its build, never longer");
	bvhlab_tree_finish(&tree);
	bvhlab_plugin_close(p);
}

static void test_names(void)
{
	char **names = NULL;
	bvhlab_error err = {{0}};
	CHECK_INT(bvhlab_plugin_names(&names, &err), 0);
	int good = 0, seq = 0;
	for (char **n = names; n && *n; n++) {
		good += strcmp(*n, "fake_good") == 0;
		seq += strcmp(*n, "sah_seq") == 0;
	}
	CHECK_INT(good, 1);
	CHECK_INT(seq, 1);
	bvhlab_plugin_names_free(names);
}

int main(void)
{
	test_broken_plugins();
	test_not_a_library();
	test_good_plugin();
	test_phases();
	test_names();
	return test_finish();
}
