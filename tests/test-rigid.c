/*
 * Rigid motion of instances (#42 item 4; docs/instances.md, "Animated
 * instances"): an instance's "animate" poses it as documented (frame 0 its
 * rest, a turn about the axis it was placed about adding to its angle);
 * every frame's top, rebuilt or refitted over the moved instances' boxes
 * with the bottom trees of frame 0 kept, is valid and its hits through
 * both levels are the brute force's and the flattened frame's; the
 * harness's frames of a two-level run are valid, the top updated.
 */
#include <errno.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/mman.h>

#include "config/config.h"
#include "harness/harness_anim.h"
#include "harness/harness_anim_top.h"
#include "harness/harness_instances.h"
#include "harness/harness_rays.h"
#include "harness/harness_report.h"
#include "trace/trace_instances.h"
#define FIXTURE_SEED 0x42ULL
#include "scene_fixture.h"
#include "testutil.h"

#define FRAMES 5

static const char *const config_text =
	"{ \"scenes\": [ { \"name\": \"grove\", \"frames\": 5,"
	"  \"meshes\": [ { \"name\": \"ball\", \"generator\": \"icosphere\", \"frequency\": 2 },"
	"                { \"name\": \"rock\", \"generator\": \"soup\", \"count\": 30 } ],"
	"  \"instances\": ["
	"   { \"mesh\": \"rock\", \"scale\": 2, \"rotate\": [0, 30, 0], \"translate\": [1, 2, 3],"
	"     \"animate\": { \"rotate\": [0, 60, 0], \"translate\": [4, 0, 0], \"scale\": 1.5 } },"
	"   { \"mesh\": \"ball\", \"matrix\": [0, 0, 1, 5, 0, 1, 0, 0, -1, 0, 0, 0] },"
	"   { \"scatter\": { \"mesh\": \"ball\", \"count\": 40, \"seed\": 9,"
	"     \"bounds\": [[-10, 0, -10], [10, 1, 10]], \"rotate\": \"random-y\","
	"     \"animate\": { \"rotate\": [0, 180, 45], \"translate\": [0, 6, 0] } } } ] } ],"
	"  \"builders\": [ { \"bottom\": \"sah_seq\", \"top\": \"lbvh\","
	"                  \"animation\": { \"update\": \"refit\" } } ] }";

static bool same_instance(const struct scene_instance *a, const struct scene_instance *b)
{
	return a->mesh == b->mesh && !memcmp(a->xf, b->xf, sizeof(a->xf)) &&
	       !memcmp(a->inv, b->inv, sizeof(a->inv));
}

/* Frame 0 is the rest; instance 0 at the last frame is the part placement
 * scale 2 * 1.5, rotate [0, 90, 0], translate [5, 2, 3]; the static one
 * never moves. */
static void test_pose(const struct harness_anim *a)
{
	struct scene_instanced p0, last;
	bvhlab_error err = { "" };
	bvhlab_transform xf;
	double want[12];
	CHECK_INT(harness_anim_pose_instances(a, 0, &p0, &err), 0);
	CHECK_INT(harness_anim_pose_instances(a, FRAMES - 1, &last, &err), 0);
	CHECK(p0.instance_count == 42 && last.instance_count == 42 && p0.meshes == a->inst->meshes);
	for (uint32_t i = 0; i < 42; i++) /* the fields: padding is nobody's */
		CHECK(same_instance(&p0.instances[i], &a->inst->instances[i]));
	bvhlab_transform_init(&xf);
	xf.scale = 3;
	xf.rotate[1] = 90;
	xf.translate[0] = 5, xf.translate[1] = 2, xf.translate[2] = 3;
	scene_transform_matrix(&xf, want);
	for (int k = 0; k < 12; k++)
		CHECK(fabs(last.instances[0].xf[k] - want[k]) < 1e-12);
	CHECK(same_instance(&last.instances[1], &a->inst->instances[1]));
	CHECK(last.instances[2].xf[7] == a->inst->instances[2].xf[7] + 6);
	harness_anim_posed_finish(&p0);
	harness_anim_posed_finish(&last);
}

/* Each frame's top over the posed boxes, rebuilt (update NULL) or
 * refitted: valid, and its hits those of brute force and of the flattened
 * frame for 400 sampled rays. */
static void run_frames(const struct harness_anim *a, struct two_level_trees *t,
                       const bvhlab_plugin *top, const bvhlab_options *to,
                       const bvhlab_plugin *update, const bvhlab_options *uo)
{
	bvhlab_error err = { "" };
	float root0 = t->top.nodes[0].hi[1];
	for (uint32_t f = 0; f < FRAMES; f++) {
		struct scene_instanced posed;
		bvhlab_scene *flat = NULL;
		bvhlab_aabb boxes[42];
		uint64_t mismatches = 1, flat_mismatches = 1;
		CHECK_INT(harness_anim_pose_instances(a, f, &posed, &err), 0);
		for (uint32_t i = 0; i < 42; i++)
			scene_instanced_box(&posed, i, &boxes[i]);
		bvhlab_prims_finish(&t->top_prims);
		CHECK_INT(bvhlab_prims_init_boxes(&t->top_prims, boxes, 42, &err), 0);
		int r = update ? bvhlab_update(update, uo, &t->top_prims.input, 2, &t->top, &err)
		               : bvhlab_build(top, to, &t->top_prims.input, 2, &t->top, &err);
		CHECK_INT(r, 0);
		CHECK_INT(bvhlab_validate_tree(&t->top, &t->top_prims.input, false, &err), 0);
		CHECK_INT(harness_anim_frame(a, f, &flat, &err), 0);
		CHECK(flat && flat->triangle_count == 30 + 41 * 80);
		struct trace_two_level tl = {.inst = &posed, .top = &t->top, .bottom = t->bottom};
		trace_two_level_check(&tl, flat, 400, 11 + f, &mismatches, &flat_mismatches);
		if (mismatches || flat_mismatches)
			fprintf(stderr, "frame %u (%s): %llu, %llu mismatches\n", f,
			        update ? "refit" : "rebuild", (unsigned long long)mismatches,
			        (unsigned long long)flat_mismatches);
		CHECK(mismatches == 0 && flat_mismatches == 0);
		bvhlab_scene_destroy(flat);
		harness_anim_posed_finish(&posed);
	}
	/* The scatter rose by 6: above the rock, which topped frame 0 at 4. */
	CHECK(t->top.nodes[0].hi[1] > root0 + 4);
}

static void build_series(const struct scene_instanced *inst, const bvhlab_plugin *bottom,
                         const bvhlab_options *bo, const bvhlab_plugin *top,
                         const bvhlab_options *to, struct two_level_trees *trees)
{
	struct two_level_job job = {.inst = inst, .bottom = bottom, .top = top, .bottom_opts = bo,
	                            .top_opts = to, .repeat = 1, .threads = 2,
	                            .validate_rays = 32};
	double samples[1], cold;
	struct tree_measure whole;
	struct results_two_level lv;
	bvhlab_error err = { "" };
	CHECK_INT(harness_two_level_series(&job, samples, &cold, &whole, &lv, trees, &err), TREE_OK);
}

/* The harness's frames of the config's builder: every frame valid, rays
 * checked on the first, middle and last, the later frames refitted; with
 * a camera each frame's primary rays timed and its cost known, without
 * one neither. */
static void test_harness(const struct config *cfg, const struct harness_anim *a,
                         struct two_level_trees *trees, const bvhlab_plugin *top, bool camera)
{
	bvhlab_camera cam;
	bvhlab_aabb root;
	memcpy(root.lo, trees->top.nodes[0].lo, sizeof(root.lo));
	memcpy(root.hi, trees->top.nodes[0].hi, sizeof(root.hi));
	harness_camera_of(cfg, cfg->scenes[0].name, &root, &cam);
	struct harness_builder hb = {.cb = &cfg->builders[0]};
	size_t size = sizeof(struct series_report) + sizeof(double) +
	              FRAMES * sizeof(struct frame_metrics);
	struct series_report *rep = calloc(1, size);
	bvhlab_error err = { "" };
	hb.top.plugin = (bvhlab_plugin *)top;
	CHECK_INT(bvhlab_options_init(&hb.top.opts, bvhlab_plugin_builder(top)), 0);
	rep->samples[0] = 1.0;
	struct config one = *cfg;
	one.repeat = 1;
	CHECK_INT(harness_anim_top_frames(&one, &hb, a, trees, 2, camera ? &cam : NULL, rep, &err),
	          0);
	CHECK(rep->in_frames && rep->frame_count == FRAMES);
	const struct frame_metrics *fm = (const struct frame_metrics *)(rep->samples + 1);
	for (uint32_t f = 0; f < FRAMES; f++) {
		CHECK(fm[f].frame == f && fm[f].valid && isfinite(fm[f].sah) && fm[f].sah > 0);
		CHECK(fm[f].rebuilt == (f == 0));
		CHECK(fm[f].rays_checked == (f == 0 || f == 2 || f == 4));
		CHECK(fm[f].traced == camera && fm[f].costed == camera);
		if (camera)
			CHECK(fm[f].nodes_per_ray > 0 && fm[f].mrays_per_s > 0 &&
			      fm[f].cost_ms > fm[f].update_ms);
	}
	CHECK(fm[0].update_ms == 1.0);
	bvhlab_options_finish(&hb.top.opts);
	free(rep);
}

/* Config `text` is refused, the message placing it and containing needle. */
static void refused(const char *text, const char *needle)
{
	struct config cfg;
	bvhlab_error err = { "" };
	CHECK_INT(config_parse(&cfg, "/cfg/c.json", text, &err), -EINVAL);
	CHECK_CONTAINS(err.message, "/cfg/c.json:1:");
	CHECK_CONTAINS(err.message, needle);
	config_finish(&cfg);
}

/* What an animated two-level config cannot say, each named at its key. */
static void test_errors(void)
{
	static const char *const bad[][2] = {
		{"\"meshes\": [ { \"name\": \"b\", \"generator\": \"soup\" } ], \"instances\": "
		 "[ { \"mesh\": \"b\", \"animate\": { \"translate\": [1, 0, 0] } } ]",
		 "'scenes[0].instances[0].animate': the scene has no 'frames'"},
		{"\"frames\": 3, \"meshes\": [ { \"name\": \"b\", \"generator\": \"soup\" } ], "
		 "\"instances\": [ { \"scatter\": { \"mesh\": \"b\", \"count\": 2, \"bounds\": "
		 "[[0, 0, 0], [1, 1, 1]], \"animate\": { \"spin\": 1 } } } ]",
		 "unknown key 'spin' in scenes[0].instances[0].scatter.animate"},
		{"\"frames\": 3, \"meshes\": [ { \"name\": \"b\", \"generator\": \"soup\" } ], "
		 "\"instances\": [ { \"mesh\": \"b\", \"animate\": { \"scale\": 0 } } ]",
		 "'scenes[0].instances[0].animate.scale'"},
		{"\"frames\": 3, \"animate\": { \"translate\": [1, 0, 0] }, \"meshes\": [ { "
		 "\"name\": \"b\", \"generator\": \"soup\" } ], \"instances\": [ { \"mesh\": "
		 "\"b\" } ]",
		 "'scenes[0].animate' does not apply to a scene with 'instances': give 'animate' to "
		 "the instances that move"},
		{"\"frames\": 3, \"meshes\": [ { \"name\": \"b\", \"generator\": \"soup\" } ], "
		 "\"instances\": [ { \"mesh\": \"b\", \"deform\": \"wave\" } ]",
		 "unknown key 'deform' in scenes[0].instances[0]"},
	};
	char text[4096];
	for (size_t k = 0; k < sizeof(bad) / sizeof(bad[0]); k++) {
		snprintf(text, sizeof(text), "{ \"scenes\": [ { %s } ], \"builders\": [ { "
		         "\"plugin\": \"lbvh\" } ] }", bad[k][0]);
		refused(text, bad[k][1]);
	}
	/* A two-level builder's animation takes no refinement stages. */
	snprintf(text, sizeof(text), "%.*s\"animation\": { \"update\": \"refit\", \"refine\": [ "
	         "{ \"plugin\": \"reinsert\" } ] } } ] }", (int)(strstr(config_text,
	         "\"animation\"") - config_text), config_text);
	refused(text, "'builders[0].animation.refine': a two-level builder's top");
}

int main(void)
{
	struct config cfg;
	struct scene_instanced inst;
	struct harness_anim a;
	bvhlab_error err = { "" };
	bvhlab_plugin *bottom = NULL, *top = NULL, *refit = NULL;
	bvhlab_options bo, to, ro;
	CHECK_INT(config_parse(&cfg, "/cfg/c.json", config_text, &err), 0);
	CHECK(cfg.scenes[0].frames == FRAMES && cfg.scenes[0].instances[0].motion.animate &&
	      !cfg.scenes[0].instances[1].motion.animate);
	CHECK_INT(harness_load_instanced(&cfg.scenes[0], &inst, &err), 0);
	harness_anim_instanced(&cfg.scenes[0], &inst, &a);
	CHECK(a.frames == FRAMES && a.inst == &inst);
	test_pose(&a);
	test_errors();
	if (plugin_loads("sah_seq", &bottom) && plugin_loads("lbvh", &top) &&
	    plugin_loads("refit", &refit)) {
		CHECK_INT(bvhlab_options_init(&bo, bvhlab_plugin_builder(bottom)), 0);
		CHECK_INT(bvhlab_options_init(&to, bvhlab_plugin_builder(top)), 0);
		CHECK_INT(bvhlab_options_init(&ro, bvhlab_plugin_builder(refit)), 0);
		for (int strategy = 0; strategy < 4; strategy++) {
			struct two_level_trees trees;
			build_series(&inst, bottom, &bo, top, &to, &trees);
			if (strategy < 2)
				run_frames(&a, &trees, top, &to, strategy ? refit : NULL, &ro);
			else
				test_harness(&cfg, &a, &trees, top, strategy == 3);
			harness_two_level_finish(&trees);
		}
		bvhlab_options_finish(&bo);
		bvhlab_options_finish(&to);
		bvhlab_options_finish(&ro);
	}
	bvhlab_plugin_close(bottom);
	bvhlab_plugin_close(top);
	bvhlab_plugin_close(refit);
	harness_anim_close(&a);
	scene_instanced_finish(&inst);
	config_finish(&cfg);
	return test_finish();
}
