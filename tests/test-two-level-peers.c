/*
 * The peer libraries' two-level builds (argv[1]: embree or tinybvh): the
 * plugin as both levels of a two-level scene, its bottom trees built by
 * the library per mesh and its top by the library over the instances'
 * world boxes (Embree's rtcBuildBVH over boxes; tinybvh's TLAS build over
 * BLASInstance records), at 1 and 2 threads. Both levels are validated by
 * the harness's two-level series (structure, sampled rays against brute
 * force), the top references each instance once, and 1,000 rays through
 * both levels find the same closest hit (instance, primitive, t) as
 * bvhlab's own two-level tree (sah_seq under lbvh) on the same scene, most
 * of them hits; the library's phases (input, convert) are the run's. A
 * top option the library cannot build over boxes is refused with a
 * message saying so. Skipped (77) when the plugin is not built.
 */
#include <errno.h>
#include <math.h>
#include <stdio.h>
#include <string.h>
#include <unistd.h>

#include "config/config.h"
#include "harness/harness_instances.h"
#include "harness/harness_two_level.h"
#include "trace/trace_instances.h"
#define FIXTURE_SEED 0x42ULL
#include "scene_fixture.h"
#include "testutil.h"

#define RAYS 1000

/* Two meshes under rotated, scaled and scattered instances (as
 * test-instances.c's scene). */
static const char *const config_text =
	"{ \"scenes\": [ { \"name\": \"grove\", \"meshes\": ["
	" { \"name\": \"ball\", \"generator\": \"icosphere\", \"frequency\": 3 },"
	" { \"name\": \"rock\", \"generator\": \"soup\", \"count\": 60 } ], \"instances\": ["
	" { \"mesh\": \"ball\", \"scale\": 2, \"rotate\": [0, 30, 0], \"translate\": [1, 2, 3] },"
	" { \"mesh\": \"rock\", \"matrix\": [0, 0, 1, 5, 0, 1, 0, 0, -1, 0, 0, 0] },"
	" { \"scatter\": { \"mesh\": \"ball\", \"count\": 60, \"seed\": 9,"
	"   \"bounds\": [[-10, 0, -10], [10, 1, 10]], \"scale\": [0.5, 2],"
	"   \"rotate\": \"random-y\" } },"
	" { \"scatter\": { \"mesh\": \"rock\", \"count\": 20, \"seed\": 4,"
	"   \"bounds\": [[-8, -2, -8], [8, 2, 8]] } } ] } ],"
	" \"builders\": [ { \"plugin\": \"sah_seq\" } ] }";

/* What a peer is asked for at each level ("key=value", NULL-ended). */
struct levels {
	const char *bottom[3], *top[3];
};

struct built {
	bvhlab_options bo, to;
	struct two_level_trees trees;
};

static int options(bvhlab_options *o, const bvhlab_plugin *p, const char *const *items,
                   bvhlab_error *err)
{
	int r = bvhlab_options_init(o, bvhlab_plugin_builder(p));
	for (size_t k = 0; r == 0 && items[k]; k++)
		r = bvhlab_options_parse(o, items[k], err);
	return r == 0 ? bvhlab_options_check(o, err) : r;
}

/* The two-level series of `bottom` under `top`, one timed build; its
 * verdict, the trees in *b (freed by unbuild). */
static int build(const struct scene_instanced *inst, const bvhlab_plugin *bottom,
                 const bvhlab_plugin *top, const struct levels *lv, uint32_t threads,
                 struct built *b, bvhlab_error *err)
{
	struct tree_measure whole;
	struct results_two_level rl;
	double sample, cold;
	memset(b, 0, sizeof(*b));
	CHECK_INT(options(&b->bo, bottom, lv->bottom, err), 0);
	CHECK_INT(options(&b->to, top, lv->top, err), 0);
	struct two_level_job job = {.inst = inst, .bottom = bottom, .top = top,
	                            .bottom_opts = &b->bo, .top_opts = &b->to, .warmup = 1,
	                            .repeat = 1, .threads = threads, .validate_rays = 64};
	int v = harness_two_level_series(&job, &sample, &cold, &whole, &rl, &b->trees, err);
	if (v == TREE_OK) {
		CHECK(whole.valid && whole.mismatches == 0 && whole.rays_checked == 3 * 64);
		CHECK(rl.bottom.trees == inst->mesh_count && rl.top.trees == 1);
		CHECK(b->trees.top.index_count == inst->instance_count);
	}
	return v;
}

static void unbuild(struct built *b)
{
	harness_two_level_finish(&b->trees);
	bvhlab_options_finish(&b->bo);
	bvhlab_options_finish(&b->to);
}

/* Every ray's closest hit through `got` the same as through `want`. */
static void same_hits(const struct scene_instanced *inst, const struct two_level_trees *got,
                      const struct two_level_trees *want, const char *what)
{
	struct trace_two_level a = {.inst = inst, .top = &got->top, .bottom = got->bottom};
	struct trace_two_level b = {.inst = inst, .top = &want->top, .bottom = want->bottom};
	bvhlab_aabb box;
	uint32_t hits = 0, differ = 0;
	memcpy(box.lo, want->top.nodes[0].lo, sizeof(box.lo));
	memcpy(box.hi, want->top.nodes[0].hi, sizeof(box.hi));
	for (uint32_t i = 0; i < RAYS; i++) {
		bvhlab_ray ray;
		struct trace_inst_hit x, y;
		trace_two_level_ray(inst, &box, 11, i, &ray);
		trace_two_level_closest(&a, &ray, &x, NULL);
		trace_two_level_closest(&b, &ray, &y, NULL);
		hits += y.hit.prim != BVHLAB_NO_HIT;
		differ += x.hit.prim != y.hit.prim ||
		          (y.hit.prim != BVHLAB_NO_HIT &&
		           (x.instance != y.instance || x.hit.t != y.hit.t));
	}
	if (differ)
		fprintf(stderr, "%s: %u of %d rays hit otherwise than bvhlab's two-level tree\n",
		        what, differ, RAYS);
	CHECK(differ == 0);
	CHECK(hits > RAYS / 3);
}

static bool has_phase(const struct two_level_trees *t, const char *name)
{
	for (uint32_t j = 0; j < t->phase_count; j++)
		if (strcmp(t->phases[j].name, name) == 0 && t->phases[j].ms > 0)
			return true;
	return false;
}

/* A top the library cannot build over boxes: the run fails, saying so. */
static void refused(const struct scene_instanced *inst, const bvhlab_plugin *peer,
                    const char *option, const char *needle)
{
	struct levels lv = {.top = {option, NULL}};
	struct built b;
	bvhlab_error err = {{0}};
	CHECK_INT(build(inst, peer, peer, &lv, 1, &b, &err), TREE_FAILED);
	CHECK_CONTAINS(err.message, needle);
	unbuild(&b);
}

static void check_peer(const struct scene_instanced *inst, const bvhlab_plugin *peer,
                       const struct levels *lv, size_t count, const struct built *ref)
{
	for (size_t k = 0; k < count; k++)
		for (uint32_t threads = 1; threads <= 2; threads++) {
			struct built b;
			bvhlab_error err = {{0}};
			char what[128];
			int v = build(inst, peer, peer, &lv[k], threads, &b, &err);
			snprintf(what, sizeof(what), "%s %s / %s at %u threads",
			         bvhlab_plugin_builder(peer)->name,
			         lv[k].bottom[0] ? lv[k].bottom[0] : "defaults",
			         lv[k].top[0] ? lv[k].top[0] : "defaults", threads);
			if (v != TREE_OK)
				fprintf(stderr, "%s: %s\n", what, err.message);
			CHECK_INT(v, TREE_OK);
			if (v == TREE_OK)
				same_hits(inst, &b.trees, &ref->trees, what);
			/* the library's time apart from bvhlab's, as for a one-level run */
			CHECK(has_phase(&b.trees, "input") && has_phase(&b.trees, "convert"));
			unbuild(&b);
		}
}

static const struct levels embree_levels[] = {
	{.bottom = {NULL}, .top = {NULL}},
	{.bottom = {"quality=high", NULL}, .top = {"quality=low", NULL}},
};
static const struct levels tinybvh_levels[] = {
	{.bottom = {NULL}, .top = {"builder=binned", NULL}},
	{.bottom = {"builder=sweep", NULL}, .top = {"builder=binned", NULL}},
};

static int run(const char *name, const struct scene_instanced *inst)
{
	bvhlab_plugin *peer = NULL, *sah = NULL, *lbvh = NULL;
	bvhlab_error err = {{0}};
	char path[1024];
	snprintf(path, sizeof(path), "%s/%s/%s.so", BVHLAB_BUILD_PLUGIN_DIR, name, name);
	if (access(path, R_OK) != 0) {
		printf("skip: %s not built (meson setup says why)\n", name);
		return TEST_SKIP;
	}
	if (bvhlab_plugin_open(path, &peer, &err) < 0) {
		fprintf(stderr, "%s\n", err.message);
		return 1;
	}
	CHECK(bvhlab_plugin_builder(peer)->flags & BVHLAB_BUILDER_BOXES);
	struct built ref;
	struct levels none = {.bottom = {NULL}, .top = {NULL}};
	if (plugin_loads("sah_seq", &sah) && plugin_loads("lbvh", &lbvh) &&
	    build(inst, sah, lbvh, &none, 1, &ref, &err) == TREE_OK) {
		bool embree = strcmp(name, "embree") == 0;
		check_peer(inst, peer, embree ? embree_levels : tinybvh_levels, 2, &ref);
		if (embree)
			refused(inst, peer, "quality=high", "'high' splits triangles");
		else
			refused(inst, peer, "builder=avx", "set builder 'binned'");
		unbuild(&ref);
	}
	bvhlab_plugin_close(sah);
	bvhlab_plugin_close(lbvh);
	bvhlab_plugin_close(peer);
	return test_finish();
}

int main(int argc, char **argv)
{
	struct config cfg;
	struct scene_instanced inst;
	bvhlab_error err = {{0}};
	if (argc != 2 || (strcmp(argv[1], "embree") && strcmp(argv[1], "tinybvh"))) {
		fprintf(stderr, "usage: test-two-level-peers embree|tinybvh\n");
		return 2;
	}
	CHECK_INT(config_parse(&cfg, "/cfg/c.json", config_text, &err), 0);
	CHECK_INT(harness_load_instanced(&cfg.scenes[0], &inst, &err), 0);
	int rc = run(argv[1], &inst);
	scene_instanced_finish(&inst);
	config_finish(&cfg);
	return rc;
}
