/*
 * Experiment configs that do not load: JSON syntax, unknown keys, wrong
 * types and ranges, a missing or contradictory structure, each with its
 * FILE:LINE:COL.
 */
#include <errno.h>
#include <string.h>

#include "config/config.h"
#include "testutil.h"

#include "config_fixture.h"
#include "scene_files.h"

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
	write_config("{\n \0 }", 6);
	CHECK_INT(config_load(&cfg, cfg_path, &err), -EINVAL);
	CHECK_CONTAINS(err.message, ":2:2: NUL byte");
	CHECK_INT(config_load(&cfg, tmp_path("missing.json"), &err), -ENOENT);
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
	                "meshes, instances, frequency, count, size, seed, width, subdivide, frames, "
	                "animate, deform, "
	                "amplitude, camera); did you mean "
	                "'frequency'?");
	EXPECT_ERROR("{ " SCENES ",\n"
	             "  \"builders\": [ { \"plugin\": \"a\" },\n"
	             "    { \"plugin\": \"b\", \"threds\": [2] } ] }",
	             3, 22,
	             "unknown key 'threds' in builders[1] (known: plugin, name, threads, "
	             "timeout_s, memory_limit_mb, options, optional, refine, animation, bottom, "
	             "top, top_options, scenes); did you mean 'threads'?");
	t = "{ " SCENES ", " BUILDERS ", \"rays\": { \"widht\": 8 } }";
	EXPECT_ERROR_AT(t, "\"widht\"", 0, "unknown key 'widht' in rays (known: width, height, "
	                "diffuse, camera, threads, min_ms, rounds, traversal, device, kinds, light, "
	                "ao_length); did you mean "
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

int main(void)
{
	config_fixture_open("config-errors");
	test_syntax();
	test_unknown_keys();
	test_types();
	test_structure();
	tmp_end();
	return test_finish();
}
