/*
 * sbvh: valid trees (coverage of clipped references, sampled rays against
 * brute force) on soups, needles, a mixed-scale composite with huge
 * diagonal triangles, coincident and tiny scenes; the same tree
 * (bvhlab_tree_compare) for 1, 2, 3 and 8 threads, with the team split
 * forced deep by a low parallel_min and with the default; the reference
 * budget respected; spatial splits lowering the SAH cost against the same
 * builder with them off (alpha = 1), which builds no duplicates; and
 * pre-splitting cutting the needles' SAH by more than a fifth.
 */
#include <errno.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include <bvhlab/bvhlab.h>

#include "testutil.h"

#define FIXTURE_SEED 11
#include "scene_fixture.h"

#define RAYS 512

static const uint32_t thread_counts[] = { 1, 2, 3, 8 };
static bvhlab_plugin *sbvh;

/* Builds with the options in `extra` (comma-free list, NULL-terminated),
 * validates as a spatial-split tree and traces rays. 0 or the failure. */
static int build_valid(const char *const *extra, const bvhlab_scene *scene,
                       const bvhlab_build_input *in, uint32_t threads, bvhlab_tree *tree)
{
	bvhlab_options opts;
	bvhlab_error err = { { 0 } };
	uint64_t bad = 0;
	int rc = bvhlab_options_init(&opts, bvhlab_plugin_builder(sbvh));

	for (const char *const *o = extra; rc == 0 && o && *o; o++)
		rc = bvhlab_options_parse(&opts, *o, &err);
	if (rc == 0)
		rc = bvhlab_build(sbvh, &opts, in, threads, tree, &err);
	if (rc == 0)
		rc = bvhlab_validate_tree(tree, in, true, &err);
	if (rc == 0)
		rc = bvhlab_validate_rays(tree, scene, RAYS, 0x5eed, &bad, &err);
	if (rc != 0 || bad != 0) {
		fprintf(stderr, "sbvh %s threads=%u: %s (%llu ray mismatches)\n",
		        extra && extra[0] ? extra[0] : "", threads, err.message,
		        (unsigned long long)bad);
		CHECK(!"valid build");
		rc = rc ? rc : -EINVAL;
	}
	bvhlab_options_finish(&opts);
	return rc;
}

static double sah(const bvhlab_tree *t)
{
	bvhlab_tree_stats s;
	bvhlab_tree_stats_compute(t, &s);
	return s.sah_cost;
}

/* Every thread count gives the 1-thread tree. */
static void check_threads(const char *name, const char *const *extra,
                          const bvhlab_scene *scene, const bvhlab_build_input *in,
                          double split_factor)
{
	bvhlab_tree one = { 0 }, tree = { 0 };
	bvhlab_error err = { { 0 } };

	if (build_valid(extra, scene, in, 1, &one) == 0) {
		CHECK(one.index_count <= ceil(split_factor * in->prim_count));
		for (size_t t = 1; t < sizeof(thread_counts) / sizeof(thread_counts[0]); t++) {
			if (build_valid(extra, scene, in, thread_counts[t], &tree) != 0)
				continue;
			if (bvhlab_tree_compare(&one, &tree, &err) != 0) {
				fprintf(stderr, "%s %s: %u threads differ from 1: %s\n", name,
				        extra && extra[0] ? extra[0] : "", thread_counts[t], err.message);
				CHECK(!"same tree");
			}
		}
	}
	bvhlab_tree_finish(&one);
	bvhlab_tree_finish(&tree);
}

/* Spatial splits on: duplicates, a lower SAH than with them off. */
static void check_spatial_gain(const char *name, const bvhlab_scene *scene,
                               const bvhlab_build_input *in)
{
	static const char *const off[] = { "alpha=1", NULL };
	bvhlab_tree with = { 0 }, without = { 0 };

	if (build_valid(NULL, scene, in, 2, &with) == 0 &&
	    build_valid(off, scene, in, 2, &without) == 0) {
		CHECK_INT(without.index_count, in->prim_count);
		CHECK(with.index_count > in->prim_count);
		CHECK(sah(&with) < sah(&without));
		printf("%-10s SAH %.3f with spatial splits (%u refs), %.3f without\n", name,
		       sah(&with), with.index_count, sah(&without));
	}
	bvhlab_tree_finish(&with);
	bvhlab_tree_finish(&without);
}

static void test_scene(const char *name, bvhlab_scene *scene, bool gain)
{
	static const char *const deep[] = { "parallel_min=64", NULL };
	static const char *const budget[] = { "parallel_min=64", "split_factor=2", NULL };
	static const char *const none[] = { "split_factor=1", NULL };
	static const char *const pre[] = { "parallel_min=64", "presplit=0.5", "split_factor=2",
		                           NULL };
	static const char *const ahead[] = { "parallel_min=64", "lookahead=256", NULL };
	bvhlab_prims prims;
	bvhlab_error err = { { 0 } };

	if (!scene)
		return;
	CHECK_INT(bvhlab_prims_init(&prims, scene, &err), 0);
	check_threads(name, deep, scene, &prims.input, 1.3);
	check_threads(name, NULL, scene, &prims.input, 1.3);
	check_threads(name, budget, scene, &prims.input, 2.0);
	check_threads(name, none, scene, &prims.input, 1.0);
	check_threads(name, pre, scene, &prims.input, 2.0);
	check_threads(name, ahead, scene, &prims.input, 1.3);
	if (gain)
		check_spatial_gain(name, scene, &prims.input);
	printf("%-10s %8u triangles: done\n", name, scene->triangle_count);
	bvhlab_prims_finish(&prims);
	bvhlab_scene_destroy(scene);
}

/* Pre-splitting the needles: more references, a much lower SAH. */
static void check_presplit_gain(const bvhlab_scene *scene)
{
	static const char *const pre[] = { "presplit=1", "split_factor=2", NULL };
	static const char *const off[] = { "alpha=1", NULL };
	bvhlab_prims prims;
	bvhlab_error err = { { 0 } };
	bvhlab_tree with = { 0 }, without = { 0 };

	if (!scene || bvhlab_prims_init(&prims, scene, &err) != 0)
		return;
	if (build_valid(pre, scene, &prims.input, 2, &with) == 0 &&
	    build_valid(off, scene, &prims.input, 2, &without) == 0) {
		CHECK(with.index_count > prims.input.prim_count * 3 / 2);
		CHECK(with.index_count <= 2 * prims.input.prim_count);
		CHECK(sah(&with) < 0.8 * sah(&without));
		printf("needles    SAH %.1f pre-split (%u refs), %.1f plain\n", sah(&with),
		       with.index_count, sah(&without));
	}
	bvhlab_tree_finish(&with);
	bvhlab_tree_finish(&without);
	bvhlab_prims_finish(&prims);
}

/* Terrain under a few huge triangles turned 30 degrees: mixed scales. */
static bvhlab_scene *mixed_scene(void)
{
	static const float big[] = { -1, -1, -1, 1, -1, -1, 1, 1, -1, -1, -1, 1, 1, 1, 1, -1, 1, -1 };
	bvhlab_scene *parts[2] = { generate("terrain", 0, 0, SCALE(40, 16)), NULL };
	bvhlab_scene *out = NULL;
	bvhlab_error err = { { 0 } };
	bvhlab_transform xf;

	if (!parts[0])
		return NULL;
	parts[1] = generate("soup", 6, 0, 0); /* reshaped below into 6 huge triangles */
	if (parts[1]) {
		for (uint32_t v = 0; v < 18; v++)
			parts[1]->vertices[v] = big[v];
		bvhlab_transform_init(&xf);
		xf.rotate[1] = 30;
		xf.rotate[0] = 40;
		bvhlab_scene_transform(parts[1], &xf);
		CHECK_INT(bvhlab_scene_merge(parts, 2, "mixed", &out, &err), 0);
	}
	bvhlab_scene_destroy(parts[0]);
	bvhlab_scene_destroy(parts[1]);
	return out;
}

static bvhlab_scene *needles(uint32_t count)
{
	bvhlab_gen_params p;
	bvhlab_scene *s = NULL;
	bvhlab_error err = { { 0 } };
	bvhlab_gen_params_init(&p);
	p.count = count;
	CHECK_INT(bvhlab_scene_generate("needles", &p, &s, &err), 0);
	return s;
}

static void test_descriptor(void)
{
	const bvhlab_builder *b = bvhlab_plugin_builder(sbvh);

	CHECK(strcmp(b->name, "sbvh") == 0);
	CHECK(b->flags & BVHLAB_BUILDER_PARALLEL);
	CHECK(b->flags & BVHLAB_BUILDER_DETERMINISTIC);
	CHECK(b->flags & BVHLAB_BUILDER_SPATIAL_SPLITS);
	CHECK(b->option_count >= 1 && strcmp(b->options[0].name, "split_factor") == 0 &&
	      b->options[0].def_float == 1.3);
}

int main(void)
{
	if (!plugin_loads("sbvh", &sbvh))
		return test_finish();
	test_descriptor();
	test_scene("soup", generate("soup", SCALE(8000, 2000), 0, 0), true);
	test_scene("needles", needles(SCALE(3000, 800)), false);
	bvhlab_scene *n = needles(SCALE(3000, 800));
	check_presplit_gain(n);
	bvhlab_scene_destroy(n);
	test_scene("mixed", mixed_scene(), false);
	test_scene("identical", identical_scene(SCALE(500, 200)), false);
	test_scene("one", generate("soup", 1, 0, 0), false);
	test_scene("two", generate("soup", 2, 0, 0), false);
	bvhlab_plugin_close(sbvh);
	return test_finish();
}
