/*
 * The refinement stages (ABI 1.2 refine), reinsert and treelet: after
 * lbvh, sah_seq and ploc, on generated scenes (coincident centroids,
 * needles, 2 and 3 triangles) and shared meshes, the refined tree is
 * valid, traces like brute force, keeps its index count, never has a
 * higher SAH cost than the tree it started from (and lower where the
 * builder left room), and is the same tree, node for node, for 1 and 2
 * threads. Also: the descriptors, the host's refusals, a config's
 * "refine" list and the harness's timed series with stages. Both modes:
 * leaves split and re-cut by the SAH (the node count may change), and
 * leaves kept. treelet on scenes of at most 8 triangles, where one
 * treelet holds them all, must find the least SAH of every binary tree
 * over them, found here by enumerating the trees. reinsert runs with
 * its children moves (Bittner et al.) and, on a few scenes, without, and
 * with its batch chosen by area.
 */
#include <errno.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include <bvhlab/aabb.h>
#include <bvhlab/bvhlab.h>

#include "config/config.h"
#include "harness/harness_series.h"
#include "testutil.h"

#define FIXTURE_SEED 18
#include "scene_fixture.h"
#include "refine_scenes.h"

#define RAYS 256
#define RAY_SEED 1818

/* The stage under test and the options the tests give it. */
static bvhlab_plugin *refiner;
static const char *refiner_options;

static double sah(const bvhlab_tree *t)
{
	bvhlab_tree_stats st;

	bvhlab_tree_stats_compute(t, &st);
	return st.sah_cost;
}

static const char *b_name(void)
{
	return bvhlab_plugin_builder(refiner)->name;
}

/* Leaves split and re-cut (the default), or subtree moves only. */
static bool split_leaves = true;

/* Refines `tree` in place with the test's options; 0 or the failure. */
static int refine(const bvhlab_build_input *in, uint32_t threads, bvhlab_tree *tree)
{
	bvhlab_options opts;
	bvhlab_error err = { { 0 } };
	int rc = bvhlab_options_init(&opts, bvhlab_plugin_builder(refiner));

	for (const char *o = refiner_options; rc == 0 && *o; o += strlen(o) + 1)
		rc = bvhlab_options_parse(&opts, o, &err);
	if (rc == 0)
		rc = bvhlab_options_set_bool(&opts, "leaves", split_leaves, &err);
	if (rc == 0)
		rc = bvhlab_refine(refiner, &opts, in, threads, tree, &err);
	if (rc < 0)
		fprintf(stderr, "refine: %s\n", err.message);
	bvhlab_options_finish(&opts);
	return rc;
}

/* One builder's tree, refined with 1 and 2 threads. */
static void check_builder(const char *name, const char *builder, const bvhlab_scene *scene,
                          const bvhlab_build_input *in, uint32_t rays)
{
	bvhlab_plugin *p = NULL;
	bvhlab_options opts = { 0 };
	bvhlab_tree built = { 0 }, one = { 0 }, two = { 0 };
	bvhlab_error err = { { 0 } };
	uint64_t mismatches = 1;
	double before, after;

	if (bvhlab_plugin_open(builder, &p, &err) < 0 || bvhlab_options_init(&opts,
	    bvhlab_plugin_builder(p)) < 0 || bvhlab_build(p, &opts, in, 2, &built, &err) < 0) {
		fprintf(stderr, "%s %s: %s\n", name, builder, err.message);
		CHECK(!"builder builds");
		goto out;
	}
	tree_dup(&one, &built);
	tree_dup(&two, &built);
	CHECK_INT(refine(in, 1, &one), 0);
	CHECK_INT(refine(in, 2, &two), 0);
	CHECK_INT(bvhlab_validate_tree(&one, in, false, &err), 0);
	CHECK_INT(bvhlab_validate_rays(&one, scene, rays, RAY_SEED, &mismatches, &err), 0);
	CHECK_INT(mismatches, 0);
	/* reinsert's moves keep every node; a new cut of leaves does not */
	if (!split_leaves && strcmp(b_name(), "reinsert") == 0)
		CHECK_INT(one.node_count, built.node_count);
	CHECK_INT(one.index_count, built.index_count);
	before = sah(&built);
	after = sah(&one);
	printf("%-8s %-18s %-8s %8u triangles  leaves %d  SAH %9.4f -> %9.4f\n",
	       bvhlab_plugin_builder(refiner)->name, name, builder, scene->triangle_count,
	       split_leaves, before, after);
	CHECK(after <= before * (1 + 1e-12));
	CHECK(trees_identical(&one, &two));
	/* Again on the refined tree: still never higher. */
	CHECK_INT(refine(in, 2, &two), 0);
	CHECK_INT(bvhlab_validate_tree(&two, in, false, &err), 0);
	CHECK(sah(&two) <= after * (1 + 1e-12));
out:
	bvhlab_tree_finish(&built);
	bvhlab_tree_finish(&one);
	bvhlab_tree_finish(&two);
	if (opts.values)
		bvhlab_options_finish(&opts);
	bvhlab_plugin_close(p);
}

/* Every builder on one scene, in both modes. */
static void test_scene(const char *name, bvhlab_scene *scene, uint32_t rays)
{
	static const char *const builders[] = { "lbvh", "sah_seq", "ploc" };
	bvhlab_prims prims;
	bvhlab_error err = { { 0 } };

	if (!scene)
		return;
	CHECK_INT(bvhlab_prims_init(&prims, scene, &err), 0);
	for (int mode = 0; mode < 2; mode++) {
		split_leaves = mode == 0;
		for (size_t b = 0; b < sizeof(builders) / sizeof(builders[0]); b++)
			check_builder(name, builders[b], scene, &prims.input, rays);
	}
	split_leaves = true;
	bvhlab_prims_finish(&prims);
	bvhlab_scene_destroy(scene);
}

/* On a real mesh lbvh leaves room: the refinement must find some. */
static void test_improves(void)
{
	bvhlab_scene *scene = generate("icosphere", 0, SCALE(40, 12), 0);
	bvhlab_plugin *lbvh = NULL;
	bvhlab_options opts = { 0 };
	bvhlab_prims prims = { 0 };
	bvhlab_tree tree = { 0 };
	bvhlab_error err = { { 0 } };

	if (!scene || bvhlab_prims_init(&prims, scene, &err) < 0 ||
	    bvhlab_plugin_open("lbvh", &lbvh, &err) < 0 ||
	    bvhlab_options_init(&opts, bvhlab_plugin_builder(lbvh)) < 0 ||
	    bvhlab_build(lbvh, &opts, &prims.input, 1, &tree, &err) < 0) {
		CHECK(!"lbvh on an icosphere");
	} else {
		double before = sah(&tree);
		CHECK_INT(refine(&prims.input, 2, &tree), 0);
		CHECK(sah(&tree) < before * 0.99);
	}
	bvhlab_tree_finish(&tree);
	if (opts.values)
		bvhlab_options_finish(&opts);
	bvhlab_plugin_close(lbvh);
	bvhlab_prims_finish(&prims);
	bvhlab_scene_destroy(scene);
}

/* A refinement-only plugin cannot build; a builder cannot refine. */
static void test_descriptor(void)
{
	const bvhlab_builder *b = bvhlab_plugin_builder(refiner);
	bvhlab_scene *scene = generate("soup", 50, 0, 0);
	bvhlab_plugin *lbvh = NULL;
	bvhlab_options opts, lopts = { 0 };
	bvhlab_prims prims = { 0 };
	bvhlab_tree tree = { 0 };
	bvhlab_error err = { { 0 } };

	CHECK(b->build == NULL && bvhlab_builder_refine(b) != NULL);
	CHECK_INT(bvhlab_options_init(&opts, b), 0);
	if (scene && bvhlab_prims_init(&prims, scene, &err) == 0) {
		CHECK_INT(bvhlab_build(refiner, &opts, &prims.input, 1, &tree, &err), -ENOTSUP);
		CHECK_CONTAINS(err.message, "refine");
		CHECK_INT(bvhlab_plugin_open("lbvh", &lbvh, &err), 0);
		CHECK_INT(bvhlab_options_init(&lopts, bvhlab_plugin_builder(lbvh)), 0);
		CHECK_INT(bvhlab_build(lbvh, &lopts, &prims.input, 1, &tree, &err), 0);
		CHECK_INT(bvhlab_refine(lbvh, &lopts, &prims.input, 1, &tree, &err), -ENOTSUP);
	}
	bvhlab_options_finish(&opts);
	if (lopts.values)
		bvhlab_options_finish(&lopts);
	bvhlab_plugin_close(lbvh);
	bvhlab_tree_finish(&tree);
	bvhlab_prims_finish(&prims);
	bvhlab_scene_destroy(scene);
}

/* "refine" in a config: the default name, and errors naming the key. */
static void test_config(void)
{
	static const char *const bad[][2] = {
		{ "\"refine\": 3", "builders[0].refine" },
		{ "\"refine\": []", "builders[0].refine" },
		{ "\"refine\": [{\"options\": {}}]", "builders[0].refine[0]" },
		{ "\"refine\": [{\"plugin\": \"reinsert\", \"batch\": 1}]", "batch" },
	};
	const char *head = "{\"format_version\": 1, \"scenes\": [{\"generator\": \"soup\"}], "
	                   "\"builders\": [{\"plugin\": \"lbvh\", ";
	char text[512];
	struct config cfg;
	bvhlab_error err = { { 0 } };

	snprintf(text, sizeof(text), "%s\"refine\": [{\"plugin\": \"reinsert\", \"options\": "
	         "{\"batch\": 0.1}}, {\"plugin\": \"reinsert\"}]}]}", head);
	CHECK_INT(config_parse(&cfg, "t.json", text, &err), 0);
	if (cfg.builder_count == 1) {
		CHECK(strcmp(cfg.builders[0].name, "lbvh+reinsert+reinsert") == 0);
		CHECK_INT(cfg.builders[0].refine_count, 2);
	}
	config_finish(&cfg);
	for (size_t k = 0; k < sizeof(bad) / sizeof(bad[0]); k++) {
		snprintf(text, sizeof(text), "%s%s}]}", head, bad[k][0]);
		err.message[0] = '\0';
		CHECK(config_parse(&cfg, "t.json", text, &err) < 0);
		CHECK_CONTAINS(err.message, bad[k][1]);
	}
}

/* The harness's series: the stages run after every build, their SAH is
 * taken around them on the last repeat, and the tree it keeps is the
 * refined one. */
static void test_series(void)
{
	bvhlab_scene *scene = generate("icosphere", 0, SCALE(24, 8), 0);
	bvhlab_plugin *lbvh = NULL;
	bvhlab_options opts = { 0 }, ropts = { 0 };
	bvhlab_prims prims = { 0 };
	bvhlab_error err = { { 0 } };
	double samples[3];
	struct stage_metrics out[2];
	struct refine_stage stages[2];
	struct build_series s = { .warmup = 1, .repeat = 3, .threads = 2, .samples_ms = samples,
	                          .stages = stages, .stage_count = 2, .stage_out = out };

	if (!scene || bvhlab_prims_init(&prims, scene, &err) < 0 ||
	    bvhlab_plugin_open("lbvh", &lbvh, &err) < 0 ||
	    bvhlab_options_init(&opts, bvhlab_plugin_builder(lbvh)) < 0 ||
	    bvhlab_options_init(&ropts, bvhlab_plugin_builder(refiner)) < 0) {
		CHECK(!"series set-up");
		goto out;
	}
	stages[0] = stages[1] = (struct refine_stage){ .plugin = refiner, .opts = &ropts };
	CHECK_INT(harness_time_builds(lbvh, &opts, &prims.input, &s, &err), 0);
	CHECK(strcmp(out[0].plugin, b_name()) == 0 && strcmp(out[1].plugin, b_name()) == 0);
	CHECK(out[0].sah_after < out[0].sah_before);
	CHECK(out[1].sah_before == out[0].sah_after);
	CHECK(out[1].sah_after <= out[1].sah_before);
	CHECK(sah(&s.tree) == out[1].sah_after);
	for (int k = 0; k < 3; k++)
		CHECK(samples[k] > 0);
	CHECK_INT(bvhlab_validate_tree(&s.tree, &prims.input, false, &err), 0);
out:
	bvhlab_tree_finish(&s.tree);
	if (opts.values)
		bvhlab_options_finish(&opts);
	if (ropts.values)
		bvhlab_options_finish(&ropts);
	bvhlab_plugin_close(lbvh);
	bvhlab_prims_finish(&prims);
	bvhlab_scene_destroy(scene);
}

static void test_shared(const char *file, bvhlab_scene *scene)
{
	test_scene(file, scene, 64);
}

/* Least SAH (area units) of any binary tree over the boxes in `set`, one
 * primitive a leaf, by trying every split of every subset: no memo. */
static double best_tree(const bvhlab_aabb *box, uint32_t set)
{
	bvhlab_aabb u;
	double best = INFINITY;

	bvhlab_aabb_empty(&u);
	for (uint32_t i = 0; i < 32; i++)
		if (set >> i & 1)
			bvhlab_aabb_grow(&u, &box[i]);
	if (!(set & (set - 1)))
		return bvhlab_box_area(u.lo, u.hi);
	for (uint32_t l = (set - 1) & set; l; l = (l - 1) & set) {
		double c = best_tree(box, l) + best_tree(box, set ^ l);
		best = c < best ? c : best;
	}
	return bvhlab_box_area(u.lo, u.hi) + best;
}

/* treelet on n <= 8 triangles, one a leaf: the least SAH there is. */
static void test_optimal(uint32_t n)
{
	bvhlab_scene *scene = generate("soup", n, 0, 0);
	bvhlab_plugin *seq = NULL;
	bvhlab_options opts = { 0 };
	bvhlab_prims prims = { 0 };
	bvhlab_tree tree = { 0 };
	bvhlab_error err = { { 0 } };
	const char *saved = refiner_options;

	if (!scene || bvhlab_prims_init(&prims, scene, &err) < 0 ||
	    bvhlab_plugin_open("sah_seq", &seq, &err) < 0 ||
	    bvhlab_options_init(&opts, bvhlab_plugin_builder(seq)) < 0 ||
	    bvhlab_options_parse(&opts, "max_leaf=1", &err) < 0 ||
	    bvhlab_build(seq, &opts, &prims.input, 1, &tree, &err) < 0) {
		CHECK(!"sah_seq on a small soup");
	} else {
		const bvhlab_aabb *b = prims.input.prim_bounds;
		double root = bvhlab_box_area(tree.nodes[0].lo, tree.nodes[0].hi);
		double least = best_tree(b, (1u << n) - 1) / root, before = sah(&tree);

		refiner_options = "size=8\0max_leaf=1\0";
		CHECK_INT(refine(&prims.input, 2, &tree), 0);
		printf("treelet optimal: %u triangles, SAH %.6f -> %.6f, least %.6f\n", n, before,
		       sah(&tree), least);
		CHECK(fabs(sah(&tree) - least) <= 1e-9 * least);
		CHECK_INT(bvhlab_validate_tree(&tree, &prims.input, false, &err), 0);
	}
	refiner_options = saved;
	bvhlab_tree_finish(&tree);
	if (opts.values)
		bvhlab_options_finish(&opts);
	bvhlab_plugin_close(seq);
	bvhlab_prims_finish(&prims);
	bvhlab_scene_destroy(scene);
}

/* reinsert with its first move only (children off): the same checks on
 * a scene where moves are many (the stage's own run has both moves).
 * Not the soup under TSan: the threads share the same search code with
 * children on, which the stage's own run covers there. */
static void test_subtree_moves(void)
{
	const char *saved = refiner_options;

	refiner_options = "batch=0.25\0iterations=3\0children=false\0";
	test_improves();
	if (!UNDER_SANITIZER)
		test_scene("soup", generate("soup", 10000, 0, 0), RAYS);
	refiner_options = saved;
}

/* reinsert choosing its batch by area (the largest nodes, madmann91/bvh's
 * rule) instead of Bittner et al.'s measure: the same checks. */
static void test_area_measure(void)
{
	const char *saved = refiner_options;

	refiner_options = "batch=0.05\0iterations=3\0measure=area\0leaves=false\0";
	test_improves();
	test_scene("soup", generate("soup", SCALE(10000, 2000), 0, 0), RAYS);
	refiner_options = saved;
}

/* Trees of more nodes than reinsert's candidate choice takes in one block
 * (65,536 keys): the blocks are shared out to the threads, each counts
 * its keys in a histogram of its own and partitions its blocks in place,
 * and the candidates still come out the same for 1 and 2 threads. */
static void test_many_blocks(void)
{
	const char *saved = refiner_options;

	refiner_options = "batch=0.02\0iterations=2\0measure=area\0leaves=false\0";
	test_scene("soup", generate("soup", SCALE(200000, 100000), 0, 0), SCALE(RAYS, 16));
	refiner_options = saved;
}

/* Every test of one stage, with the options it is tested with. */
static void test_stage(const char *name, const char *options)
{
	static const char *const shared[] = { "stanford-bunny.obj", "horse.ply" };

	if (!plugin_loads(name, &refiner))
		return;
	refiner_options = options;
	CHECK(strcmp(b_name(), name) == 0);
	test_descriptor();
	test_series();
	test_improves();
	test_scene("soup", generate("soup", SCALE(10000, 2000), 0, 0), RAYS);
	test_scene("identical", identical_scene(SCALE(2000, 400)), RAYS);
	test_scene("needles", needle_scene(SCALE(3000, 600)), RAYS);
	test_scene("two", generate("soup", 2, 0, 0), RAYS);
	test_scene("three", generate("soup", 3, 0, 0), RAYS);
	test_scene("stadium", generate("stadium", SCALE(10000, 2000), 0, 0), RAYS);
	/* No mesh under TSan (97 s there): the generated scenes race the same
	 * search and apply paths. */
	(void)for_shared(shared, sizeof(shared) / sizeof(shared[0]), UNDER_TSAN ? 0 : 1,
	                 test_shared);
	if (strcmp(name, "treelet") == 0)
		for (uint32_t n = 3; n <= 8; n++)
			test_optimal(n);
	if (strcmp(name, "reinsert") == 0) {
		test_subtree_moves();
		test_area_measure();
		test_many_blocks();
	}
	bvhlab_plugin_close(refiner);
	refiner = NULL;
}

int main(void)
{
	test_config();
	test_stage("reinsert", "batch=0.25\0iterations=3\0");
	test_stage("treelet", "rounds=2\0");
	return test_finish();
}
