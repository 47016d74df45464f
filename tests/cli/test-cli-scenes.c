/*
 * Which builders run on which scene (a builder's "scenes", #42) and a
 * two-level run's up-front memory estimate: a builder left off a scene has
 * no run there at all, in `run`, `plan` and `--resume` alike, and none
 * "failed"; a "scenes" that names no scene, is empty, repeats one or puts
 * a two-level builder on a one-level scene is exit 2 naming the key and
 * the builder, before any output folder; a two-level run whose estimate
 * exceeds its memory_limit_mb is refused before building, naming scene and
 * builder, and one that fits records its estimate and its measured memory.
 */
#include "cliutil.h"

/* Two strings equal, both shown when not. */
#define CHECK_STR(a, b) \
	do { \
		const char *a_ = (a), *b_ = (b); \
		if (strcmp(a_, b_) != 0) { \
			fprintf(stderr, "%s:%d: expected \"%s\", got \"%s\"\n", __FILE__, __LINE__, \
			        b_, a_); \
			test_failures++; \
		} \
	} while (0)

/* Into the output folder given, scenes "one" and "two"; builder "a" on
 * the scenes given only, "b" on both. */
static const char filter_config[] =
	"{ \"output\": \"%s\", \"repeat\": 1, \"warmup\": 0, \"threads\": [1],\n"
	"  \"rays\": { \"width\": 4, \"height\": 4, \"min_ms\": 1, \"rounds\": 1 },\n"
	"  \"scenes\": [ { \"name\": \"one\", \"generator\": \"soup\", \"count\": 100 },\n"
	"              { \"name\": \"two\", \"generator\": \"icosphere\", \"frequency\": 2 } ],\n"
	"  \"builders\": [ { \"plugin\": \"fake_good\", \"name\": \"a\", \"scenes\": %s },\n"
	"                { \"plugin\": \"fake_good\", \"name\": \"b\" } ] }\n";

static const char *str_at(const cJSON *o, const char *key)
{
	const cJSON *v = cJSON_GetObjectItem(o, key);
	return cJSON_IsString(v) ? v->valuestring : "";
}

/* The runs of a results.json or plan.json "runs" array are exactly
 * `expected` ("scene/builder" each, in id order), every one ok when
 * `ok` (results). */
static void check_runs(const cJSON *runs, const char *const *expected, size_t n, bool ok)
{
	CHECK_INT(cJSON_GetArraySize(runs), (int)n);
	for (size_t k = 0; k < n; k++) {
		const cJSON *run = NULL, *r;
		char slot[128];
		cJSON_ArrayForEach(r, runs) /* by id: a resumed document keeps its order */
			if (cJSON_GetObjectItem(r, "id") &&
			    cJSON_GetObjectItem(r, "id")->valueint == (int)k)
				run = r;
		CHECK(run != NULL);
		if (!run)
			continue;
		snprintf(slot, sizeof(slot), "%s/%s", str_at(run, "scene"), str_at(run, "builder"));
		CHECK_STR(slot, expected[k]);
		if (ok)
			CHECK_STR(str_at(run, "status"), "ok");
	}
}

static void check_results(const char *dir, const char *const *expected, size_t n)
{
	cJSON *doc = load_results(dir);
	check_runs(cJSON_GetObjectItem(doc, "runs"), expected, n, true);
	cJSON_Delete(doc);
}

/* "a" on "one" only, "b" on both: three runs, in `plan`, in a sweep done
 * in two parts (--only, then --resume), and after "a" moves to "two". */
static void filter(void)
{
	static const char *const runs[] = {"one/a", "one/b", "two/b"};
	static const char *const moved[] = {"one/b", "two/a", "two/b"};
	char text[2048];
	snprintf(text, sizeof(text), filter_config, "out", "[\"one\"]");
	const char *cfg = write_config("filter.json", text);
	CHECK_INT(run_in(tmpdir, ARGS("plan", cfg, "--out", "plan")), 0);
	char *plan_text = read_file(cli_path_in("plan"), "plan.json");
	cJSON *plan = plan_text ? cJSON_Parse(plan_text) : NULL;
	CHECK(plan != NULL);
	check_runs(cJSON_GetObjectItem(plan, "runs"), runs, 3, false);
	cJSON_Delete(plan);
	free(plan_text);
	/* the plan's parts, merged: what is missing is a run of the list */
	CHECK_INT(cli_run_part("plan", 0), 0);
	CHECK_INT(cli_run_part("plan", 2), 0);
	CHECK_INT(run(ARGS("merge", cli_path_in("plan/parts/0"), cli_path_in("plan/parts/2"),
	                   "--out", cli_path_in("plan"))), 1);
	CHECK_CONTAINS(err_text, "merged 2 of the plan's 3 runs");
	CHECK_CONTAINS(err_text, "missing: run 1 (one, b, 1 thread");
	CHECK_INT(run(ARGS("plan", "--missing", cli_path_in("plan"))), 0);
	CHECK_CONTAINS(out_text, "--only 1 --out ");
	CHECK_INT(cli_run_part("plan", 1), 0);
	CHECK_INT(run(ARGS("merge", cli_path_in("plan/parts/0"), cli_path_in("plan/parts/1"),
	                   cli_path_in("plan/parts/2"), "--out", cli_path_in("plan"))), 0);
	check_results(cli_path_in("plan"), runs, 3);
	/* the same sweep run at once, in two parts: --only, then --resume */
	CHECK_INT(run_in(tmpdir, ARGS("run", cfg, "--only", "1", "--quiet")), 0);
	CHECK_INT(runs_written(cli_path_in("out")), 1);
	CHECK_INT(run_in(tmpdir, ARGS("run", cfg, "--resume", "--quiet")), 0);
	check_results(cli_path_in("out"), runs, 3);
	/* "a" now on "two": its run on "one" is dropped, not refused. */
	snprintf(text, sizeof(text), filter_config, "out", "[\"two\"]");
	cfg = write_config("filter.json", text);
	CHECK_INT(run_in(tmpdir, ARGS("run", cfg, "--resume")), 0);
	CHECK_CONTAINS(err_text, "1 run dropped");
	check_results(cli_path_in("out"), moved, 3);
	char *md = read_file(cli_path_in("out"), "report.md");
	CHECK(md && !strstr(md, "failed"));
	free(md);
}

/* Each bad "scenes" is exit 2, naming key and builder, with no folder. */
static void errors(void)
{
	static const struct {
		const char *value, *message;
	} cases[] = {
		{"[\"one\", \"tow\"]", "'builders[0].scenes[1]' of builder 'a': no scene is named "
		                     "'tow' (the config's scenes: one, two); did you mean 'two'?"},
		{"[]", "'builders[0].scenes' of builder 'a' is empty: list the scenes it runs on"},
		{"[\"one\", \"one\"]", "'builders[0].scenes[1]' of builder 'a': scene 'one' is listed "
		                     "twice"},
		{"\"one\"", "'builders[0].scenes' of builder 'a' must be an array of scene names, not "
		            "a string"},
		{"[1]", "'builders[0].scenes[0]' of builder 'a' must be a scene's name, not 1"},
	};
	char text[2048];
	for (size_t k = 0; k < sizeof(cases) / sizeof(cases[0]); k++) {
		snprintf(text, sizeof(text), filter_config, "out-bad", cases[k].value);
		cli_refused("bad.json", text, cases[k].message);
	}
	CHECK(!cli_exists(cli_path_in("out-bad")));
	cli_refused("two.json",
	            "{ \"output\": \"out-bad\",\n"
	            "  \"scenes\": [ { \"name\": \"one\", \"generator\": \"soup\", \"count\": 10 } ],\n"
	            "  \"builders\": [ { \"bottom\": \"sah_seq\", \"top\": \"lbvh\",\n"
	            "                    \"scenes\": [\"one\"] } ] }\n",
	            "'builders[0].scenes' of builder 'two-level[top=lbvh,bottom=sah_seq]': a "
	            "two-level builder runs on two-level scenes only, and scene 'one' has no "
	            "'instances'");
	CHECK(!cli_exists(cli_path_in("out-bad")));
}

static double num_at(const cJSON *run, const char *object, const char *key)
{
	const cJSON *v = cJSON_GetObjectItem(cJSON_GetObjectItem(run, object), key);
	return cJSON_IsNumber(v) ? v->valuedouble : -1;
}

/* 180-triangle balls placed 20,000 times, beside a one-level scene: the
 * two-level builders on the forest only, "capped" under 4 MiB (the
 * instances' records alone are 3.8 MiB) refused before building, "free"
 * run; the forest never flattened (no one-level builder runs on it). */
static void estimate(void)
{
	const char *text =
		"{ \"output\": \"out-est\", \"repeat\": 1, \"warmup\": 0, \"threads\": [1],\n"
		"  \"validate_rays\": 16, \"rays\": { \"width\": 4, \"height\": 4, \"min_ms\": 1 },\n"
		"  \"scenes\": [ { \"name\": \"plain\", \"generator\": \"soup\", \"count\": 50 },\n"
		"    { \"name\": \"forest\",\n"
		"      \"meshes\": [ { \"name\": \"ball\", \"generator\": \"icosphere\",\n"
		"                      \"frequency\": 3 } ],\n"
		"      \"instances\": [ { \"scatter\": { \"mesh\": \"ball\", \"count\": 20000,\n"
		"        \"bounds\": [[-200, 0, -200], [200, 0, 200]] } } ] } ],\n"
		"  \"builders\": [ { \"plugin\": \"sah_seq\", \"scenes\": [\"plain\"] },\n"
		"    { \"name\": \"capped\", \"bottom\": \"sah_seq\", \"top\": \"lbvh\",\n"
		"      \"memory_limit_mb\": 4, \"scenes\": [\"forest\"] },\n"
		"    { \"name\": \"free\", \"bottom\": \"sah_seq\", \"top\": \"lbvh\",\n"
		"      \"scenes\": [\"forest\"] } ] }\n";
	CHECK_INT(run_in(tmpdir, ARGS("run", "--quiet", write_config("est.json", text))), 1);
	cJSON *doc = load_results(cli_path_in("out-est"));
	CHECK_INT(cJSON_GetArraySize(cJSON_GetObjectItem(doc, "runs")), 3);
	const cJSON *capped = find_run(doc, "forest", "capped", 1);
	const cJSON *free_run = find_run(doc, "forest", "free", 1);
	CHECK(capped && free_run && find_run(doc, "plain", "sah_seq", 1));
	CHECK_STR(str_at(capped, "status"), "failed");
	CHECK_CONTAINS(str_at(capped, "error"), "scene 'forest', builder 'capped': refused before "
	                                         "building: estimated peak ");
	CHECK_CONTAINS(str_at(capped, "error"), " 180 unique triangles x ");
	CHECK_CONTAINS(str_at(capped, "error"), " 20000 instances x ");
	CHECK_CONTAINS(str_at(capped, "error"), ") exceeds memory_limit_mb = 4");
	CHECK(!cJSON_GetObjectItem(capped, "build_ms") && !cJSON_GetObjectItem(capped, "memory"));
	CHECK(num_at(capped, "memory_estimate", "bytes") >
	      num_at(capped, "memory_estimate", "limit_bytes"));
	CHECK(num_at(capped, "memory_estimate", "limit_bytes") == 4.0 * 1048576);
	CHECK(num_at(capped, "memory_estimate", "instances") == 20000);
	CHECK(num_at(capped, "memory_estimate", "scene_bytes") >= 20000 * 200.0);
	CHECK_STR(str_at(free_run, "status"), "ok");
	CHECK(num_at(free_run, "memory_estimate", "top_bytes_per_instance") > 68);
	CHECK_STR(str_at(cJSON_GetObjectItem(free_run, "memory_estimate"), "limit"), "available");
	/* measured: the same scene share, the whole run's peak, no per-triangle figure */
	CHECK(num_at(free_run, "memory", "scene_bytes") ==
	      num_at(free_run, "memory_estimate", "scene_bytes"));
	CHECK(num_at(free_run, "memory", "run_peak_rss_bytes") >=
	      num_at(free_run, "memory", "peak_rss_bytes"));
	CHECK(num_at(free_run, "memory", "peak_rss_bytes") > 0);
	CHECK(!cJSON_GetObjectItem(cJSON_GetObjectItem(free_run, "memory"),
	                           "child_bytes_per_triangle"));
	const cJSON *forest = cJSON_GetArrayItem(cJSON_GetObjectItem(doc, "scenes"), 1);
	CHECK_STR(str_at(forest, "source"), "two-level scene");
	/* the levels' table states the run's peak */
	char *md = read_file(cli_path_in("out-est"), "report.md"), row[128];
	snprintf(row, sizeof(row), "| %.1f |\n",
	         num_at(free_run, "memory", "run_peak_rss_bytes") / 1048576.0);
	CHECK_CONTAINS(md, "| two-level SAH | peak MiB |");
	CHECK_CONTAINS(md, row);
	free(md);
	cJSON_Delete(doc);
}

static void all(void)
{
	filter();
	errors();
	estimate();
}

int main(int argc, char **argv)
{
	static const struct cli_mode modes[] = {{"all", all}};
	return cli_main_modes(argc, argv, "test-cli-scenes", modes, 1);
}
