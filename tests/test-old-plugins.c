/*
 * Old plugins keep loading unchanged (1.5, 1.6 and 1.7 are minor steps): the C and
 * C++ example templates built against ABI 1.4's headers (tests/abi14) load
 * as 1.4 plugins, and give, for 1 and 2 threads on generated scenes, the
 * very trees (node for node, binary, valid, tracing like brute force) the
 * same templates give built against today's headers. A 1.4 plugin is
 * never given boxes: the host refuses such a build by name.
 */
#include <errno.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include <bvhlab/bvhlab.h>

#include "testutil.h"

#define FIXTURE_SEED 41
#include "scene_fixture.h"

static bool open_variant(const char *name, const char *variant, bvhlab_plugin **p)
{
	char path[1024];
	bvhlab_error err = { { 0 } };
	snprintf(path, sizeof(path), "%s/%s_%s.so", BVHLAB_TEST_BUILDDIR, name, variant);
	if (bvhlab_plugin_open(path, p, &err) == 0)
		return true;
	fprintf(stderr, "%s\n", err.message);
	CHECK(!"template loads");
	return false;
}

static void compare_builds(bvhlab_plugin *old, bvhlab_plugin *now, bvhlab_scene *scene)
{
	bvhlab_prims prims;
	bvhlab_error err = { { 0 } };
	const char *none[] = { NULL };
	CHECK_INT(bvhlab_prims_init(&prims, scene, &err), 0);
	for (uint32_t threads = 1; threads <= 2; threads++) {
		bvhlab_tree a = { 0 }, b = { 0 };
		uint64_t mismatches = 1;
		CHECK_INT(build_with(old, none, &prims.input, threads, &a, &err), 0);
		CHECK_INT(build_with(now, none, &prims.input, threads, &b, &err), 0);
		CHECK_INT(bvhlab_validate_tree(&a, &prims.input, false, &err), 0);
		CHECK_INT(a.width, 2);
		CHECK(trees_identical(&a, &b));
		CHECK_INT(bvhlab_validate_rays(&a, scene, 256, 41, &mismatches, &err), 0);
		CHECK_INT(mismatches, 0);
		bvhlab_tree_finish(&a);
		bvhlab_tree_finish(&b);
	}
	bvhlab_prims_finish(&prims);
	bvhlab_scene_destroy(scene);
}

static void refuse_boxes(bvhlab_plugin *old)
{
	bvhlab_aabb box = { { 0, 0, 0 }, { 1, 1, 1 } };
	bvhlab_prims prims;
	bvhlab_tree t = { 0 };
	bvhlab_error err = { { 0 } };
	const char *none[] = { NULL };
	CHECK_INT(bvhlab_prims_init_boxes(&prims, &box, 1, &err), 0);
	CHECK_INT(build_with(old, none, &prims.input, 1, &t, &err), -ENOTSUP);
	CHECK_CONTAINS(err.message, "builds over triangles only");
	bvhlab_tree_finish(&t);
	bvhlab_prims_finish(&prims);
}

static void test_template(const char *name)
{
	bvhlab_plugin *old = NULL, *now = NULL;
	if (open_variant(name, "abi14", &old) && open_variant(name, "now", &now)) {
		const bvhlab_builder *bo = bvhlab_plugin_builder(old);
		CHECK_INT(BVHLAB_ABI_VERSION_MINOR(bo->abi_version), 4);
		CHECK_INT(BVHLAB_ABI_VERSION_MINOR(bvhlab_plugin_builder(now)->abi_version),
		          BVHLAB_ABI_MINOR);
		CHECK(strcmp(bo->name, bvhlab_plugin_builder(now)->name) == 0);
		/* 1.7's peak_bytes_per_prim lies past a 1.4 descriptor: not read. */
		bool declared = true;
		CHECK_INT(bvhlab_builder_peak_bytes_per_prim(bo, NULL, &declared),
		          BVHLAB_UNDECLARED_BYTES_PER_PRIM);
		CHECK(!declared);
		printf("%s: ABI 1.4 and 1.%d builds of '%s'\n", name, BVHLAB_ABI_MINOR, bo->name);
		compare_builds(old, now, generate("soup", 3000, 0, 0));
		compare_builds(old, now, generate("stadium", 2000, 0, 0));
		compare_builds(old, now, generate("terrain", 0, 0, 24));
		refuse_boxes(old);
	}
	bvhlab_plugin_close(old);
	bvhlab_plugin_close(now);
}

int main(void)
{
	test_template("template");
	test_template("template_cpp");
	return test_finish();
}
