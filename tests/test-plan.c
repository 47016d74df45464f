/*
 * Option grids and run ids: a grid expands into one builder per value (per
 * combination), in order, named after what varies, each value applied and
 * checked like a plain one; run ids follow `bvhlab run`'s order; --only
 * lists parse into exactly the ids they name.
 */
#include <errno.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "config/config.h"
#include "plan/plan.h"
#include "testutil.h"

#define SCENES "\"scenes\": [ { \"generator\": \"icosphere\" }, { \"generator\": \"soup\" } ]"

static const bvhlab_option_decl options[] = {
	{ .name = "max_leaf", .type = BVHLAB_OPTION_INT, .help = "leaf size", .def_int = 4,
	  .min = 1, .max = 64 },
	{ .name = "method", .type = BVHLAB_OPTION_STRING, .help = "split search",
	  .def_string = "sweep", .choices = "sweep|binned" },
	{ .name = "spatial", .type = BVHLAB_OPTION_BOOL, .help = "spatial splits", .min = 1 },
};

/* Never built: only the option declarations matter here. */
static const bvhlab_builder fake_builder = {
	.abi_version = BVHLAB_ABI_CURRENT, .struct_size = sizeof(bvhlab_builder),
	.name = "fake", .summary = "test descriptor", .option_count = 3, .options = options,
};

static int parse(struct config *cfg, const char *builders, bvhlab_error *err)
{
	char text[1024];
	snprintf(text, sizeof(text), "{ " SCENES ", \"threads\": [1, 2],\n  \"builders\": %s }",
	         builders);
	return config_parse(cfg, "grid.json", text, err);
}

/* Two grids: their product, the last varying fastest, each named and applied. */
static void test_product(void)
{
	static const char *const names[] = {
		"g[max_leaf=2,method=sweep]", "g[max_leaf=2,method=binned]",
		"g[max_leaf=8,method=sweep]", "g[max_leaf=8,method=binned]", "plain"};
	struct config cfg;
	bvhlab_error err = {{0}};
	CHECK_INT(parse(&cfg, "[ { \"plugin\": \"fake\", \"name\": \"g\", \"options\": {\n"
	                "    \"max_leaf\": { \"grid\": [2, 8] }, \"spatial\": true,\n"
	                "    \"method\": { \"grid\": [\"sweep\", \"binned\"] } } },\n"
	                "  { \"plugin\": \"fake\", \"name\": \"plain\" } ]", &err), 0);
	CHECK_INT(cfg.builder_count, 5);
	for (size_t b = 0; b < cfg.builder_count && b < 5; b++) {
		CHECK(!strcmp(cfg.builders[b].name, names[b]));
		bvhlab_options opts;
		CHECK_INT(bvhlab_options_init(&opts, &fake_builder), 0);
		CHECK_INT(config_apply_options(&cfg, &cfg.builders[b], &opts, &err), 0);
		if (b < 4) {
			CHECK_INT(opts.values[0].i, b < 2 ? 2 : 8);
			CHECK(!strcmp(opts.values[1].s, b % 2 ? "binned" : "sweep"));
			CHECK(opts.values[2].b);
		}
		bvhlab_options_finish(&opts);
	}
	/* 2 scenes x 5 builders x 2 thread counts, ids in run order. */
	struct run_list list;
	CHECK_INT(plan_list_make(&list, &cfg, NULL, &err), 0);
	CHECK_INT(list.count, 20);
	for (size_t k = 0; k < list.count; k++) {
		const struct plan_run *run = &list.runs[k];
		CHECK_INT(run->key.id, k);
		CHECK(plan_list_find(&list, run->scene, run->builder, k % 2) == run);
		CHECK_INT(run->threads, k % 2 + 1);
		CHECK_INT(run->key.threads, k % 2 + 1);
		CHECK(!strcmp(run->key.builder, cfg.builders[run->builder].name));
	}
	CHECK(list.runs[10].scene == 1 && list.runs[10].builder == 0);
	plan_list_finish(&list);
	/* A serial builder runs once per scene, at its count of 1: the ids
	 * after it close up, and its 2 has no run. */
	struct plan_builder pb[5] = {{.serial = true}};
	CHECK_INT(plan_list_make(&list, &cfg, pb, &err), 0);
	CHECK_INT(list.count, 18);
	CHECK(list.runs[0].builder == 0 && list.runs[0].key.threads == 1);
	CHECK(list.runs[1].builder == 1 && list.runs[1].key.id == 1);
	CHECK(plan_list_find(&list, 1, 0, 1) == NULL);
	CHECK(plan_list_first(&list, 1, 0) == &list.runs[9]);
	CHECK(list.threads[0].serial && list.threads[0].first == 0);
	plan_list_finish(&list);
	config_finish(&cfg);
}

/* A grid value the plugin refuses: its element's position, the key and the value. */
static void test_bad_value(void)
{
	struct config cfg;
	bvhlab_error err = {{0}};
	CHECK_INT(parse(&cfg, "[ { \"plugin\": \"fake\", \"options\": {\n"
	                "    \"max_leaf\": { \"grid\": [4, 65] } } } ]", &err), 0);
	bvhlab_options opts;
	CHECK_INT(bvhlab_options_init(&opts, &fake_builder), 0);
	CHECK_INT(config_apply_options(&cfg, &cfg.builders[0], &opts, &err), 0);
	CHECK_INT(config_apply_options(&cfg, &cfg.builders[1], &opts, &err), -EINVAL);
	CHECK_CONTAINS(err.message, "grid.json:3:31: builder 'fake[max_leaf=65]'");
	CHECK_CONTAINS(err.message, "65 not in [1, 64] (options.max_leaf.grid[1])");
	bvhlab_options_finish(&opts);
	config_finish(&cfg);
	CHECK_INT(parse(&cfg, "[ { \"plugin\": \"fake\", \"options\": {\n"
	                "    \"method\": { \"grid\": [\"sweep\", 3] } } } ]", &err), 0);
	CHECK_INT(bvhlab_options_init(&opts, &fake_builder), 0);
	CHECK_INT(config_apply_options(&cfg, &cfg.builders[1], &opts, &err), -EINVAL);
	CHECK_CONTAINS(err.message, "grid.json:3:35: builder 'fake[method=3]': option 'method' "
	                            "of plugin 'fake' must be a string (one of sweep|binned), "
	                            "not 3 (options.method.grid[1])");
	bvhlab_options_finish(&opts);
	config_finish(&cfg);
}

/* Names that collide once expanded are refused. */
static void test_duplicate_names(void)
{
	struct config cfg;
	bvhlab_error err = {{0}};
	CHECK_INT(parse(&cfg, "[ { \"plugin\": \"fake\", \"options\": { \"max_leaf\": { \"grid\": "
	                "[4, 4] } } } ]", &err), -EINVAL);
	CHECK_CONTAINS(err.message, "duplicate builder name 'fake[max_leaf=4]' after expanding");
	CHECK_INT(parse(&cfg, "[ { \"plugin\": \"fake\", \"options\": { \"max_leaf\": { \"grid\": "
	                "[4] } } }, { \"plugin\": \"fake\", \"name\": \"fake[max_leaf=4]\" } ]",
	                &err), -EINVAL);
	CHECK_CONTAINS(err.message, "duplicate builder name 'fake[max_leaf=4]'");
}

static void expect_only(const char *text, size_t count, const char *ids)
{
	bool *only = NULL;
	bvhlab_error err = {{0}};
	CHECK_INT(plan_parse_only(text, count, &only, &err), 0);
	for (size_t k = 0; only && k < count; k++)
		CHECK_INT(only[k], ids[k] == '1');
	free(only);
}

static void test_only(void)
{
	bool *only = NULL;
	bvhlab_error err = {{0}};
	expect_only("3", 6, "000100");
	expect_only("0,2-4", 6, "101110");
	expect_only("5,5,0-0", 6, "100001");
	CHECK_INT(plan_parse_only("6", 6, &only, &err), -EINVAL);
	CHECK_CONTAINS(err.message, "there is no run 6; this config has 6 runs (ids 0 to 5");
	static const char *const bad[] = {"", "a", "-1", "3-1", "1,,2", "2-", "1 "};
	for (size_t k = 0; k < sizeof(bad) / sizeof(bad[0]); k++) {
		CHECK_INT(plan_parse_only(bad[k], 6, &only, &err), -EINVAL);
		CHECK_CONTAINS(err.message, "--only needs run ids like 3,7,10-12");
		CHECK(only == NULL);
	}
}

/* The hash is FNV-1a 64: fixed values, so plans stay comparable across builds. */
static void test_hash(void)
{
	char h[17];
	plan_hash_text("", h);
	CHECK(!strcmp(h, "cbf29ce484222325"));
	plan_hash_text("a", h);
	CHECK(!strcmp(h, "af63dc4c8601ec8c"));
}

int main(void)
{
	test_product();
	test_bad_value();
	test_duplicate_names();
	test_only();
	test_hash();
	return test_finish();
}
