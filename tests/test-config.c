/*
 * Experiment configs: a full config read into every field, defaults, path
 * resolution, and every kind of error with its FILE:LINE:COL; plus the
 * position index (json_locate) underneath.
 */
#include <errno.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <unistd.h>

#include <cJSON.h>

#include <bvhlab/trace.h>

#include "config/config.h"
#include "config/json_locate.h"
#include "harness/harness_rays.h"
#include "trace/trace_cl.h"
#include "testutil.h"

#define SCENES "\"scenes\": [ { \"generator\": \"icosphere\" } ]"
#define BUILDERS "\"builders\": [ { \"plugin\": \"sah_seq\" } ]"

static char tmp_dir[64];
static char cfg_path[128];

static void write_file(const char *path, const char *data, size_t size)
{
	FILE *f = fopen(path, "wb");
	CHECK(f && fwrite(data, 1, size, f) == size);
	if (f)
		fclose(f);
}

static int load(struct config *cfg, const char *text, bvhlab_error *err)
{
	write_file(cfg_path, text, strlen(text));
	return config_load(cfg, cfg_path, err);
}

/* Line and column of the n-th (0-based) occurrence of needle; ASCII text. */
static void position_of(const char *text, const char *needle, int n, int *line, int *col)
{
	const char *at = strstr(text, needle);
	while (at && n-- > 0)
		at = strstr(at + 1, needle);
	*line = 1;
	*col = 1;
	for (const char *p = text; at && p < at; p++) {
		*col = *p == '\n' ? 1 : *col + 1;
		*line += *p == '\n';
	}
	if (!at)
		fprintf(stderr, "test bug: '%s' not in the config\n", needle);
}

/* Loading must fail with a message starting "PATH:LINE:COL: " and holding needle. */
static void expect_error_at(int caller, const char *text, int line, int col,
                            const char *needle)
{
	struct config cfg;
	bvhlab_error err = { "" };
	char prefix[256];
	int rc = load(&cfg, text, &err);
	snprintf(prefix, sizeof(prefix), "%s:%d:%d: ", cfg_path, line, col);
	if (getenv("TEST_VERBOSE")) /* to read the messages as users will */
		fprintf(stderr, "%s\n", err.message);
	if (rc != -EINVAL || strncmp(err.message, prefix, strlen(prefix)) != 0 ||
	    !strstr(err.message, needle)) {
		fprintf(stderr, "%s:%d: rc %d; expected \"%s...%s...\"\n     got \"%s\"\n",
		        __FILE__, caller, rc, prefix, needle, err.message);
		test_failures++;
	}
	/* A failed load leaves nothing behind to free. */
	CHECK(!cfg.root && !cfg.text && !cfg.scenes && !cfg.builders && !cfg.threads);
	config_finish(&cfg);
}

#define EXPECT_ERROR(text, line, col, needle) \
	expect_error_at(__LINE__, text, line, col, needle)

/* The error is at the n-th occurrence of `at` in the text. */
static void expect_error_near(int caller, const char *text, const char *at, int n,
                              const char *needle)
{
	int line, col;
	position_of(text, at, n, &line, &col);
	expect_error_at(caller, text, line, col, needle);
}
#define EXPECT_ERROR_AT(text, at, n, needle) expect_error_near(__LINE__, text, at, n, needle)

static char *in_dir(const char *rel)
{
	static char buf[8][256];
	static int next;
	char *out = buf[next++ % 8];
	snprintf(out, sizeof(buf[0]), "%s/%s", tmp_dir, rel);
	return out;
}

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
	CHECK(strcmp(cfg.path, cfg_path) == 0 && strcmp(cfg.dir, tmp_dir) == 0);
	CHECK(cfg.format_version == 1 && strcmp(cfg.output, in_dir("out/run1")) == 0);
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
	CHECK(strcmp(s[1].path, in_dir("../meshes/ogre.obj")) == 0);
	CHECK(s[1].line == 11 && s[1].column == 5);
	CHECK(strcmp(s[2].name, "soup") == 0 && s[2].gen.count == 1000 && s[2].gen.size == 8);

	CHECK_INT(cfg.builder_count, 3);
	struct config_builder *b = cfg.builders;
	CHECK(strcmp(b[0].plugin, "sah_seq") == 0 && strcmp(b[0].name, "sweep") == 0);
	CHECK(b[0].thread_count == 2 && b[0].threads[0] == 1 && b[0].threads[1] == 8);
	CHECK(cJSON_IsObject(b[0].options) && b[0].line == 14 && b[0].column == 5);
	CHECK(strcmp(b[1].plugin, in_dir("plugins/custom.so")) == 0);
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
	CHECK(cfg.format_version == 1 && strcmp(cfg.output, in_dir("results")) == 0);
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
	const char *t = "{ " SCENES ", " BUILDERS ", \"rays\": { \"traversal\": \"wid\" } }";
	EXPECT_ERROR_AT(t, "\"wid\"", 0, "'rays.traversal' must be \"wide\", \"stack\", "
	                "\"stackless\", \"cl_stack\", \"cl_stackless\", \"both\" (stack and "
	                "stackless) or an array of those names (an entry may be {\"name\": NAME, "
	                "\"optional\": true}), not \"wid\"");
	t = "{ " SCENES ", " BUILDERS ", \"rays\": { \"traversal\": [\"wide\", 2] } }";
	EXPECT_ERROR_AT(t, "2]", 0, "\"optional\": true}), not 2");
	t = "{ " SCENES ", " BUILDERS ", \"rays\": { \"traversal\": [\"wide\", \"wide\"] } }";
	EXPECT_ERROR_AT(t, "\"wide\"", 1, "'rays.traversal' names \"wide\" twice");
	t = "{ " SCENES ", " BUILDERS ", \"rays\": { \"traversal\": [] } }";
	EXPECT_ERROR_AT(t, "[]", 0, "not an array");
	t = "{ " SCENES ", " BUILDERS ", \"rays\": { \"traversal\": [{\"name\": \"stack\", "
	    "\"opt\": true}] } }";
	EXPECT_ERROR_AT(t, "\"opt\"", 0, "entries as objects take \"name\" (a string) and "
	                "\"optional\" (true or false) only");
	t = "{ " SCENES ", " BUILDERS ", \"rays\": { \"device\": \"0:x\" } }";
	EXPECT_ERROR_AT(t, "\"0:x\"", 0, "'rays.device' must be \"auto\", \"gpu\", \"cpu\" or "
	                "\"P:D\"");
}

/* The device traversals: refused, naming the key, in a build without
 * OpenCL unless optional (then left out); kept in a build with it. */
static void test_device_traversal(void)
{
	struct config cfg;
	bvhlab_error err = {""};
	const char *t = "{ " SCENES ", " BUILDERS ", \"rays\": { \"device\": \"1:0\", \"traversal\": "
	                "[{\"name\": \"cl_stack\", \"optional\": true}, \"stack\"] } }";
	CHECK_INT(load(&cfg, t, &err), 0);
	unsigned stack = 1u << BVHLAB_TRAVERSAL_STACK, cl = 1u << BVHLAB_TRAVERSAL_CL_STACK;
	CHECK(strcmp(cfg.ray_device, "1:0") == 0);
	if (trace_cl_built())
		CHECK(cfg.ray_traversal == BVHLAB_TRAVERSAL_CL_STACK && cfg.ray_traversals == (stack | cl));
	else
		CHECK(cfg.ray_traversal == BVHLAB_TRAVERSAL_STACK && cfg.ray_traversals == stack);
	config_finish(&cfg);
	t = "{ " SCENES ", " BUILDERS ", \"rays\": { \"traversal\": \"cl_stackless\" } }";
	if (trace_cl_built()) {
		CHECK_INT(load(&cfg, t, &err), 0);
		config_finish(&cfg);
	} else {
		EXPECT_ERROR_AT(t, "\"cl_stackless\"", 0, "'rays.traversal' \"cl_stackless\" runs on "
		                "an OpenCL device, and this bvhlab was built without OpenCL");
	}
}

static void test_syntax(void)
{
	EXPECT_ERROR("{\n"
	             "  " SCENES ",\n"
	             "  " BUILDERS ",\n"
	             "  \"repeat\": 3 \"warmup\": 1\n"
	             "}\n",
	             4, 15, "JSON syntax error near '\"warmup\": 1'");
	/* A comma missing at the end of a line shows where the next item starts. */
	EXPECT_ERROR("{\n  " SCENES ",\n  " BUILDERS ",\n  \"repeat\": 3\n  \"warmup\": 1\n}\n",
	             5, 3, "JSON syntax error near '\"warmup\": 1'");
	EXPECT_ERROR("{ " SCENES ", " BUILDERS " }\n  x\n", 2, 3,
	             "JSON syntax error near 'x'");
	EXPECT_ERROR("{ \"repeat\": 3,\n  \"scenes\": [", 2, 14, "unexpected end of text");
	EXPECT_ERROR("", 1, 1, "unexpected end of text");
	EXPECT_ERROR("\xEF\xBB\xBF{ \"r\xC3\xA9peat\": 3 x", 1, 15, "near 'x'");
	EXPECT_ERROR("{ \"output\": \"a\\u0000b\",\n " SCENES ", " BUILDERS " }", 1, 15,
	             "strings must not contain \\u0000");

	struct config cfg;
	bvhlab_error err = { "" };
	write_file(cfg_path, "{\n \0 }", 6);
	CHECK_INT(config_load(&cfg, cfg_path, &err), -EINVAL);
	CHECK_CONTAINS(err.message, ":2:2: NUL byte");
	CHECK_INT(config_load(&cfg, in_dir("missing.json"), &err), -ENOENT);
	CHECK_CONTAINS(err.message, "missing.json: cannot open");
}

static void test_unknown_keys(void)
{
	struct config cfg;
	bvhlab_error err = { "" };
	const char *t;
	t = "{ " SCENES ", " BUILDERS ", \"repet\": 3 }";
	EXPECT_ERROR_AT(t, "\"repet\"", 0,
	                "unknown key 'repet' at the top level (known: format_version, output, "
	                "repeat, warmup, threads, validate, validate_rays, rays, images, isolate, "
	                "timeout_s, memory_limit_mb, pin, rays_per_frame, report, scenes, builders); "
	                "did you mean "
	                "'repeat'?");
	t = "{ " SCENES ", " BUILDERS ", \"zzzzzz\": 3 }";
	EXPECT_ERROR_AT(t, "\"zzzzzz\"", 0, "unknown key 'zzzzzz' at the top level");
	CHECK(load(&cfg, t, &err) < 0 && !strstr(err.message, "did you mean"));
	t = "{ \"scenes\": [ { \"generator\": \"icosphere\", \"frequncy\": 4 } ], " BUILDERS " }";
	EXPECT_ERROR_AT(t, "\"frequncy\"", 0,
	                "unknown key 'frequncy' in scenes[0] (known: name, path, generator, parts, "
	                "frequency, count, size, seed, width, subdivide, frames, animate, deform, "
	                "amplitude, camera); did you mean "
	                "'frequency'?");
	EXPECT_ERROR("{ " SCENES ",\n"
	             "  \"builders\": [ { \"plugin\": \"a\" },\n"
	             "    { \"plugin\": \"b\", \"threds\": [2] } ] }",
	             3, 22,
	             "unknown key 'threds' in builders[1] (known: plugin, name, threads, "
	             "timeout_s, memory_limit_mb, options, optional, refine, animation); did you "
	             "mean 'threads'?");
	t = "{ " SCENES ", " BUILDERS ", \"rays\": { \"widht\": 8 } }";
	EXPECT_ERROR_AT(t, "\"widht\"", 0, "unknown key 'widht' in rays (known: width, height, "
	                "diffuse, camera, threads, min_ms, rounds, traversal, device); did you mean "
	                "'width'?");
}

static void test_types(void)
{
	const char *t;
#define TOP(extra) "{ " SCENES ", " BUILDERS ", " extra " }"
	t = TOP("\"repeat\": \"5\"");
	EXPECT_ERROR_AT(t, "\"5\"", 0, "'repeat' must be a positive integer");
	EXPECT_ERROR_AT(t, "\"5\"", 0, "not a string");
	t = TOP("\"repeat\": 2.5");
	EXPECT_ERROR_AT(t, "2.5", 0, "'repeat' must be a positive integer, not 2.5");
	t = TOP("\"repeat\": 1e12");
	EXPECT_ERROR_AT(t, "1e12", 0, "'repeat' must be a positive integer up to 4294967295");
	t = TOP("\"repeat\": 0");
	EXPECT_ERROR_AT(t, "0 }", 0, "'repeat' must be a positive integer");
	t = TOP("\"threads\": [1, -2]");
	EXPECT_ERROR_AT(t, "-2", 0, "'threads[1]' must be a non-negative integer, not -2");
	t = TOP("\"threads\": 4");
	EXPECT_ERROR_AT(t, "4 }", 0, "'threads' must be an array of thread counts");
	t = TOP("\"threads\": []");
	EXPECT_ERROR_AT(t, "[]", 0, "'threads' must not be empty");
	t = TOP("\"threads\": [2, 4, 2]");
	EXPECT_ERROR_AT(t, "2]", 0, "'threads[2]' repeats thread count 2 of 'threads[0]'");
	t = TOP("\"validate\": \"yes\"");
	EXPECT_ERROR_AT(t, "\"yes\"", 0, "'validate' must be true or false, not a string");
	t = TOP("\"format_version\": 2");
	EXPECT_ERROR_AT(t, "2 }", 0, "'format_version' must be 1");
	t = TOP("\"output\": \"\"");
	EXPECT_ERROR_AT(t, "\"\"", 0, "'output' must not be empty");
	t = TOP("\"rays\": { \"width\": 0 }");
	EXPECT_ERROR_AT(t, "0 }", 0, "'rays.width' must be a positive integer, not 0");
	t = TOP("\"rays\": { \"height\": 16385 }");
	EXPECT_ERROR_AT(t, "16385", 0, "'rays.height' must be a positive integer up to 16384");
	t = TOP("\"rays\": { \"rounds\": 0 }");
	EXPECT_ERROR_AT(t, "0 }", 0, "'rays.rounds' must be a positive integer, not 0");
	t = TOP("\"rays\": { \"rounds\": 1001 }");
	EXPECT_ERROR_AT(t, "1001", 0, "'rays.rounds' must be a positive integer up to 1000");
	t = TOP("\"rays\": [1]");
	EXPECT_ERROR_AT(t, "[1]", 0, "'rays' must be an object");
	t = "{ \"builders\": [ { \"plugin\": \"a\", \"threads\": [true] } ], " SCENES " }";
	EXPECT_ERROR_AT(t, "true", 0, "'builders[0].threads[0]' must be a non-negative integer");
	t = "{ \"builders\": [ { \"plugin\": \"a\", \"options\": [] } ], " SCENES " }";
	EXPECT_ERROR_AT(t, "[]", 0, "'builders[0].options' must be an object, not an array");
	t = "{ \"scenes\": [ { \"generator\": \"soup\", \"seed\": 18446744073709551616 } ], "
	    BUILDERS " }";
	EXPECT_ERROR_AT(t, "1844", 0, "'scenes[0].seed' must be a non-negative integer");
	t = "{ \"scenes\": [ { \"generator\": \"soup\", \"subdivide\": 16 } ], " BUILDERS " }";
	EXPECT_ERROR_AT(t, "16", 0, "'scenes[0].subdivide' must be a non-negative integer up to 15");
	t = "{ \"scenes\": [ { \"generator\": \"soup\", \"name\": 3 } ], " BUILDERS " }";
	EXPECT_ERROR_AT(t, "3 }", 0, "'scenes[0].name' must be a string, not 3");
	t = "{ \"scenes\": [ 5 ], " BUILDERS " }";
	EXPECT_ERROR_AT(t, "5", 0, "'scenes[0]' must be an object, not 5");
	EXPECT_ERROR("[1]", 1, 1, "a config must be an object, not an array");
#undef TOP
}

static void test_structure(void)
{
	const char *t;
	EXPECT_ERROR("{ " BUILDERS " }", 1, 1, "missing 'scenes'");
	EXPECT_ERROR("{ " SCENES " }", 1, 1, "missing 'builders'");
	t = "{ \"scenes\": [], " BUILDERS " }";
	EXPECT_ERROR_AT(t, "[]", 0, "'scenes' must not be empty");
	t = "{ \"builders\": {}, " SCENES " }";
	EXPECT_ERROR_AT(t, "{}", 0, "'builders' must be an array, not an object");
	t = "{ \"scenes\": [ { \"path\": \"a.obj\", \"generator\": \"soup\" } ], " BUILDERS " }";
	EXPECT_ERROR_AT(t, "\"generator\"", 0,
	                "'scenes[0]' has both 'path' and 'generator': give exactly one");
	t = "{ \"scenes\": [ { \"generator\": \"soup\" },\n  { \"name\": \"x\" } ], " BUILDERS " }";
	EXPECT_ERROR(t, 2, 3, "'scenes[1]' needs a 'path' (a mesh file) or a 'generator'");
	t = "{ \"scenes\": [ { \"path\": \"a.obj\", \"frequency\": 3 } ], " BUILDERS " }";
	EXPECT_ERROR_AT(t, "\"frequency\"", 0, "'scenes[0].frequency' applies to generated");
	t = "{ \"builders\": [ { \"name\": \"x\" } ], " SCENES " }";
	EXPECT_ERROR_AT(t, "{ \"name", 0, "'builders[0]' needs a 'plugin'");
	t = "{ \"repeat\": 2, " SCENES ", " BUILDERS ",\n \"repeat\": 3 }";
	EXPECT_ERROR(t, 2, 2, "duplicate key 'repeat' at the top level (first at line 1, column 3)");
	t = "{ \"builders\": [ { \"plugin\": \"a\", \"plugin\": \"b\" } ], " SCENES " }";
	EXPECT_ERROR_AT(t, "\"plugin\"", 1, "duplicate key 'plugin' in builders[0]");
	t = "{ \"builders\": [ { \"plugin\": \"a\", \"options\": { \"k\": 1, \"k\": 2 } } ], "
	    SCENES " }";
	EXPECT_ERROR_AT(t, "\"k\"", 1, "duplicate key 'k' in builders[0].options");
	t = "{ " SCENES ", \"builders\": [ { \"plugin\": \"sah_seq\" },\n"
	    "  { \"plugin\": \"sah_seq\", \"threads\": [2] } ] }";
	EXPECT_ERROR(t, 2, 3, "duplicate builder name 'sah_seq': builders[0] has it too");
	t = "{ " SCENES ", \"builders\": [ { \"plugin\": \"a\", \"name\": \"x\" },"
	    " { \"plugin\": \"b\", \"name\": \"x\" } ] }";
	EXPECT_ERROR_AT(t, "\"x\"", 1, "duplicate builder name 'x'");
	t = "{ \"scenes\": [ { \"generator\": \"soup\" }, { \"path\": \"m/soup.ply\" } ], "
	    BUILDERS " }";
	EXPECT_ERROR_AT(t, "{ \"path", 0, "duplicate scene name 'soup': scenes[0] has it too");
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

/* ---- builder options --------------------------------------------------------- */

static const bvhlab_option_decl fake_options[] = {
	{ .name = "max_leaf", .type = BVHLAB_OPTION_INT, .help = "leaf size", .def_int = 4,
	  .min = 1, .max = 64 },
	{ .name = "method", .type = BVHLAB_OPTION_STRING, .help = "split search",
	  .def_string = "sweep", .choices = "sweep|binned" },
	{ .name = "spatial", .type = BVHLAB_OPTION_BOOL, .help = "spatial splits", .min = 1 },
	{ .name = "alpha", .type = BVHLAB_OPTION_FLOAT, .help = "overlap", .def_float = 0.5,
	  .min = 0.0, .max = 1.0 },
	{ .name = "salt", .type = BVHLAB_OPTION_INT, .help = "any integer", .min = 1 },
};

/* Never built: only the option declarations matter here. */
static const bvhlab_builder fake_builder = {
	.abi_version = BVHLAB_ABI_CURRENT, .struct_size = sizeof(bvhlab_builder),
	.name = "fake", .summary = "test descriptor", .option_count = 5,
	.options = fake_options,
};

/* Applies `options` (a JSON object's text) to builder "fast"; returns the rc. */
static int apply(const char *options, bvhlab_options *opts, bvhlab_error *err)
{
	char text[512];
	struct config cfg;
	snprintf(text, sizeof(text),
	         "{ " SCENES ",\n  \"builders\": [ { \"plugin\": \"fake\", \"name\": \"fast\","
	         "\n    \"options\": %s } ] }", options);
	CHECK_INT(bvhlab_options_init(opts, &fake_builder), 0);
	int rc = load(&cfg, text, err);
	CHECK_INT(rc, 0);
	if (rc)
		return rc;
	rc = config_apply_options(&cfg, &cfg.builders[0], opts, err);
	config_finish(&cfg);
	return rc;
}

/* Options sit on line 3 from column 16; the error must point at `key`. */
static void expect_option_error(int caller, const char *options, const char *key,
                                const char *needle)
{
	bvhlab_options opts;
	bvhlab_error err = { "" };
	char want[256];
	int rc = apply(options, &opts, &err);
	snprintf(want, sizeof(want), "%s:3:%d: builder 'fast': ", cfg_path,
	         (int)(strstr(options, key) - options) + 16);
	if (getenv("TEST_VERBOSE"))
		fprintf(stderr, "%s\n", err.message);
	if (rc >= 0 || strncmp(err.message, want, strlen(want)) != 0 || !strstr(err.message, needle)) {
		fprintf(stderr, "%s:%d: rc %d; expected \"%s...%s...\"\n     got \"%s\"\n",
		        __FILE__, caller, rc, want, needle, err.message);
		test_failures++;
	}
	bvhlab_options_finish(&opts);
}
#define EXPECT_OPTION_ERROR(options, key, needle) \
	expect_option_error(__LINE__, options, key, needle)

static void test_options(void)
{
	bvhlab_options opts;
	bvhlab_error err = { "" };
	int rc = apply("{ \"max_leaf\": 8, \"method\": \"binned\", \"spatial\": true, "
	               "\"alpha\": 1, \"salt\": -9223372036854775808 }",
	               &opts, &err);
	CHECK_INT(rc, 0);
	if (rc)
		fprintf(stderr, "%s\n", err.message);
	CHECK(opts.values[0].i == 8 && strcmp(opts.values[1].s, "binned") == 0);
	CHECK(opts.values[2].b && opts.values[3].f == 1.0 && opts.values[4].i == INT64_MIN);
	bvhlab_options_finish(&opts);

	EXPECT_OPTION_ERROR("{ \"max_leaf\": 8, \"mthod\": \"x\" }", "\"mthod\"",
	                    "unknown option 'mthod' (known: max_leaf, method, spatial, alpha, "
	                    "salt); did you mean 'method'?");
	EXPECT_OPTION_ERROR("{ \"max_leaf\": \"8\" }", "\"max_leaf\"",
	                    "option 'max_leaf' must be an integer, not a string");
	EXPECT_OPTION_ERROR("{ \"max_leaf\": 2.5 }", "\"max_leaf\"",
	                    "option 'max_leaf' must be an integer, not 2.5");
	EXPECT_OPTION_ERROR("{ \"salt\": 1e30 }", "\"salt\"", "an integer that fits in 64 bits");
	EXPECT_OPTION_ERROR("{ \"spatial\": 1 }", "\"spatial\"",
	                    "option 'spatial' must be true or false, not 1");
	EXPECT_OPTION_ERROR("{ \"alpha\": \"x\" }", "\"alpha\"", "option 'alpha' must be a");
	EXPECT_OPTION_ERROR("{ \"method\": null }", "\"method\"",
	                    "option 'method' must be a string, not null");
	/* Range and choices: the options module's message, located and named. */
	EXPECT_OPTION_ERROR("{ \"max_leaf\": 99 }", "\"max_leaf\"", "max_leaf");
	EXPECT_OPTION_ERROR("{ \"method\": \"fast\" }", "\"method\"", "sweep|binned");
}

/* ---- the position index ------------------------------------------------------ */

static void check_pos(const struct json_locations *loc, const cJSON *item, bool key,
                      int line, int col)
{
	int l = 0, c = 0;
	bool found = key ? json_locate_key(loc, item, &l, &c)
	                 : json_locate_value(loc, item, &l, &c);
	if (!found || l != line || c != col) {
		fprintf(stderr, "%s: %s of '%s' at %d:%d, expected %d:%d\n", __FILE__,
		        key ? "key" : "value", item->string ? item->string : "", l, c, line, col);
		test_failures++;
	}
}

static void test_locate(void)
{
	const char *text = "{\"a\": [1, {\"b\": true, \"b\": null}],\n"
	                   " \"c\": \"x\", \"\xC3\xA9\": 1, \"k\": 2}";
	cJSON *root = cJSON_Parse(text);
	struct json_locations *loc = NULL;
	CHECK_INT(json_locations_build(&loc, text, root), 0);
	const cJSON *a = root->child, *arr0 = a->child, *obj = arr0->next;
	int l, c;
	check_pos(loc, root, false, 1, 1);
	CHECK(!json_locate_key(loc, root, &l, &c) && !json_locate_key(loc, arr0, &l, &c));
	check_pos(loc, a, true, 1, 2);
	check_pos(loc, a, false, 1, 7);
	check_pos(loc, arr0, false, 1, 8);
	check_pos(loc, obj, false, 1, 11);
	check_pos(loc, obj->child, true, 1, 12);
	check_pos(loc, obj->child, false, 1, 17);
	check_pos(loc, obj->child->next, true, 1, 23); /* the duplicate, kept in order */
	check_pos(loc, obj->child->next, false, 1, 28);
	check_pos(loc, a->next, true, 2, 2);
	check_pos(loc, a->next->next->next, true, 2, 20); /* "é" is one column */
	json_locations_destroy(loc);
	json_locations_destroy(NULL);
	cJSON_Delete(root);
	json_offset_position("ab\ncd", 4, &l, &c);
	CHECK(l == 2 && c == 2);

	const char *numbers = "[0, -0, 9223372036854775807, -9223372036854775808, "
	                      "9223372036854775808, 1e3, 2.50e1, 1.5, 1e-1, 0e999999, 10e-1, "
	                      "123456789012345678901234, 0.000, 18446744073709551615, "
	                      "18446744073709551616, -1, \"7\"]";
	static const struct { int rc; int64_t v; } want[] = {
		{ 0, 0 }, { 0, 0 }, { 0, INT64_MAX }, { 0, INT64_MIN }, { -ERANGE, 0 },
		{ 0, 1000 }, { 0, 25 }, { -EINVAL, 0 }, { -EINVAL, 0 }, { 0, 0 }, { 0, 1 },
		{ -ERANGE, 0 }, { 0, 0 }, { -ERANGE, 0 }, { -ERANGE, 0 }, { 0, -1 }, { -EINVAL, 0 },
	};
	root = cJSON_Parse(numbers);
	CHECK_INT(json_locations_build(&loc, numbers, root), 0);
	size_t i = 0;
	for (const cJSON *e = root->child; e; e = e->next, i++) {
		int64_t v = 0;
		int rc = json_get_int64(loc, e, &v);
		if (rc != want[i].rc || (rc == 0 && v != want[i].v)) {
			fprintf(stderr, "%s: number %zu: rc %d, %lld\n", __FILE__, i, rc, (long long)v);
			test_failures++;
		}
	}
	uint64_t u = 0;
	CHECK(json_get_uint64(loc, cJSON_GetArrayItem(root, 13), &u) == 0 && u == UINT64_MAX);
	CHECK_INT(json_get_uint64(loc, cJSON_GetArrayItem(root, 14), &u), -ERANGE);
	CHECK_INT(json_get_uint64(loc, cJSON_GetArrayItem(root, 15), &u), -ERANGE);
	CHECK(json_get_uint64(loc, cJSON_GetArrayItem(root, 1), &u) == 0 && u == 0);
	json_locations_destroy(loc);
	cJSON_Delete(root);
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
	snprintf(tmp_dir, sizeof(tmp_dir), "/tmp/bvhlab-test-config-XXXXXX");
	if (!mkdtemp(tmp_dir)) {
		perror("mkdtemp");
		return 1;
	}
	snprintf(cfg_path, sizeof(cfg_path), "%s/c.json", tmp_dir);
	test_full();
	test_defaults();
	test_syntax();
	test_traversal();
	test_device_traversal();
	test_unknown_keys();
	test_types();
	test_structure();
	test_scene_camera();
	test_options();
	test_isolation_keys();
	test_locate();
	test_animation();
	unlink(cfg_path);
	rmdir(tmp_dir);
	return test_finish();
}
