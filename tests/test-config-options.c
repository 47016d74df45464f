/*
 * A builder's "options" in a config applied to its declarations
 * (config_apply_options): values of every type, and each error located at
 * its key and naming the builder.
 */
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include <bvhlab/builder.h>
#include <bvhlab/host.h>

#include "config/config.h"
#include "testutil.h"

#include "config_fixture.h"
#include "scene_files.h"

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
	                    "unknown option 'mthod' for plugin 'fake' (known: max_leaf, method, "
	                    "spatial, alpha, salt); did you mean 'method'?");
	EXPECT_OPTION_ERROR("{ \"max_leaf\": \"8\" }", "\"max_leaf\"",
	                    "option 'max_leaf' of plugin 'fake' must be an integer in [1, 64], not a "
	                    "string");
	EXPECT_OPTION_ERROR("{ \"max_leaf\": 2.5 }", "\"max_leaf\"",
	                    "option 'max_leaf' of plugin 'fake' must be an integer in [1, 64], not 2.5");
	EXPECT_OPTION_ERROR("{ \"salt\": 1e30 }", "\"salt\"", "an integer that fits in 64 bits");
	EXPECT_OPTION_ERROR("{ \"spatial\": 1 }", "\"spatial\"",
	                    "option 'spatial' of plugin 'fake' must be true or false, not 1");
	EXPECT_OPTION_ERROR("{ \"alpha\": \"x\" }", "\"alpha\"",
	                    "option 'alpha' of plugin 'fake' must be a");
	EXPECT_OPTION_ERROR("{ \"method\": null }", "\"method\"",
	                    "option 'method' of plugin 'fake' must be a string (one of sweep|binned), "
	                    "not null");
	/* Range and choices: the options module's message, located and named. */
	EXPECT_OPTION_ERROR("{ \"max_leaf\": 99 }", "\"max_leaf\"", "max_leaf");
	EXPECT_OPTION_ERROR("{ \"method\": \"fast\" }", "\"method\"", "sweep|binned");
}

int main(void)
{
	config_fixture_open("config-options");
	test_options();
	tmp_end();
	return test_finish();
}
