/*
 * The OpenCL device builders against their CPU references: on every shared
 * mesh and on generated scenes (degenerate ones included: every centroid
 * equal, one, two and three triangles, needles, zero-area triangles),
 * cl_lbvh's tree equals lbvh's, cl_ploc's ploc's and cl_hploc's hploc's
 * under the canonical compare, for a few option setups, and every tree is
 * valid.
 * The device builds report the phases upload, device and download, the
 * device time within the whole call. A bad `device` option fails the build
 * with a message naming it.
 *
 * One process for everything: the OpenCL compiler (PoCL) builds each
 * plugin's kernels once per process. Skips (77) when there is no OpenCL
 * device, saying why. The meshes get two setups; the sanitizer builds
 * run smaller generated scenes only (UNDER_SANITIZER).
 */
#include <errno.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <time.h>

#include <bvhlab/bvhlab.h>

#include "../testutil.h"

#define FIXTURE_SEED 30
#include "../scene_fixture.h"
#include "../refine_scenes.h"

/* One option setup: the same options for the reference and the device
 * builder ("key=value" for bvhlab_options_parse), and one for the device
 * builder only (may be NULL). */
struct setup {
	const char *opts[4];
	const char *dev_only[3];
};

struct pair {
	const char *ref_name, *dev_name;
	bvhlab_plugin *ref, *dev;
	struct setup setups[3];
	struct setup differ[2]; /* two setups that build different trees */
	double dev_ms, ref_ms; /* summed over all builds, for the log */
};

static struct pair pairs[] = {
	{ .ref_name = "lbvh", .dev_name = "cl_lbvh",
	  .setups = { { { "bits=63", "collapse=true" } },
	              { { "bits=30", "collapse=false" } },
	              /* Karras's searches, a work-item per leaf, the sort's passes
	               * over all keys: what a GPU runs */
	              { { "max_leaf=3", "c_trav=2.5" },
	                { "leaf_block=1", "hierarchy=search", "sort=passes" } } },
	  .differ = { { { "max_leaf=2" } }, { { "max_leaf=8" } } } },
	{ .ref_name = "ploc", .dev_name = "cl_ploc",
	  .setups = { { { "radius=16", "collapse=true" } },
	              { { "radius=1", "collapse=false" } },
	              /* a work-item per cluster in nearest: what a GPU runs */
	              { { "radius=4", "bits=30" }, { "nn_block=1" } } },
	  .differ = { { { "radius=1" } }, { { "radius=16" } } } },
	{ .ref_name = "hploc", .dev_name = "cl_hploc",
	  .setups = { { { "radius=8", "threshold=16", "collapse=true" } },
	              { { "radius=1", "threshold=1", "collapse=false", "bits=30" } },
	              { { "radius=4", "threshold=32", "max_leaf=3", "c_trav=2.5" } } },
	  .differ = { { { "threshold=2" } }, { { "threshold=16" } } } },
};
#define PAIRS (sizeof(pairs) / sizeof(pairs[0]))

static double now_ms(void)
{
	struct timespec ts;

	clock_gettime(CLOCK_MONOTONIC, &ts);
	return ts.tv_sec * 1e3 + ts.tv_nsec / 1e6;
}

static int build(bvhlab_plugin *p, const struct setup *s, const char *device,
                 const bvhlab_build_input *in, bvhlab_tree *tree, double *ms,
                 bvhlab_error *err)
{
	bvhlab_options opts;
	char dev[64];
	int rc = bvhlab_options_init(&opts, bvhlab_plugin_builder(p));

	for (int k = 0; k < 4 && rc == 0 && s->opts[k]; k++)
		rc = bvhlab_options_parse(&opts, s->opts[k], err);
	if (rc == 0 && device) {
		snprintf(dev, sizeof(dev), "device=%s", device);
		rc = bvhlab_options_parse(&opts, dev, err);
	}
	for (int k = 0; k < 3 && rc == 0 && device && s->dev_only[k]; k++)
		rc = bvhlab_options_parse(&opts, s->dev_only[k], err);
	double t0 = now_ms();
	if (rc == 0)
		rc = bvhlab_build(p, &opts, in, 2, tree, err);
	*ms = now_ms() - t0;
	if (rc == 0)
		rc = bvhlab_validate_tree(tree, in, false, err);
	bvhlab_options_finish(&opts);
	return rc;
}

static double phase(const bvhlab_tree *t, const char *name)
{
	for (uint32_t k = 0; k < t->phase_count; k++)
		if (!strcmp(t->phases[k].name, name))
			return t->phases[k].ms;
	return -1;
}

/* The device build's phases: each there, none negative, the kernels'
 * time within the whole call. */
static void check_phases(const char *what, const bvhlab_tree *t, double whole_ms)
{
	double up = phase(t, "upload"), dev = phase(t, "device"), down = phase(t, "download");

	if (up < 0 || dev < 0 || down < 0 || dev > whole_ms) {
		fprintf(stderr, "%s: phases upload %.3f device %.3f download %.3f, call %.3f ms\n",
		        what, up, dev, down, whole_ms);
		CHECK(!"phases upload, device, download reported, device <= whole call");
	}
}

static void check_setup(struct pair *p, const struct setup *s, const char *name,
                        const bvhlab_build_input *in)
{
	bvhlab_tree ref = { 0 }, dev = { 0 };
	bvhlab_error err = { { 0 } };
	char what[160];
	double ref_ms, dev_ms;

	snprintf(what, sizeof(what), "%s %s %s %s", p->dev_name, name, s->opts[0],
	         s->opts[1] ? s->opts[1] : "");
	if (build(p->ref, s, NULL, in, &ref, &ref_ms, &err) != 0) {
		fprintf(stderr, "%s (reference %s): %s\n", what, p->ref_name, err.message);
		CHECK(!"reference builds a valid tree");
	} else if (build(p->dev, s, "auto", in, &dev, &dev_ms, &err) != 0) {
		fprintf(stderr, "%s: %s\n", what, err.message);
		CHECK(!"device builder builds a valid tree");
	} else {
		int rc = bvhlab_tree_compare(&ref, &dev, &err);
		if (rc != 0) {
			fprintf(stderr, "%s: not %s's tree: %s\n", what, p->ref_name, err.message);
			CHECK(!"device tree equals the reference's");
		}
		if (in->prim_count > 1)
			check_phases(what, &dev, dev_ms);
		p->ref_ms += ref_ms;
		p->dev_ms += dev_ms;
	}
	bvhlab_tree_finish(&ref);
	bvhlab_tree_finish(&dev);
}

/* The first `setups` setups of every pair on one scene; destroys it. */
static void test_setups(const char *name, bvhlab_scene *scene, size_t setups)
{
	bvhlab_prims prims;
	bvhlab_error err = { { 0 } };

	if (!scene)
		return;
	CHECK_INT(bvhlab_prims_init(&prims, scene, &err), 0);
	for (size_t k = 0; k < PAIRS; k++)
		for (size_t s = 0; pairs[k].dev && s < setups; s++)
			check_setup(&pairs[k], &pairs[k].setups[s], name, &prims.input);
	printf("%-20s %8u triangles\n", name, scene->triangle_count);
	bvhlab_prims_finish(&prims);
	bvhlab_scene_destroy(scene);
}

static void test_scene(const char *name, bvhlab_scene *scene)
{
	test_setups(name, scene, 3);
}

/* The meshes: the default setup (collapse) and 30-bit codes without. */
static void test_shared(const char *file, bvhlab_scene *scene)
{
	test_setups(file, scene, 2);
}

/* n triangles of zero area: points scattered on a plane, and segments. */
static bvhlab_scene *zero_area_scene(uint32_t n)
{
	bvhlab_scene *scene = blank_scene(3 * n, n);

	if (!scene)
		return NULL;
	for (uint32_t i = 0; i < n; i++) {
		float x = (float)(i * 7919 % 1000) * 0.01f, y = (float)(i % 13), *v;
		v = scene->vertices + 9 * (size_t)i;
		v[0] = x, v[1] = y, v[2] = 0;
		v[3] = i % 2 ? x : x + 0.5f, v[4] = y, v[5] = 0;
		v[6] = x, v[7] = y, v[8] = 0;
		for (int k = 0; k < 3; k++)
			scene->indices[3 * (size_t)i + k] = 3 * i + (uint32_t)k;
	}
	bvhlab_scene_update(scene);
	return scene;
}

/* A device spec that is not one fails the build, naming it; one that
 * names no device too. */
static void test_bad_device(struct pair *p)
{
	bvhlab_scene *scene = generate("soup", 100, 0, 0);
	bvhlab_prims prims;
	bvhlab_tree tree = { 0 };
	bvhlab_error err = { { 0 } };
	double ms;

	if (!scene || bvhlab_prims_init(&prims, scene, &err) != 0)
		return;
	CHECK(build(p->dev, &p->setups[0], "banana", &prims.input, &tree, &ms, &err) < 0);
	/* the plugin's fill_options check, at the build when nobody checked before */
	CHECK_CONTAINS(err.message, "option 'device' is 'banana': allowed are auto, gpu, cpu or P:D");
	CHECK(build(p->dev, &p->setups[0], "7:3", &prims.input, &tree, &ms, &err) < 0);
	CHECK_CONTAINS(err.message, "device '7:3': no such OpenCL device");
	bvhlab_tree_finish(&tree);
	bvhlab_prims_finish(&prims);
	bvhlab_scene_destroy(scene);
}

/* The compare tells trees apart: the device builder with one setup
 * against its reference with another that changes the tree. */
static void test_compare_sees(struct pair *p)
{
	bvhlab_scene *scene = generate("soup", 3000, 0, 0);
	bvhlab_prims prims;
	bvhlab_tree ref = { 0 }, dev = { 0 };
	bvhlab_error err = { { 0 } };
	double ms;

	if (!scene || bvhlab_prims_init(&prims, scene, &err) != 0)
		return;
	CHECK_INT(build(p->ref, &p->differ[1], NULL, &prims.input, &ref, &ms, &err), 0);
	CHECK_INT(build(p->dev, &p->differ[0], "auto", &prims.input, &dev, &ms, &err), 0);
	CHECK_INT(bvhlab_tree_compare(&ref, &dev, &err), 1);
	bvhlab_tree_finish(&ref);
	bvhlab_tree_finish(&dev);
	bvhlab_prims_finish(&prims);
	bvhlab_scene_destroy(scene);
}

/* Whether the device builders can run here: a one-triangle build. */
static bool device_works(struct pair *p, char *why, size_t size)
{
	bvhlab_scene *scene = generate("soup", 1, 0, 0);
	bvhlab_prims prims;
	bvhlab_tree tree = { 0 };
	bvhlab_error err = { { 0 } };
	double ms;
	int rc = -1;

	if (scene && bvhlab_prims_init(&prims, scene, &err) == 0) {
		rc = build(p->dev, &p->setups[0], "auto", &prims.input, &tree, &ms, &err);
		bvhlab_prims_finish(&prims);
	}
	snprintf(why, size, "%s", err.message);
	bvhlab_tree_finish(&tree);
	bvhlab_scene_destroy(scene);
	return rc == 0;
}

static bool open_pairs(void)
{
	bvhlab_error err = { { 0 } };

	for (size_t k = 0; k < PAIRS; k++) {
		if (bvhlab_plugin_open(pairs[k].dev_name, &pairs[k].dev, &err) != 0) {
			printf("%s not built: %s\n", pairs[k].dev_name, err.message);
			pairs[k].dev = NULL;
			continue;
		}
		if (!plugin_loads(pairs[k].ref_name, &pairs[k].ref))
			return false;
	}
	return pairs[0].dev != NULL;
}

int main(void)
{
	static const char *const shared[] = { "stanford-bunny.obj", "horse.ply", "ogre.obj",
	                                      "igea.ply", "nefertiti.obj", "sponza.obj",
	                                      "conference.obj" };
	char why[512];

	if (!open_pairs())
		return test_finish();
	if (!device_works(&pairs[0], why, sizeof(why))) {
		/* Only a missing device skips; any other failure is one. */
		if (strstr(why, "no OpenCL platform") || strstr(why, "no such OpenCL device")) {
			printf("skip: no OpenCL device for the device builders: %s\n", why);
			return TEST_SKIP;
		}
		fprintf(stderr, "cl_lbvh fails on one triangle: %s\n", why);
		CHECK(!"device builder runs");
		return test_finish();
	}
	test_bad_device(&pairs[0]);
	for (size_t k = 0; k < PAIRS; k++)
		if (pairs[k].dev)
			test_compare_sees(&pairs[k]);
	test_scene("one", generate("soup", 1, 0, 0));
	test_scene("two", generate("soup", 2, 0, 0));
	test_scene("three", generate("soup", 3, 0, 0));
	test_scene("identical", identical_scene(SCALE(3000, 1000)));
	test_scene("needles", needle_scene(SCALE(5000, 1500)));
	test_scene("zero-area", zero_area_scene(SCALE(4000, 1500)));
	test_scene("soup", generate("soup", SCALE(20000, 4000), 0, 0));
	if (!UNDER_SANITIZER)
		(void)for_shared(shared, sizeof(shared) / sizeof(shared[0]), 0, test_shared);
	else
		printf("sanitizer build: the shared meshes are left to the release build\n");
	for (size_t k = 0; k < PAIRS; k++) {
		if (pairs[k].dev)
			printf("%s %.1f ms, %s %.1f ms in all (2 threads)\n", pairs[k].dev_name,
			       pairs[k].dev_ms, pairs[k].ref_name, pairs[k].ref_ms);
		bvhlab_plugin_close(pairs[k].dev);
		bvhlab_plugin_close(pairs[k].ref);
	}
	return test_finish();
}
