/*
 * Two-level scenes: "meshes" and "instances" in configs (parsing and every
 * error), and the scene they make: matrices and their inverses, scatters,
 * world boxes and the flattened scene.
 */
#include <errno.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "config/config.h"
#include "harness/harness_instances.h"
#include "harness/harness_two_level.h"
#include "trace/trace_instances.h"
#define FIXTURE_SEED 0x42ULL
#include "scene_fixture.h"
#include "testutil.h"
#include "two_level_fixture.h"

#define BUILDERS "\"builders\": [ { \"plugin\": \"sah_seq\" } ]"
#define MESHES "\"meshes\": [ { \"name\": \"ball\", \"generator\": \"icosphere\", " \
	"\"frequency\": 2 }, { \"name\": \"rock\", \"generator\": \"soup\", \"count\": 30 } ]"

static int parse(struct config *cfg, const char *scene, bvhlab_error *err)
{
	char text[4096];
	snprintf(text, sizeof(text), "{ \"scenes\": [ { \"name\": \"grove\", %s } ], " BUILDERS
	         " }", scene);
	return config_parse(cfg, "/cfg/c.json", text, err);
}

static void expect_error(const char *scene, const char *needle)
{
	struct config cfg;
	bvhlab_error err = { "" };
	CHECK_INT(parse(&cfg, scene, &err), -EINVAL);
	CHECK_CONTAINS(err.message, "/cfg/c.json:1:");
	CHECK_CONTAINS(err.message, needle);
	config_finish(&cfg);
}

static const char *const ok_scene =
	MESHES ", \"instances\": ["
	" { \"mesh\": \"ball\", \"scale\": 2, \"rotate\": [0, 30, 0], \"translate\": [1, 2, 3] },"
	" { \"mesh\": \"rock\", \"matrix\": [0, 0, 1, 5, 0, 1, 0, 0, -1, 0, 0, 0] },"
	" { \"scatter\": { \"mesh\": \"ball\", \"count\": 40, \"seed\": 9,"
	"   \"bounds\": [[-10, 0, -10], [10, 1, 10]], \"scale\": [0.5, 2],"
	"   \"rotate\": \"random-y\" } } ]";

static void test_parse(void)
{
	struct config cfg;
	bvhlab_error err = { "" };
	CHECK_INT(parse(&cfg, ok_scene, &err), 0);
	const struct config_scene *sc = &cfg.scenes[0];
	CHECK(sc->mesh_count == 2 && sc->instance_count == 3 && sc->instance_total == 42);
	CHECK(strcmp(sc->meshes[1].name, "rock") == 0 && sc->meshes[1].src.gen.count == 30);
	CHECK(sc->instances[1].mesh == 1 && sc->instances[1].xf[2] == 1.0 &&
	      sc->instances[1].xf[3] == 5.0 && sc->instances[1].xf[8] == -1.0);
	const struct config_instance *s = &sc->instances[2];
	CHECK(s->scatter && s->count == 40 && s->seed == 9 && s->mesh == 0);
	CHECK(s->lo[0] == -10 && s->hi[1] == 1 && s->scale[0] == 0.5 && s->scale[1] == 2);
	CHECK(s->rotate == CONFIG_SCATTER_RANDOM_Y);
	config_finish(&cfg);
}

static void test_errors(void)
{
	expect_error(MESHES ", \"instances\": [ { \"mesh\": \"bal\" } ]",
	             "'scenes[0].instances[0].mesh': scene 'grove' has no mesh 'bal' (did you "
	             "mean 'ball'?)");
	expect_error(MESHES ", \"instances\": [ { \"scatter\": { \"mesh\": \"tree\", "
	             "\"count\": 3, \"bounds\": [[0, 0, 0], [1, 1, 1]] } } ]",
	             "has no mesh 'tree'");
	expect_error(MESHES ", \"instances\": [ { \"mesh\": \"ball\", "
	             "\"matrix\": [1, 0, 0, 0, 0, 1, 0, 0, 0, 0] } ]",
	             "'scenes[0].instances[0].matrix' must be an array of 12 finite numbers");
	expect_error(MESHES ", \"instances\": [ { \"mesh\": \"ball\", "
	             "\"matrix\": [1, 0, 0, 0, 2, 0, 0, 0, 0, 0, 1, 0] } ]",
	             "'scenes[0].instances[0].matrix' is singular");
	expect_error(MESHES ", \"instances\": [ { \"mesh\": \"ball\", \"scale\": 2, "
	             "\"matrix\": [1, 0, 0, 0, 0, 1, 0, 0, 0, 0, 1, 0] } ]",
	             "'scenes[0].instances[0].scale' and 'scenes[0].instances[0].matrix' both");
	expect_error(MESHES ", \"instances\": [ { \"scatter\": { \"mesh\": \"ball\", "
	             "\"count\": 0, \"bounds\": [[0, 0, 0], [1, 1, 1]] } } ]",
	             "'scenes[0].instances[0].scatter.count'");
	expect_error(MESHES ", \"instances\": [ { \"scatter\": { \"mesh\": \"ball\", "
	             "\"count\": 16777217, \"bounds\": [[0, 0, 0], [1, 1, 1]] } } ]",
	             "'scenes[0].instances[0].scatter.count'");
	expect_error(MESHES ", \"instances\": ["
	             " { \"scatter\": { \"mesh\": \"ball\", \"count\": 16777216,"
	             " \"bounds\": [[0, 0, 0], [1, 1, 1]] } }, { \"mesh\": \"rock\" } ]",
	             "16777217 instances in all, more than the 16777216");
	expect_error(MESHES ", \"instances\": [ { \"scatter\": { \"mesh\": \"ball\" } } ]",
	             "'scenes[0].instances[0].scatter.count' is missing");
	expect_error(MESHES ", \"instances\": [ { \"scatter\": { \"mesh\": \"ball\", "
	             "\"count\": 2, \"bounds\": [[0, 0, 0], [1, -1, 1]] } } ]",
	             "'scenes[0].instances[0].scatter.bounds' must be [[x, y, z], [x, y, z]]");
	expect_error(MESHES ", \"instances\": [ { \"scatter\": { \"mesh\": \"ball\", "
	             "\"count\": 2, \"bounds\": [[0, 0, 0], [1, 1, 1]], \"scale\": [2, 1] } } ]",
	             "'scenes[0].instances[0].scatter.scale' must be [a, b] with 0 < a <= b");
	expect_error(MESHES ", \"instances\": [ { \"scatter\": { \"mesh\": \"ball\", "
	             "\"count\": 2, \"bounds\": [[0, 0, 0], [1, 1, 1]], \"rotate\": \"y\" } } ]",
	             "'scenes[0].instances[0].scatter.rotate' must be \"none\" or \"random-y\"");
	expect_error(MESHES ", \"instances\": [ { \"mesh\": \"ball\", \"scatter\": {} } ]",
	             "'scenes[0].instances[0].mesh' beside 'scatter'");
	expect_error(MESHES ", \"instances\": [ { \"mesh\": \"ball\", \"translat\": [0, 0, 0] } ]",
	             "unknown key 'translat' in scenes[0].instances[0]");
	expect_error(MESHES ", \"instances\": [ ]", "'scenes[0].instances' must be a non-empty");
	expect_error(MESHES, "'scenes[0].meshes' without 'instances'");
	expect_error("\"meshes\": [ { \"generator\": \"soup\" } ], \"instances\": [ { \"mesh\": "
	             "\"a\" } ]", "'scenes[0].meshes[0]' needs a 'name'");
	expect_error("\"meshes\": [ { \"name\": \"a\", \"generator\": \"soup\" }, { \"name\": "
	             "\"a\", \"generator\": \"room\" } ], \"instances\": [ { \"mesh\": \"a\" } ]",
	             "mesh 'a' is also scenes[0].meshes[0]'s name");
	expect_error("\"generator\": \"soup\", " MESHES ", \"instances\": [ { \"mesh\": \"a\" } ]",
	             "'scenes[0].generator' does not apply to a scene with 'meshes'");
	expect_error("\"frames\": { \"pattern\": \"f%d.ply\", \"count\": 2 }, " MESHES
	             ", \"instances\": [ { \"mesh\": \"ball\" } ]",
	             "'scenes[0].frames' of a scene with 'instances' is a number of frames");
}

/* Two-level builders: "bottom" and "top" together, on two-level scenes only. */
static void test_builder_errors(void)
{
	static const char *const bad[][2] = {
		{"{ \"bottom\": \"lbvh\" }", "'builders[0].bottom' without 'builders[0].top'"},
		{"{ \"top\": \"lbvh\" }", "'builders[0].top' without 'builders[0].bottom'"},
		{"{ \"top\": \"lbvh\", \"bottom\": \"ploc\", \"plugin\": \"ploc\" }",
		 "'builders[0].plugin' does not apply to a two-level builder"},
		{"{ \"top\": \"lbvh\", \"bottom\": 3 }", "'builders[0].bottom' must be a plugin"},
		{"{ \"plugin\": \"lbvh\", \"top_options\": {} }",
		 "'builders[0].top_options' without 'builders[0].top'"},
		{"{ \"top\": \"lbvh\", \"bottom\": \"ploc\", \"top_options\": 1 }",
		 "'builders[0].top_options' must be an object"},
	};
	char text[4096];
	struct config cfg;
	bvhlab_error err = { "" };
	for (size_t k = 0; k < sizeof(bad) / sizeof(bad[0]); k++) {
		snprintf(text, sizeof(text), "{ \"scenes\": [ { \"name\": \"g\", %s } ], "
		         "\"builders\": [ %s ] }", ok_scene, bad[k][0]);
		CHECK_INT(config_parse(&cfg, "/cfg/c.json", text, &err), -EINVAL);
		CHECK_CONTAINS(err.message, bad[k][1]);
		config_finish(&cfg);
	}
	snprintf(text, sizeof(text), "{ \"scenes\": [ { \"name\": \"g\", %s }, { \"generator\": "
	         "\"soup\" } ], \"builders\": [ { \"top\": \"lbvh\", \"bottom\": \"ploc\" } ] }",
	         ok_scene);
	CHECK_INT(config_parse(&cfg, "/cfg/c.json", text, &err), -EINVAL);
	CHECK_CONTAINS(err.message, "a two-level builder runs on two-level scenes only, and "
	                            "scene 'soup' has no 'instances'");
	config_finish(&cfg);
	snprintf(text, sizeof(text), "{ \"scenes\": [ { \"name\": \"g\", %s } ], \"builders\": "
	         "[ { \"top\": \"lbvh\", \"bottom\": \"ploc\" } ] }", ok_scene);
	CHECK_INT(config_parse(&cfg, "/cfg/c.json", text, &err), 0);
	CHECK(strcmp(cfg.builders[0].name, "two-level[top=lbvh,bottom=ploc]") == 0 &&
	      strcmp(cfg.builders[0].plugin, "ploc") == 0 && strcmp(cfg.builders[0].top, "lbvh") == 0);
	config_finish(&cfg);
}

/* Beside a one-level scene, a two-level builder whose "scenes" leaves it
 * out is fine, and so is an animation beside a static scene it does not
 * run on; config_builder_runs_on answers for each pair, grids alike. */
static void test_builder_scenes(void)
{
	char text[4096];
	struct config cfg;
	bvhlab_error err = { "" };
	snprintf(text, sizeof(text), "{ \"scenes\": [ { \"name\": \"g\", %s }, { \"generator\": "
	         "\"soup\" }, { \"name\": \"moving\", \"generator\": \"soup\", \"frames\": 3 } ], "
	         "\"builders\": [ { \"top\": \"lbvh\", \"bottom\": \"ploc\", \"scenes\": [\"g\"] },"
	         " { \"plugin\": \"lbvh\", \"scenes\": [\"soup\", \"moving\"],"
	         "   \"options\": { \"max_leaf\": { \"grid\": [2, 4] } } },"
	         " { \"plugin\": \"lbvh\", \"name\": \"refitted\", \"scenes\": [\"moving\"],"
	         "   \"animation\": { \"update\": \"refit\" } } ] }", ok_scene);
	CHECK_INT(config_parse(&cfg, "/cfg/c.json", text, &err), 0);
	static const bool runs[4][3] = {{true, false, false}, {false, true, true},
	                                {false, true, true}, {false, false, true}};
	CHECK_INT(cfg.builder_count, 4);
	for (size_t b = 0; b < 4 && b < cfg.builder_count; b++)
		for (size_t s = 0; s < 3; s++)
			CHECK(config_builder_runs_on(&cfg.builders[b], &cfg.scenes[s]) == runs[b][s]);
	config_finish(&cfg);
}

static double xf_of(const struct scene_instanced *s, uint32_t i, int k)
{
	return s->instances[i].xf[k];
}

/* The scene a config makes: the meshes once, a scatter drawn from its
 * seed (the same twice), every box holding its instance's vertices, and
 * the flattened scene the composite placement would give, bit for bit. */
static void test_scene(void)
{
	struct config cfg;
	bvhlab_error err = { "" };
	struct scene_instanced a, b;
	CHECK_INT(parse(&cfg, ok_scene, &err), 0);
	CHECK_INT(harness_load_instanced(&cfg.scenes[0], &a, &err), 0);
	CHECK_INT(harness_load_instanced(&cfg.scenes[0], &b, &err), 0);
	CHECK(a.mesh_count == 2 && a.instance_count == 42);
	CHECK(scene_instanced_unique_triangles(&a) == 80 + 30);
	CHECK(scene_instanced_triangles(&a) == 41 * 80 + 30);
	CHECK(memcmp(a.instances, b.instances, 42 * sizeof(*a.instances)) == 0);
	bool spread = false;
	for (uint32_t i = 2; i < a.instance_count; i++) {
		CHECK(xf_of(&a, i, 3) >= -10 && xf_of(&a, i, 3) <= 10);
		CHECK(xf_of(&a, i, 7) >= 0 && xf_of(&a, i, 7) <= 1);
		spread = spread || fabs(xf_of(&a, i, 3) - xf_of(&a, 2, 3)) > 1;
		/* turned about y only: the y axis stays put, scaled */
		CHECK(xf_of(&a, i, 4) == 0 && xf_of(&a, i, 6) == 0 && xf_of(&a, i, 5) >= 0.5);
	}
	CHECK(spread);
	bvhlab_scene *flat = NULL, *ball = NULL;
	CHECK_INT(scene_instanced_flatten(&a, "grove", &flat, &err), 0);
	CHECK(flat && flat->triangle_count == 41 * 80 + 30 && flat->part_count == 42);
	bvhlab_gen_params p;
	bvhlab_gen_params_init(&p);
	p.frequency = 2;
	CHECK_INT(bvhlab_scene_generate("icosphere", &p, &ball, &err), 0);
	bvhlab_transform xf = {.scale = 2, .rotate = {0, 30, 0}, .translate = {1, 2, 3}};
	bvhlab_scene_transform(ball, &xf);
	CHECK(flat && ball && memcmp(flat->vertices, ball->vertices,
	                             3 * ball->vertex_count * sizeof(float)) == 0);
	/* every instance's vertices inside its world box */
	size_t v = 0;
	for (uint32_t i = 0; flat && i < a.instance_count; i++) {
		bvhlab_aabb box;
		scene_instanced_box(&a, i, &box);
		for (uint32_t k = 0; k < a.meshes[a.instances[i].mesh]->vertex_count; k++, v++)
			for (int c = 0; c < 3; c++)
				CHECK(flat->vertices[3 * v + c] >= box.lo[c] &&
				      flat->vertices[3 * v + c] <= box.hi[c]);
	}
	bvhlab_scene_destroy(flat);
	bvhlab_scene_destroy(ball);
	scene_instanced_finish(&a);
	scene_instanced_finish(&b);
	config_finish(&cfg);
}

/* A mesh that does not load fails the scene, naming scene and mesh. */
static void test_load_error(void)
{
	struct config cfg;
	bvhlab_error err = { "" };
	bvhlab_scene *flat = NULL;
	CHECK_INT(parse(&cfg, "\"meshes\": [ { \"name\": \"a\", \"generator\": \"room\" }, "
	                "{ \"name\": \"b\", \"path\": \"/tmp/bvhlab-no-such-mesh.obj\" } ], "
	                "\"instances\": [ { \"mesh\": \"b\" } ]", &err), 0);
	CHECK(harness_load_flattened(&cfg.scenes[0], &flat, &err) < 0 && !flat);
	CHECK_CONTAINS(err.message, "scene 'grove' mesh 1: ");
	CHECK_CONTAINS(err.message, "bvhlab-no-such-mesh.obj");
	config_finish(&cfg);
}

/* m * inv is the identity; a singular matrix is refused. */
static void test_inverse(void)
{
	bvhlab_transform xf = {.scale = 3, .rotate = {10, 20, 30}, .translate = {4, -5, 6}};
	double m[12], inv[12], p[3] = {1.5, -2, 0.25}, q[3], r[3];
	scene_transform_matrix(&xf, m);
	CHECK_INT(scene_matrix_invert(m, inv), 0);
	scene_matrix_apply(m, p, 1.0, q);
	scene_matrix_apply(inv, q, 1.0, r);
	for (int k = 0; k < 3; k++)
		CHECK(fabs(r[k] - p[k]) < 1e-12);
	double flat[12] = {1, 0, 0, 0, 0, 1, 0, 0, 1, 1, 0, 0};
	CHECK_INT(scene_matrix_invert(flat, inv), -EINVAL);
}

/* The two-level SAH recomputed from the trees the series left. */
static double two_level_sah(const struct scene_instanced *s, const struct two_level_trees *t)
{
	bvhlab_tree_stats st;
	double mesh[2], root = bvhlab_box_area(t->top.nodes[0].lo, t->top.nodes[0].hi);
	for (uint32_t m = 0; m < 2; m++) {
		bvhlab_tree_stats_compute(&t->bottom[m], &st);
		mesh[m] = st.sah_cost;
	}
	bvhlab_tree_stats_compute(&t->top, &st);
	double sah = st.sah_cost;
	for (uint32_t i = 0; i < s->instance_count; i++) {
		bvhlab_aabb b;
		scene_instanced_box(s, i, &b);
		sah += bvhlab_box_area(b.lo, b.hi) / root * mesh[s->instances[i].mesh];
	}
	return sah;
}

/* Every CPU traversal through both levels (trace_two_level_prepare): no
 * disagreement with brute force over the instanced triangles or over the
 * flattened scene, and for every ray the stack traversal's very hit. */
static void check_traversals(const struct scene_instanced *inst, struct two_level_trees *trees,
                             const bvhlab_scene *flat, const char *what)
{
	static const int kinds[] = {BVHLAB_TRAVERSAL_STACK, BVHLAB_TRAVERSAL_STACKLESS,
	                            BVHLAB_TRAVERSAL_WIDE, BVHLAB_TRAVERSAL_WIDE4,
	                            BVHLAB_TRAVERSAL_WIDE8};
	struct trace_two_level ref = {.inst = inst, .top = &trees->top, .bottom = trees->bottom};
	bvhlab_aabb b;
	memcpy(b.lo, trees->top.nodes[0].lo, sizeof(b.lo));
	memcpy(b.hi, trees->top.nodes[0].hi, sizeof(b.hi));
	for (size_t k = 0; k < sizeof(kinds) / sizeof(kinds[0]); k++) {
		struct trace_two_level tl = ref;
		uint64_t mismatches = 1, flat_mismatches = 1, differ = 0;
		CHECK_INT(trace_two_level_prepare(&tl, kinds[k]), 0);
		trace_two_level_check(&tl, flat, 500, 11, &mismatches, &flat_mismatches);
		for (uint32_t i = 0; i < 500; i++) {
			bvhlab_ray ray;
			struct trace_inst_hit a, h;
			trace_two_level_ray(inst, &b, 11, i, &ray);
			trace_two_level_closest(&ref, &ray, &a, NULL);
			trace_two_level_closest(&tl, &ray, &h, NULL);
			differ += a.instance != h.instance || a.hit.prim != h.hit.prim ||
			          memcmp(&a.hit.t, &h.hit.t, sizeof(a.hit.t)) != 0;
		}
		if (mismatches || flat_mismatches || differ)
			fprintf(stderr, "%s, %s: %llu against brute force, %llu against the flat "
			        "scene, %llu against the stack traversal\n", what,
			        bvhlab_traversal_name(kinds[k]), (unsigned long long)mismatches,
			        (unsigned long long)flat_mismatches, (unsigned long long)differ);
		CHECK(mismatches == 0 && flat_mismatches == 0 && differ == 0);
		trace_two_level_release(&tl);
		CHECK(tl.views == NULL && tl.top_parents == NULL);
	}
	struct trace_two_level tl = ref;
	CHECK_INT(trace_two_level_prepare(&tl, BVHLAB_TRAVERSAL_DEVICE_STACK), -EINVAL);
}

/* The bottom trees collapsed to 8 wide (wide_collapse), so wide8 walks
 * 8-lane nodes as built, and the top to 4: every traversal again. */
static void check_wide_bottoms(const struct scene_instanced *inst, struct two_level_trees *trees,
                               const bvhlab_scene *flat)
{
	if (collapse_levels(inst, trees, 8, 4))
		check_traversals(inst, trees, flat, "8-wide bottoms, 4-wide top");
}

/* Rays through both levels: the brute force over every instanced triangle
 * gives the same (instance, primitive, t), and the flattened scene the
 * same hits; a top tree whose leaves name the wrong instances is caught. */
static void check_trace(const struct scene_instanced *inst, struct two_level_trees *trees)
{
	struct trace_two_level tl = {.inst = inst, .top = &trees->top, .bottom = trees->bottom};
	bvhlab_scene *flat = NULL;
	bvhlab_error err = { "" };
	uint64_t mismatches = 1, flat_mismatches = 1, hits = 0;
	CHECK_INT(scene_instanced_flatten(inst, "flat", &flat, &err), 0);
	trace_two_level_check(&tl, flat, 1000, 7, &mismatches, &flat_mismatches);
	CHECK(mismatches == 0 && flat_mismatches == 0);
	for (uint32_t i = 0; i < 1000; i++) { /* and the check saw hits, not only misses */
		bvhlab_ray ray;
		struct trace_inst_hit h;
		bvhlab_aabb b;
		memcpy(b.lo, trees->top.nodes[0].lo, sizeof(b.lo));
		memcpy(b.hi, trees->top.nodes[0].hi, sizeof(b.hi));
		trace_two_level_ray(inst, &b, 7, i, &ray);
		trace_two_level_closest(&tl, &ray, &h, NULL);
		hits += h.hit.prim != BVHLAB_NO_HIT;
		CHECK(h.hit.prim == BVHLAB_NO_HIT || h.instance < inst->instance_count);
	}
	CHECK(hits > 300);
	check_traversals(inst, trees, flat, "binary trees");
	uint32_t *ix = trees->top.prim_index, keep = ix[0];
	ix[0] = ix[trees->top.index_count - 1];
	ix[trees->top.index_count - 1] = keep;
	trace_two_level_check(&tl, NULL, 1000, 7, &mismatches, NULL);
	CHECK(mismatches > 0);
	ix[trees->top.index_count - 1] = ix[0];
	ix[0] = keep;
	check_wide_bottoms(inst, trees, flat);
	bvhlab_scene_destroy(flat);
}

/* Each box-taking builder as a top (sbvh without spatial splits: every
 * instance once), over bottoms of another builder; both levels valid and
 * measured apart, the whole's figures their sums. */
static void test_two_level(void)
{
	static const char *const pairs[][2] = {{"sah_seq", "lbvh"}, {"ploc", "sah_tasks"},
	                                       {"lbvh", "sbvh"}, {"sbvh", "ploc"}};
	struct config cfg;
	bvhlab_error err = { "" };
	struct scene_instanced inst;
	CHECK_INT(parse(&cfg, ok_scene, &err), 0);
	CHECK_INT(harness_load_instanced(&cfg.scenes[0], &inst, &err), 0);
	for (size_t p = 0; p < sizeof(pairs) / sizeof(pairs[0]); p++) {
		bvhlab_plugin *bottom = NULL, *top = NULL;
		bvhlab_options bo, to;
		if (!plugin_loads(pairs[p][0], &bottom) || !plugin_loads(pairs[p][1], &top))
			continue;
		CHECK_INT(bvhlab_options_init(&bo, bvhlab_plugin_builder(bottom)), 0);
		CHECK_INT(bvhlab_options_init(&to, bvhlab_plugin_builder(top)), 0);
		struct two_level_job job = {.inst = &inst, .bottom = bottom, .top = top,
		                            .bottom_opts = &bo, .top_opts = &to, .warmup = 0,
		                            .repeat = 2, .threads = 2, .validate_rays = 32};
		double samples[2], cold;
		struct tree_measure whole;
		struct results_two_level lv;
		struct two_level_trees trees;
		int v = harness_two_level_series(&job, samples, &cold, &whole, &lv, &trees, &err);
		if (v != TREE_OK)
			fprintf(stderr, "%s under %s: %s\n", pairs[p][0], pairs[p][1], err.message);
		CHECK_INT(v, TREE_OK);
		CHECK(whole.valid && whole.rays_checked == 96 && whole.mismatches == 0);
		CHECK(samples[0] > 0 && samples[1] > 0);
		CHECK(lv.bottom.trees == 2 && lv.top.trees == 1 && trees.top.index_count == 42);
		CHECK(strcmp(lv.bottom.plugin, pairs[p][0]) == 0 && strcmp(lv.top.plugin,
		                                                           pairs[p][1]) == 0);
		CHECK(whole.stats.nodes == lv.bottom.nodes + lv.top.nodes);
		CHECK(lv.sah > lv.top.sah && fabs(lv.sah - two_level_sah(&inst, &trees)) < 1e-9);
		CHECK(whole.stats.sah_cost == lv.sah);
		check_trace(&inst, &trees);
		harness_two_level_finish(&trees);
		bvhlab_options_finish(&bo);
		bvhlab_options_finish(&to);
		bvhlab_plugin_close(bottom);
		bvhlab_plugin_close(top);
	}
	scene_instanced_finish(&inst);
	config_finish(&cfg);
}

int main(void)
{
	test_parse();
	test_errors();
	test_builder_errors();
	test_builder_scenes();
	test_scene();
	test_inverse();
	test_load_error();
	test_two_level();
	return test_finish();
}
