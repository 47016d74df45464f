/*
 * sah_seq: both methods on every generator and on degenerate scenes build
 * valid trees that trace like brute force, respect max_leaf, repeat
 * exactly, and the exact sweep is at least as good as binning. Quality
 * fast builds valid, repeatable trees too, the same with either SIMD path,
 * and where every centroid lies on one axis (so that high's search has no
 * other axis either) exactly high's tree. Its options are declared with
 * their ranges.
 */
#include <errno.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include <bvhlab/bvhlab.h>

#include "testutil.h"

#define FIXTURE_SEED 7
#include "scene_fixture.h"

#define RAYS 512
#define RAY_SEED 12345

static const char *const methods[] = { "sweep", "binned" };
static const uint32_t leaf_sizes[] = { 1, 4, 8, 16 };
/* The quality option of build(); test_quality switches it. */
static const char *quality = "high";
#define LEAF_SIZES (sizeof(leaf_sizes) / sizeof(leaf_sizes[0]))

/* A leaf over max_leaf is allowed only when all its centroids coincide. */
static void check_leaves(const bvhlab_tree *tree, const bvhlab_build_input *in,
                         uint32_t max_leaf)
{
	for (uint32_t i = 0; i < tree->node_count; i++) {
		const bvhlab_node *node = &tree->nodes[i];
		if (node->count <= max_leaf)
			continue;
		const float *c0 = &in->centroids[3 * (size_t)tree->prim_index[node->first]];
		for (uint32_t j = 1; j < node->count; j++) {
			const float *c = &in->centroids[3 * (size_t)tree->prim_index[node->first + j]];
			CHECK(c[0] == c0[0] && c[1] == c0[1] && c[2] == c0[2]);
		}
	}
}

static int build(const bvhlab_plugin *plugin, const bvhlab_build_input *in, const char *method,
                 uint32_t max_leaf, bvhlab_tree *tree)
{
	bvhlab_options opts;
	bvhlab_error err = { { 0 } };
	int rc;

	CHECK_INT(bvhlab_options_init(&opts, bvhlab_plugin_builder(plugin)), 0);
	CHECK_INT(bvhlab_options_set_string(&opts, "method", method, &err), 0);
	CHECK_INT(bvhlab_options_set_int(&opts, "max_leaf", max_leaf, &err), 0);
	CHECK_INT(bvhlab_options_set_string(&opts, "quality", quality, &err), 0);
	rc = bvhlab_build(plugin, &opts, in, 1, tree, &err);
	if (rc < 0)
		fprintf(stderr, "build %s %s max_leaf=%u: %s\n", method, quality, max_leaf,
		        err.message);
	bvhlab_options_finish(&opts);
	return rc;
}

/* Builds, checks everything about the tree and returns its SAH cost. */
static double build_checked(const bvhlab_plugin *plugin, const char *name,
                            const bvhlab_scene *scene, const bvhlab_build_input *in,
                            const char *method, uint32_t max_leaf)
{
	bvhlab_tree tree = { 0 }, again = { 0 };
	bvhlab_tree_stats stats;
	bvhlab_error err = { { 0 } };
	uint64_t mismatches = 1;
	double cost = -1;

	CHECK_INT(build(plugin, in, method, max_leaf, &tree), 0);
	if (bvhlab_validate_tree(&tree, in, false, &err) != 0) {
		fprintf(stderr, "%s %s max_leaf=%u: %s\n", name, method, max_leaf, err.message);
		CHECK(!"valid tree");
		goto out;
	}
	CHECK_INT(tree.index_count, in->prim_count);
	CHECK(tree.node_count <= 2 * in->prim_count - 1);
	CHECK_INT(bvhlab_validate_rays(&tree, scene, RAYS, RAY_SEED, &mismatches, &err), 0);
	CHECK_INT(mismatches, 0);
	check_leaves(&tree, in, max_leaf);
	bvhlab_tree_stats_compute(&tree, &stats);
	cost = stats.sah_cost;
	/* Twice the same input: the same tree. */
	CHECK_INT(build(plugin, in, method, max_leaf, &again), 0);
	CHECK_INT(again.node_count, tree.node_count);
	if (bvhlab_tree_compare(&tree, &again, &err) != 0) {
		fprintf(stderr, "%s %s max_leaf=%u rebuilt: %s\n", name, method, max_leaf,
		        err.message);
		CHECK(!"repeatable");
	}
out:
	bvhlab_tree_finish(&tree);
	bvhlab_tree_finish(&again);
	return cost;
}

static void test_scene(const bvhlab_plugin *plugin, const char *name, bvhlab_scene *scene)
{
	bvhlab_prims prims;
	bvhlab_error err = { { 0 } };

	if (!scene)
		return;
	CHECK_INT(bvhlab_prims_init(&prims, scene, &err), 0);
	for (size_t l = 0; l < LEAF_SIZES; l++) {
		double cost[2];
		for (int m = 0; m < 2; m++)
			cost[m] = build_checked(plugin, name, scene, &prims.input, methods[m],
			                        leaf_sizes[l]);
		printf("%-10s %7u triangles  max_leaf %2u  SAH sweep %10.4f  binned %10.4f\n",
		       name, scene->triangle_count, leaf_sizes[l], cost[0], cost[1]);
		/* Both methods split nodes of at most 64 primitives exactly
		 * (the kernel's small subtrees), so over such scenes they build
		 * the same tree. Above, each sweep split is the best of a
		 * superset of the binned candidates; over a whole greedy tree
		 * that holds on meshes (cli-shared checks it strictly) but not
		 * on a random soup, where a locally worse split higher up can
		 * come out ahead lower down, by a hair: hence the 0.5 %. */
		if (scene->triangle_count <= 64)
			CHECK(cost[0] == cost[1]);
		else
			CHECK(cost[0] <= cost[1] * 1.005);
	}
	bvhlab_prims_finish(&prims);
	bvhlab_scene_destroy(scene);
}

static void test_descriptor(const bvhlab_plugin *plugin)
{
	const bvhlab_builder *b = bvhlab_plugin_builder(plugin);
	static const char *const names[] = { "method", "bins", "max_leaf", "c_trav", "c_isect",
	                                     "simd", "quality" };

	CHECK(strcmp(b->name, "sah_seq") == 0);
	CHECK(b->summary && *b->summary);
	CHECK(b->flags & BVHLAB_BUILDER_DETERMINISTIC);
	CHECK(!(b->flags & BVHLAB_BUILDER_PARALLEL));
	CHECK_INT(b->option_count, 7);
	for (uint32_t i = 0; i < b->option_count && i < 7; i++) {
		CHECK(strcmp(b->options[i].name, names[i]) == 0);
		CHECK(b->options[i].help && *b->options[i].help);
	}
	CHECK(strcmp(b->options[0].def_string, "sweep") == 0);
	CHECK_INT(b->options[1].def_int, 32);
	CHECK_INT(b->options[2].def_int, 8);
	CHECK(b->options[3].def_float == 1.0 && b->options[4].def_float == 1.0);
	CHECK(strcmp(b->options[5].def_string, "auto") == 0);
	CHECK(strcmp(b->options[6].def_string, "high") == 0);
}

static void test_options(const bvhlab_plugin *plugin)
{
	bvhlab_options opts;
	bvhlab_error err = { { 0 } };

	CHECK_INT(bvhlab_options_init(&opts, bvhlab_plugin_builder(plugin)), 0);
	CHECK_INT(bvhlab_options_set_int(&opts, "bins", 1, &err), -EINVAL);
	CHECK_CONTAINS(err.message, "bins");
	CHECK_INT(bvhlab_options_set_int(&opts, "bins", 257, &err), -EINVAL);
	CHECK_CONTAINS(err.message, "bins");
	CHECK_INT(bvhlab_options_set_int(&opts, "max_leaf", 0, &err), -EINVAL);
	CHECK_CONTAINS(err.message, "max_leaf");
	CHECK_INT(bvhlab_options_set_float(&opts, "c_trav", 0, &err), -EINVAL);
	CHECK_CONTAINS(err.message, "c_trav");
	CHECK_INT(bvhlab_options_set_string(&opts, "method", "median", &err), -EINVAL);
	CHECK_CONTAINS(err.message, "method");
	CHECK_INT(bvhlab_options_set_string(&opts, "quality", "low", &err), -EINVAL);
	CHECK_CONTAINS(err.message, "quality");
	CHECK_INT(bvhlab_options_set_int(&opts, "bins", 2, &err), 0);
	CHECK_INT(bvhlab_options_set_int(&opts, "bins", 256, &err), 0);
	bvhlab_options_finish(&opts);
}

/* With traversal made expensive the SAH wants big leaves: max_leaf caps them. */
static void test_max_leaf_binds(const bvhlab_plugin *plugin, const bvhlab_prims *prims)
{
	/* Parsed in turn: sweep and binned at quality high, then at fast. */
	const char *const settings[] = { "method=sweep", "method=binned", "quality=fast",
	                                 "method=sweep" };
	bvhlab_tree tree = { 0 };
	bvhlab_tree_stats stats;
	bvhlab_error err = { { 0 } };
	bvhlab_options opts;

	CHECK_INT(bvhlab_options_init(&opts, bvhlab_plugin_builder(plugin)), 0);
	CHECK_INT(bvhlab_options_parse(&opts, "c_trav=1000", &err), 0);
	for (uint32_t max_leaf = 2; max_leaf <= 16; max_leaf *= 2) {
		CHECK_INT(bvhlab_options_set_int(&opts, "max_leaf", max_leaf, &err), 0);
		CHECK_INT(bvhlab_options_parse(&opts, "quality=high", &err), 0);
		for (size_t i = 0; i < 4; i++) {
			CHECK_INT(bvhlab_options_parse(&opts, settings[i], &err), 0);
			CHECK_INT(bvhlab_build(plugin, &opts, &prims->input, 1, &tree, &err), 0);
			CHECK_INT(bvhlab_validate_tree(&tree, &prims->input, false, &err), 0);
			check_leaves(&tree, &prims->input, max_leaf);
			bvhlab_tree_stats_compute(&tree, &stats);
			CHECK(stats.leaf_histogram[max_leaf - 1] > 0);
		}
	}
	bvhlab_options_finish(&opts);
	bvhlab_tree_finish(&tree);
}

/* Other bins and costs still give valid trees; bins does not affect sweep. */
static void test_option_values(const bvhlab_plugin *plugin)
{
	bvhlab_scene *scene = generate("icosphere", 0, 12, 0);
	bvhlab_prims prims;
	bvhlab_options opts;
	bvhlab_tree a = { 0 }, b = { 0 };
	bvhlab_error err = { { 0 } };

	if (!scene || bvhlab_prims_init(&prims, scene, &err) < 0) {
		CHECK(!"icosphere input");
		bvhlab_scene_destroy(scene);
		return;
	}
	CHECK_INT(bvhlab_options_init(&opts, bvhlab_plugin_builder(plugin)), 0);
	CHECK_INT(bvhlab_build(plugin, &opts, &prims.input, 1, &a, &err), 0);
	CHECK_INT(bvhlab_options_set_int(&opts, "bins", 2, &err), 0);
	CHECK_INT(bvhlab_build(plugin, &opts, &prims.input, 1, &b, &err), 0);
	CHECK_INT(bvhlab_tree_compare(&a, &b, &err), 0);
	const char *const settings[] = { "method=binned", "bins=256", "bins=2", "c_trav=0.25",
	                                 "c_isect=4", "max_leaf=64" };
	for (size_t i = 0; i < sizeof(settings) / sizeof(settings[0]); i++) {
		CHECK_INT(bvhlab_options_parse(&opts, settings[i], &err), 0);
		CHECK_INT(bvhlab_build(plugin, &opts, &prims.input, 2, &b, &err), 0);
		CHECK_INT(bvhlab_validate_tree(&b, &prims.input, false, &err), 0);
	}
	bvhlab_options_finish(&opts);
	test_max_leaf_binds(plugin, &prims);
	bvhlab_tree_finish(&a);
	bvhlab_tree_finish(&b);
	bvhlab_prims_finish(&prims);
	bvhlab_scene_destroy(scene);
}

/* The 8-lane and 4-lane binning fill the same bins: same trees, for
 * every bin count (2 and 256 reach the grid's ends), at both qualities. On a CPU without
 * AVX2 an explicit simd=avx2 is refused, naming the option. */
static void test_simd(const bvhlab_plugin *plugin)
{
	static const char *const scenes[] = { "soup", "terrain", "stadium" };
	static const char *const bins[] = { "bins=2", "bins=32", "bins=256" };
	bvhlab_tree a = { 0 }, b = { 0 };
	bvhlab_error err = { { 0 } };
	bvhlab_options opts;

	CHECK_INT(bvhlab_options_init(&opts, bvhlab_plugin_builder(plugin)), 0);
	CHECK_INT(bvhlab_options_parse(&opts, "method=binned", &err), 0);
	for (size_t s = 0; s < 3; s++) {
		bvhlab_scene *scene = generate(scenes[s], 20000, 0, 40);
		bvhlab_prims prims;
		if (!scene || bvhlab_prims_init(&prims, scene, &err) < 0) {
			CHECK(!"simd scene");
			bvhlab_scene_destroy(scene);
			continue;
		}
		for (size_t i = 0; i < 6; i++) {
			CHECK_INT(bvhlab_options_parse(&opts, bins[i % 3], &err), 0);
			CHECK_INT(bvhlab_options_parse(&opts, i < 3 ? "quality=high" : "quality=fast",
			                               &err), 0);
			CHECK_INT(bvhlab_options_parse(&opts, "simd=sse", &err), 0);
			CHECK_INT(bvhlab_build(plugin, &opts, &prims.input, 1, &a, &err), 0);
			CHECK_INT(bvhlab_options_parse(&opts, "simd=avx2", &err), 0);
			int rc = bvhlab_build(plugin, &opts, &prims.input, 1, &b, &err);
			if (rc == -ENOTSUP) {
				CHECK_CONTAINS(err.message, "simd");
				printf("simd: no AVX2 here, avx2 refused\n");
				continue;
			}
			CHECK_INT(rc, 0);
			CHECK_INT(bvhlab_tree_compare(&a, &b, &err), 0);
		}
		bvhlab_prims_finish(&prims);
		bvhlab_scene_destroy(scene);
	}
	bvhlab_options_finish(&opts);
	bvhlab_tree_finish(&a);
	bvhlab_tree_finish(&b);
}

/* n triangles of varied sizes whose box centres (the kernel's centroids)
 * all lie on the x axis, in
 * a shuffled order: y and z offer no split, so high searches x alone, as
 * fast does. */
static bvhlab_scene *row_scene(uint32_t n)
{
	bvhlab_scene *scene = blank_scene(3 * n, n);
	uint32_t h = 12345;

	if (!scene)
		return NULL;
	for (uint32_t k = 0; k < n; k++) {
		h = h * 1664525u + 1013904223u;
		float x = (float)((k * 7919u) % n), s = 0.1f + (float)(h >> 24) / 64.0f;
		float w = (float)((h >> 8) & 255) / 32.0f;
		const float v[9] = { x, -s, -s, x, s, -s, x + w, 0, s };
		memcpy(scene->vertices + 9 * (size_t)k, v, sizeof(v));
		for (int i = 0; i < 3; i++)
			scene->indices[3 * k + i] = 3 * k + i;
	}
	bvhlab_scene_update(scene);
	return scene;
}

/* Fast on generated scenes: valid, repeatable (build_checked); on a row,
 * high's tree for both methods. */
static void test_quality(const bvhlab_plugin *plugin)
{
	static const char *const scenes[] = { "soup", "terrain", "stadium" };
	bvhlab_scene *row = row_scene(3000);
	bvhlab_prims prims;
	bvhlab_tree tree[2] = { { 0 }, { 0 } };
	bvhlab_error err = { { 0 } };

	quality = "fast";
	for (size_t s = 0; s < 3; s++) {
		bvhlab_scene *scene = generate(scenes[s], 20000, 0, 40);
		if (!scene || bvhlab_prims_init(&prims, scene, &err) < 0) {
			CHECK(!"fast scene");
			bvhlab_scene_destroy(scene);
			continue;
		}
		for (size_t m = 0; m < 2; m++)
			CHECK(build_checked(plugin, scenes[s], scene, &prims.input, methods[m], 8) > 0);
		bvhlab_prims_finish(&prims);
		bvhlab_scene_destroy(scene);
	}
	if (row && bvhlab_prims_init(&prims, row, &err) == 0) {
		for (size_t m = 0; m < 2; m++) {
			for (int q = 0; q < 2; q++) {
				quality = q ? "fast" : "high";
				CHECK_INT(build(plugin, &prims.input, methods[m], 8, &tree[q]), 0);
			}
			if (bvhlab_tree_compare(&tree[0], &tree[1], &err) != 0) {
				fprintf(stderr, "row %s: fast differs from high: %s\n", methods[m],
				        err.message);
				CHECK(!"fast is high's tree on a row");
			}
		}
		bvhlab_prims_finish(&prims);
	}
	quality = "high";
	bvhlab_tree_finish(&tree[0]);
	bvhlab_tree_finish(&tree[1]);
	bvhlab_scene_destroy(row);
}

int main(void)
{
	bvhlab_plugin *plugin = NULL;

	if (!plugin_loads("sah_seq", &plugin))
		return test_finish();
	test_descriptor(plugin);
	test_options(plugin);
	test_option_values(plugin);
	test_simd(plugin);
	test_quality(plugin);
	test_scene(plugin, "soup", generate("soup", 20000, 0, 0));
	test_scene(plugin, "icosphere", generate("icosphere", 0, 24, 0));
	test_scene(plugin, "stadium", generate("stadium", 10000, 0, 0));
	test_scene(plugin, "terrain", generate("terrain", 0, 0, 48));
	test_scene(plugin, "identical", identical_scene(1000));
	test_scene(plugin, "one", generate("soup", 1, 0, 0));
	test_scene(plugin, "two", generate("soup", 2, 0, 0));
	test_scene(plugin, "soup64", generate("soup", 64, 0, 0));
	bvhlab_plugin_close(plugin);
	return test_finish();
}
