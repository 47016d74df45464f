/*
 * Experiment configs read into their fields: a full config, defaults and
 * path resolution, the ray traversals, a scene's camera, the isolation
 * keys and animation. The errors of every kind are test-config-errors.c's,
 * builder options test-config-options.c's, the position index
 * test-json-locate.c's.
 */
#include <errno.h>
#include <stdint.h>
#include <stdio.h>
#include <string.h>

#include <cJSON.h>

#include <bvhlab/trace.h>

#include "config/config.h"
#include "harness/harness_rays.h"
#include "trace/trace_cl.h"
#include "testutil.h"

#include "config_fixture.h"
#include "scene_files.h"

static void test_full(void)
{
	const char *text =
		"{\n"
		"  \"format_version\": 1,\n"
		"  \"output\": \"out/run1\",\n"
		"  \"repeat\": 7, \"warmup\": 0,\n"
		"  \"threads\": [0, 2, 4],\n"
		"  \"validate\": false, \"validate_rays\": 100,\n"
		"  \"rays\": { \"width\": 64, \"height\": 32, \"diffuse\": 3, \"rounds\": 3,"
		" \"camera\": {"
		" \"position\": [1, 2, 3], \"target\": [0, 0.5, 0], \"up\": [0, 0, 1], \"fov\": 30 } },\n"
		"  \"images\": true,\n"
		"  \"scenes\": [\n"
		"    { \"name\": \"ico\", \"generator\": \"icosphere\", \"frequency\": 12,"
		" \"seed\": 18446744073709551615 },\n"
		"    { \"path\": \"../meshes/ogre.obj\", \"subdivide\": 2 },\n"
		"    { \"name\": \"soup\", \"generator\": \"soup\", \"count\": 1e3, \"size\": 8 } ],\n"
		"  \"builders\": [\n"
		"    { \"plugin\": \"sah_seq\", \"name\": \"sweep\", \"threads\": [1, 8],"
		" \"options\": { \"method\": \"sweep\" } },\n"
		"    { \"plugin\": \"plugins/custom.so\" },\n"
		"    { \"plugin\": \"/abs/other.so\", \"name\": \"other\" } ] }\n";
	struct config cfg;
	bvhlab_error err = { "" };
	int rc = load(&cfg, text, &err);
	CHECK_INT(rc, 0);
	if (rc) {
		fprintf(stderr, "%s\n", err.message);
		return;
	}
	CHECK(strcmp(cfg.path, cfg_path) == 0 && strcmp(cfg.dir, tmpdir) == 0);
	CHECK(cfg.format_version == 1 && strcmp(cfg.output, tmp_path("out/run1")) == 0);
	CHECK(cfg.repeat == 7 && cfg.warmup == 0 && cfg.thread_count == 3);
	CHECK(cfg.threads[0] == 0 && cfg.threads[1] == 2 && cfg.threads[2] == 4);
	CHECK(!cfg.validate && cfg.images && cfg.validate_rays == 100);
	CHECK(cfg.ray_width == 64 && cfg.ray_height == 32 && cfg.ray_diffuse == 3);
	CHECK(cfg.ray_rounds == 3);
	const bvhlab_camera *cam = &cfg.camera;
	CHECK(cfg.has_camera && cam->fov_deg == 30.0f && cam->position[2] == 3.0f);
	CHECK(cam->target[1] == 0.5f && cam->up[1] == 0.0f && cam->up[2] == 1.0f);

	CHECK_INT(cfg.scene_count, 3);
	struct config_scene *s = cfg.scenes;
	CHECK(strcmp(s[0].name, "ico") == 0 && strcmp(s[0].generator, "icosphere") == 0);
	CHECK(s[0].path == NULL && s[0].gen.frequency == 12 && s[0].line == 10 && s[0].column == 5);
	CHECK(s[0].gen.seed == UINT64_MAX); /* exact, not rounded through a double */
	CHECK(strcmp(s[1].name, "ogre") == 0 && s[1].generator == NULL && s[1].subdivide == 2);
	CHECK(strcmp(s[1].path, tmp_path("../meshes/ogre.obj")) == 0);
	CHECK(s[1].line == 11 && s[1].column == 5);
	CHECK(strcmp(s[2].name, "soup") == 0 && s[2].gen.count == 1000 && s[2].gen.size == 8);

	CHECK_INT(cfg.builder_count, 3);
	struct config_builder *b = cfg.builders;
	CHECK(strcmp(b[0].plugin, "sah_seq") == 0 && strcmp(b[0].name, "sweep") == 0);
	CHECK(b[0].thread_count == 2 && b[0].threads[0] == 1 && b[0].threads[1] == 8);
	CHECK(cJSON_IsObject(b[0].options) && b[0].line == 14 && b[0].column == 5);
	CHECK(strcmp(b[1].plugin, tmp_path("plugins/custom.so")) == 0);
	CHECK(strcmp(b[1].name, "custom") == 0 && b[1].options == NULL);
	CHECK(b[1].threads == NULL && b[1].thread_count == 0);
	CHECK(strcmp(b[2].plugin, "/abs/other.so") == 0 && strcmp(b[2].name, "other") == 0);

	uint32_t threads[] = { 16, 8 }, dup[] = { 2, 2 };
	CHECK_INT(config_set_threads(&cfg, threads, 2), 0);
	CHECK_INT(config_set_threads(&cfg, dup, 2), -EINVAL);
	CHECK_INT(config_set_threads(&cfg, threads, 0), -EINVAL);
	CHECK(cfg.thread_count == 2 && cfg.threads[0] == 16 && cfg.threads[1] == 8);
	config_finish(&cfg);
	CHECK(cfg.root == NULL && cfg.scenes == NULL);
	config_finish(&cfg); /* twice is fine */
}

static void test_defaults(void)
{
	struct config cfg;
	bvhlab_error err = { "" };
	bvhlab_gen_params gen;
	bvhlab_gen_params_init(&gen);
	int rc = load(&cfg, "{ " SCENES ", " BUILDERS " }", &err);
	CHECK_INT(rc, 0);
	if (rc)
		return;
	CHECK(cfg.format_version == 1 && strcmp(cfg.output, tmp_path("results")) == 0);
	CHECK(cfg.repeat == 5 && cfg.warmup == 1 && cfg.thread_count == 1 && cfg.threads[0] == 1);
	CHECK(cfg.validate && !cfg.images && cfg.validate_rays == 256);
	CHECK(cfg.ray_width == 256 && cfg.ray_height == 256 && cfg.ray_diffuse == 1);
	CHECK(cfg.ray_min_ms == 200 && cfg.ray_rounds == 8);
	CHECK(strcmp(cfg.scenes[0].name, "icosphere") == 0 && cfg.scenes[0].subdivide == 0);
	CHECK(memcmp(&cfg.scenes[0].gen, &gen, sizeof(gen)) == 0);
	CHECK(strcmp(cfg.builders[0].name, "sah_seq") == 0 && !cfg.builders[0].threads);
	CHECK(cfg.ray_traversal == BVHLAB_TRAVERSAL_WIDE &&
	      cfg.ray_traversals == 1u << BVHLAB_TRAVERSAL_WIDE);
	config_finish(&cfg);

	/* Whole numbers in any spelling; a config in the current folder. */
	rc = config_parse(&cfg, "c.json",
	                  "{ \"repeat\": 2.0, \"warmup\": 1e1, \"output\": \"o\","
	                  " \"scenes\": [ { \"path\": \"m/a.obj\" } ], " BUILDERS " }",
	                  &err);
	CHECK_INT(rc, 0);
	if (!rc) {
		CHECK(cfg.repeat == 2 && cfg.warmup == 10);
		CHECK(strcmp(cfg.output, "o") == 0 && strcmp(cfg.scenes[0].path, "m/a.obj") == 0);
		CHECK(strcmp(cfg.scenes[0].name, "a") == 0);
	}
	config_finish(&cfg);
	rc = config_parse(&cfg, "/c.json", "\xEF\xBB\xBF{ " SCENES ", " BUILDERS " }", &err);
	CHECK_INT(rc, 0); /* a byte order mark is fine */
	if (!rc)
		CHECK(strcmp(cfg.output, "/results") == 0);
	config_finish(&cfg);

	struct config zero;
	memset(&zero, 0, sizeof(zero));
	config_finish(&zero);
}

/* "traversal": a name, "both" or an array of names, the first the main one. */
static void test_traversal(void)
{
	static const struct {
		const char *value;
		int main;
		unsigned all;
	} ok[] = {
		{"\"stack\"", BVHLAB_TRAVERSAL_STACK, 1u << BVHLAB_TRAVERSAL_STACK},
		{"\"both\"", BVHLAB_TRAVERSAL_STACK, 3u},
		{"[\"stackless\", \"wide\"]", BVHLAB_TRAVERSAL_STACKLESS, 6u},
		{"[\"wide\", \"stack\", \"stackless\"]", BVHLAB_TRAVERSAL_WIDE, 7u},
		{"[\"wide8\", \"wide4\"]", BVHLAB_TRAVERSAL_WIDE8,
		 1u << BVHLAB_TRAVERSAL_WIDE4 | 1u << BVHLAB_TRAVERSAL_WIDE8},
	};
	for (size_t i = 0; i < sizeof(ok) / sizeof(ok[0]); i++) {
		char text[256];
		struct config cfg;
		bvhlab_error err = {""};
		snprintf(text, sizeof(text),
		         "{ " SCENES ", " BUILDERS ", \"rays\": { \"traversal\": %s } }", ok[i].value);
		int rc = load(&cfg, text, &err);
		CHECK_INT(rc, 0);
		if (rc == 0)
			CHECK(cfg.ray_traversal == ok[i].main && cfg.ray_traversals == ok[i].all);
		config_finish(&cfg);
	}
	static const struct {
		const char *rays, *at; /* inside "rays": { }; the error at the n-th at */
		int n;
		const char *needle;
	} bad[] = {
		{"\"traversal\": \"wid\"", "\"wid\"", 0,
		 "'rays.traversal' must be \"wide\", \"wide4\", \"wide8\", \"stack\", \"stackless\", "
		 "\"both\" (stack and stackless), an entry {\"name\": NAME, \"device\": true, "
		 "\"optional\": true} (both settings may be left out) or an array of those, not "
		 "\"wid\""},
		{"\"traversal\": [\"wide\", 2]", "2]", 0, "an array of those, not 2"},
		{"\"traversal\": [\"wide\", \"wide\"]", "\"wide\"", 1,
		 "'rays.traversal' names \"wide\" twice"},
		{"\"traversal\": []", "[]", 0, "not an array"},
		{"\"traversal\": [{\"name\": \"stack\", \"opt\": true}]", "\"opt\"", 0,
		 "entries as objects take \"name\" (a string), \"device\" and \"optional\" (true or "
		 "false) only"},
		/* The device traversals' old names, and results.json's, are refused
		 * with the config's way to say them. */
		{"\"traversal\": [\"stack\", \"cl_stack\"]", "\"cl_stack\"", 0,
		 "'rays.traversal' \"cl_stack\" is written {\"name\": \"stack\", \"device\": true}: a "
		 "traversal is named for what it does"},
		{"\"traversal\": \"device_stackless\"", "\"device_stackless\"", 0,
		 "is written {\"name\": \"stackless\", \"device\": true}"},
		{"\"traversal\": {\"name\": \"wide\", \"device\": true}", "\"wide\"", 0,
		 "'rays.traversal' \"wide\" has no device kernel"},
		{"\"traversal\": {\"name\": \"wide4\", \"device\": true}", "\"wide4\"", 0,
		 "'rays.traversal' \"wide4\" has no device kernel: \"device\": true is for "
		 "\"stack\", \"stackless\" and \"wide8\""},
		{"\"traversal\": [\"wide8\", \"device_wide8\"]", "\"device_wide8\"", 0,
		 "is written {\"name\": \"wide8\", \"device\": true}"},
		{"\"traversal\": [{\"name\": \"stack\", \"device\": true}, {\"device\": true, "
		 "\"name\": \"stack\"}]",
		 "\"stack\"}", 0, "names \"stack\" on the device twice"},
		{"\"kinds\": [\"primary\", \"shade\"]", "\"shade\"", 0,
		 "'rays.kinds' must be an array of \"primary\", \"diffuse\", \"shadow\" and \"ao\", "
		 "each at most once, not \"shade\""},
		{"\"kinds\": [\"primary\", \"ao\", \"ao\"]", "\"ao\"", 1, "each at most once, not \"ao\""},
		{"\"kinds\": \"shadow\"", "\"shadow\"", 0, "'rays.kinds' must be an array"},
		{"\"kinds\": [\"shadow\"]", "[\"shadow\"]", 0, "'rays.kinds' must name \"primary\""},
		{"\"diffuse\": 0, \"kinds\": [\"primary\", \"diffuse\"]", "[\"primary\"", 0,
		 "'rays.kinds' names \"diffuse\" but 'rays.diffuse' is 0"},
		{"\"light\": [1, 2]", "[1, 2]", 0, "'rays.light' must be an array of 3 finite numbers"},
		{"\"ao_length\": 0", "0 }", 0, "'rays.ao_length' must be"},
		{"\"device\": \"0:x\"", "\"0:x\"", 0,
		 "'rays.device' must be \"auto\", \"gpu\", \"cpu\" or \"P:D\""},
	};
	for (size_t i = 0; i < sizeof(bad) / sizeof(bad[0]); i++) {
		char text[512];
		snprintf(text, sizeof(text), "{ " SCENES ", " BUILDERS ", \"rays\": { %s } }",
		         bad[i].rays);
		EXPECT_ERROR_AT(text, bad[i].at, bad[i].n, bad[i].needle);
	}
	struct config cfg;
	bvhlab_error err = {""};
	const char *t = "{ " SCENES ", " BUILDERS ", \"rays\": { \"kinds\": [\"ao\", \"primary\", "
	                "\"shadow\"], \"light\": [1, 2, 3], \"ao_length\": 0.25 } }";
	CHECK_INT(load(&cfg, t, &err), 0);
	CHECK(cfg.ray_kinds == (1u << RAY_PRIMARY | 1u << RAY_SHADOW | 1u << RAY_AO));
	CHECK(cfg.has_light && cfg.ray_light[2] == 3.0f && cfg.ray_ao_length == 0.25);
	config_finish(&cfg);
}

/* The device traversals: refused, naming the key, in a build without
 * OpenCL unless optional (then left out); kept in a build with it. */
static void test_device_traversal(void)
{
	struct config cfg;
	bvhlab_error err = {""};
	const char *t = "{ " SCENES ", " BUILDERS ", \"rays\": { \"device\": \"1:0\", \"traversal\": "
	                "[{\"name\": \"stack\", \"device\": true, \"optional\": true}, \"stack\"] } }";
	CHECK_INT(load(&cfg, t, &err), 0);
	unsigned stack = 1u << BVHLAB_TRAVERSAL_STACK, cl = 1u << BVHLAB_TRAVERSAL_DEVICE_STACK;
	CHECK(strcmp(cfg.ray_device, "1:0") == 0);
	if (trace_cl_built())
		CHECK(cfg.ray_traversal == BVHLAB_TRAVERSAL_DEVICE_STACK &&
		      cfg.ray_traversals == (stack | cl));
	else
		CHECK(cfg.ray_traversal == BVHLAB_TRAVERSAL_STACK && cfg.ray_traversals == stack);
	config_finish(&cfg);
	/* wide8 on the device is the compressed layout's traversal */
	t = "{ " SCENES ", " BUILDERS ", \"rays\": { \"traversal\": [\"wide8\", {\"name\": "
	    "\"wide8\", \"device\": true, \"optional\": true}] } }";
	CHECK_INT(load(&cfg, t, &err), 0);
	CHECK(cfg.ray_traversal == BVHLAB_TRAVERSAL_WIDE8 &&
	      cfg.ray_traversals == (1u << BVHLAB_TRAVERSAL_WIDE8 |
	                             (trace_cl_built() ? 1u << BVHLAB_TRAVERSAL_DEVICE_WIDE8 : 0)));
	config_finish(&cfg);
	t = "{ " SCENES ", " BUILDERS ", \"rays\": { \"traversal\": {\"name\": \"stackless\", "
	    "\"device\": true} } }";
	if (trace_cl_built()) {
		CHECK_INT(load(&cfg, t, &err), 0);
		config_finish(&cfg);
	} else {
		EXPECT_ERROR_AT(t, "\"stackless\"", 0, "'rays.traversal' \"stackless\" with "
		                "\"device\": true runs on a device, and this bvhlab was built without "
		                "OpenCL");
	}
}

/* A scene's own "camera" wins over "rays"' one for that scene only; its
 * errors name the scene. */
static void test_scene_camera(void)
{
	const char *text =
		"{ \"rays\": { \"camera\": { \"position\": [0, 0, 5] } },\n"
		"  \"scenes\": [ { \"name\": \"a\", \"generator\": \"icosphere\" },\n"
		"    { \"name\": \"room\", \"generator\": \"room\", \"camera\": {"
		" \"position\": [0.5, -0.5, 0], \"target\": [-1, -0.4, 0], \"fov\": 70 } } ],\n"
		"  " BUILDERS " }";
	struct config cfg;
	bvhlab_error err = { "" };
	bvhlab_camera cam;
	int rc = load(&cfg, text, &err);
	CHECK_INT(rc, 0);
	if (rc) {
		fprintf(stderr, "%s\n", err.message);
		return;
	}
	CHECK(!cfg.scenes[0].has_camera && cfg.scenes[1].has_camera);
	CHECK(cfg.scenes[1].camera.fov_deg == 70.0f && cfg.scenes[1].camera.target[0] == -1.0f);
	bvhlab_scene named = { .name = "room" }, other = { .name = "a" };
	harness_camera(&cfg, &named, &cam);
	CHECK(cam.position[0] == 0.5f && cam.fov_deg == 70.0f);
	harness_camera(&cfg, &other, &cam);
	CHECK(cam.position[2] == 5.0f && cam.fov_deg == 45.0f);
	config_finish(&cfg);
	const char *t = "{ \"scenes\": [ { \"generator\": \"room\",\n"
	                "  \"camera\": { \"position\": [1, 1, 1], \"target\": [1, 1, 1] } } ], "
	                BUILDERS " }";
	EXPECT_ERROR_AT(t, "{ \"position", 0, "'scenes[0].camera': position and target must differ");
	t = "{ \"scenes\": [ { \"generator\": \"room\", \"camera\": [1] } ], " BUILDERS " }";
	EXPECT_ERROR_AT(t, "[1]", 0, "'scenes[0].camera' must be an object");
}

/* "isolate", "timeout_s" and "memory_limit_mb": defaults, overrides, bad values. */
static void test_isolation_keys(void)
{
	struct config cfg;
	bvhlab_error err = { "" };
	const char *t;
	int rc = load(&cfg, "{ " SCENES ", " BUILDERS " }", &err);
	CHECK_INT(rc, 0);
	if (!rc)
		CHECK(cfg.isolate && cfg.timeout_s == 600 && cfg.memory_limit_mb == 0 &&
		      cfg.builders[0].timeout_s == 0 && cfg.builders[0].memory_limit_mb == 0);
	config_finish(&cfg);
	rc = load(&cfg, "{ \"isolate\": false, \"timeout_s\": 2.5, \"memory_limit_mb\": 512, "
	          SCENES ", \"builders\": [ { \"plugin\": \"a\", \"timeout_s\": 0.25, "
	          "\"memory_limit_mb\": 64 } ] }", &err);
	CHECK_INT(rc, 0);
	if (!rc)
		CHECK(!cfg.isolate && cfg.timeout_s == 2.5 && cfg.memory_limit_mb == 512 &&
		      cfg.builders[0].timeout_s == 0.25 && cfg.builders[0].memory_limit_mb == 64);
	config_finish(&cfg);
#define TOP(extra) "{ " SCENES ", " BUILDERS ", " extra " }"
	t = TOP("\"isolate\": 1");
	EXPECT_ERROR_AT(t, "1 }", 0, "'isolate' must be true or false, not 1");
	t = TOP("\"timeout_s\": 0");
	EXPECT_ERROR_AT(t, "0 }", 0, "'timeout_s' must be a number > 0, not 0");
	t = TOP("\"timeout_s\": -3");
	EXPECT_ERROR_AT(t, "-3", 0, "'timeout_s' must be a number > 0, not -3");
	t = TOP("\"timeout_s\": \"60\"");
	EXPECT_ERROR_AT(t, "\"60\"", 0, "'timeout_s' must be a number > 0, not a string");
	t = TOP("\"memory_limit_mb\": 0.5");
	EXPECT_ERROR_AT(t, "0.5", 0, "'memory_limit_mb' must be a positive integer, not 0.5");
	t = TOP("\"memory_limit_mb\": 17592186044416");
	EXPECT_ERROR_AT(t, "1759", 0, "'memory_limit_mb' must be a positive integer up to "
	                "17592186044415");
	t = "{ \"builders\": [ { \"plugin\": \"a\", \"timeout_s\": null } ], " SCENES " }";
	EXPECT_ERROR_AT(t, "null", 0, "'builders[0].timeout_s' must be a number > 0, not null");
	t = "{ \"builders\": [ { \"plugin\": \"a\", \"memory_limit_mb\": -1 } ], " SCENES " }";
	EXPECT_ERROR_AT(t, "-1", 0, "'builders[0].memory_limit_mb' must be a positive integer");
#undef TOP
}

/* An animated scene's and a strategy's keys land in their fields
 * (config_anim.c); the strategy names itself. */
static void test_animation(void)
{
	struct config cfg;
	bvhlab_error err = { "" };
	const char *t =
		"{ \"rays_per_frame\": 5000, \"scenes\": [\n"
		"  { \"name\": \"y\", \"frames\": 12, \"parts\": [\n"
		"    { \"generator\": \"room\", \"animate\": { \"rotate\": [0, 90, 0],\n"
		"      \"translate\": [1, 2, 3], \"scale\": 2 } },\n"
		"    { \"generator\": \"icosphere\", \"deform\": \"explode\", \"amplitude\": 0.25 } ] },\n"
		"  { \"name\": \"f\", \"frames\": { \"pattern\": \"w/f%03d.ply\", \"count\": 5,\n"
		"    \"first\": 7 } } ],\n"
		"  \"builders\": [ { \"plugin\": \"lbvh\", \"animation\": { \"update\": \"refit\",\n"
		"    \"rebuild_every\": 8, \"refine\": [ { \"plugin\": \"reinsert\" } ] } } ] }";
	CHECK_INT(load(&cfg, t, &err), 0);
	if (err.message[0])
		fprintf(stderr, "%s\n", err.message);
	CHECK_INT(cfg.rays_per_frame, 5000);
	CHECK_INT(cfg.scenes[0].frames, 12);
	const struct config_motion *m = &cfg.scenes[0].parts[0].motion;
	CHECK(m->animate && m->rotate[1] == 90 && m->translate[2] == 3 && m->scale == 2);
	CHECK_INT(m->deform, CONFIG_DEFORM_NONE);
	m = &cfg.scenes[0].parts[1].motion;
	CHECK(!m->animate && m->deform == CONFIG_DEFORM_EXPLODE && m->amplitude == 0.25);
	CHECK_INT(cfg.scenes[1].frames, 5);
	CHECK_INT(cfg.scenes[1].frame_first, 7);
	CHECK_CONTAINS(cfg.scenes[1].frame_pattern, "/w/f%03d.ply");
	CHECK_CONTAINS(cfg.scenes[1].path, "/w/f007.ply"); /* frame 0's file */
	const struct config_animation *a = cfg.builders[0].animation;
	CHECK(a && !strcmp(a->update, "refit") && a->rebuild_every == 8 && a->refine_count == 1);
	CHECK_CONTAINS(cfg.builders[0].name, "lbvh+refit+reinsert[rebuild_every=8]");
	config_finish(&cfg);
	t = "{ \"scenes\": [ { \"generator\": \"icosphere\" } ],\n"
	    "  \"builders\": [ { \"plugin\": \"a\" } ] }";
	CHECK_INT(load(&cfg, t, &err), 0);
	CHECK_INT(cfg.rays_per_frame, 1000000);
	CHECK_INT(cfg.scenes[0].frames, 0);
	CHECK(cfg.builders[0].animation == NULL);
	config_finish(&cfg);
}

int main(void)
{
	config_fixture_open("config");
	test_full();
	test_defaults();
	test_traversal();
	test_device_traversal();
	test_scene_camera();
	test_isolation_keys();
	test_animation();
	tmp_end();
	return test_finish();
}
