/*
 * Sweeps split across machines: option grids, `bvhlab plan`, `run --only`
 * and `bvhlab merge`, through GNU parallel as a user would drive them.
 * Usage: test-cli-plan BVHLAB_EXE grid|errors|parallel|serial
 */
#include <limits.h>
#include <stdbool.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>

#include <cJSON.h>

#include "cliutil.h"

/* 2 scenes x (a parallel grid of two bin counts x 2 thread counts, and a
 * serial sweep once): 10 runs. */
static const char sweep_config[] =
	"{ \"repeat\": 1, \"threads\": [1, 2], \"validate_rays\": 64, \"images\": true,\n"
	"  \"rays\": { \"width\": 16, \"height\": 16 },\n"
	"  \"scenes\": [ { \"generator\": \"icosphere\", \"frequency\": 6 },\n"
	"              { \"generator\": \"soup\", \"count\": 400 } ],\n"
	"  \"builders\": [\n"
	"    { \"plugin\": \"sah_tasks\", \"options\": { \"method\": \"binned\",\n"
	"                                              \"bins\": { \"grid\": [4, 8] } } },\n"
	"    { \"plugin\": \"sah_seq\", \"name\": \"sweep\", \"options\": { \"method\": \"sweep\" } } ] }\n";

static char *path_in(const char *name)
{
	static char buf[4][512];
	static int next;
	char *p = buf[next++ % 4];
	snprintf(p, 512, "%s/%s", tmpdir, name);
	return p;
}

/* Runs a shell command line in tmpdir; its exit status. */
static int shell(const char *fmt, const char *a, const char *b)
{
	char cmd[2048], line[1800];
	snprintf(line, sizeof(line), fmt, a, b);
	snprintf(cmd, sizeof(cmd), "cd '%s' && %s", tmpdir, line);
	int status = system(cmd);
	return WIFEXITED(status) ? WEXITSTATUS(status) : 128;
}

static bool exists(const char *path)
{
	struct stat st;
	return stat(path, &st) == 0;
}

/* Lines of the text (the commands a plan printed). */
static int count_lines(const char *text)
{
	int n = 0;
	for (; *text; text++)
		n += *text == '\n';
	return n;
}

static double num(const cJSON *o, const char *a, const char *b)
{
	const cJSON *v = cJSON_GetObjectItem(o, a);
	v = b ? cJSON_GetObjectItem(v, b) : v;
	return cJSON_IsNumber(v) ? v->valuedouble : -1;
}

/* Same runs in the same order with the same status, tree and validation. */
static void check_same_runs(const cJSON *merged, const cJSON *single)
{
	const cJSON *ra = cJSON_GetObjectItem(merged, "runs"), *rb = cJSON_GetObjectItem(single, "runs");
	CHECK_INT(cJSON_GetArraySize(ra), cJSON_GetArraySize(rb));
	for (const cJSON *a = ra ? ra->child : NULL, *b = rb ? rb->child : NULL; a && b;
	     a = a->next, b = b->next) {
		CHECK(num(a, "id", NULL) == num(b, "id", NULL));
		CHECK(!strcmp(run_str(a, "scene"), run_str(b, "scene")));
		CHECK(!strcmp(run_str(a, "builder"), run_str(b, "builder")));
		CHECK(num(a, "threads", NULL) == num(b, "threads", NULL));
		CHECK(!strcmp(run_str(a, "status"), run_str(b, "status")));
		CHECK(num(a, "tree", "sah_cost") > 0);
		CHECK(num(a, "tree", "sah_cost") == num(b, "tree", "sah_cost"));
		CHECK(num(a, "tree", "nodes") == num(b, "tree", "nodes"));
		CHECK(cJSON_IsTrue(cJSON_GetObjectItem(cJSON_GetObjectItem(a, "validation"), "valid")));
		CHECK(cJSON_IsTrue(cJSON_GetObjectItem(cJSON_GetObjectItem(b, "validation"), "valid")));
		CHECK(cJSON_IsObject(cJSON_GetObjectItem(a, "machine")));
	}
}


/* ---- grids ------------------------------------------------------------------- */

static const char grid_config[] =
	"{ \"output\": \"out-grid\", \"repeat\": 1, \"validate_rays\": 32, \"rays\": { \"width\": 8, \"height\": 8 },\n"
	"  \"scenes\": [ { \"generator\": \"icosphere\", \"frequency\": 6 } ],\n"
	"  \"builders\": [ { \"plugin\": \"sah_seq\", \"options\": { \"method\": \"binned\",\n"
	"    \"bins\": { \"grid\": [4, 8, 16, 32] } } } ] }\n";

/* Four bin counts: four builders, named apart in the results and reports. */
static void test_grid_runs(void)
{
	static const int bins[] = {4, 8, 16, 32};
	CHECK_INT(run(ARGS("run", "--quiet", write_config("grid.json", grid_config))), 0);
	cJSON *doc = load_results(path_in("out-grid"));
	char *md = read_file(path_in("out-grid"), "report.md");
	char *html = read_file(path_in("out-grid"), "report.html");
	CHECK_INT(cJSON_GetArraySize(cJSON_GetObjectItem(doc, "runs")), 4);
	for (int k = 0; k < 4; k++) {
		char name[64];
		snprintf(name, sizeof(name), "sah_seq[bins=%d]", bins[k]);
		CHECK_INT(count_runs(doc, name, "ok"), 1);
		const cJSON *r = cJSON_GetArrayItem(cJSON_GetObjectItem(doc, "runs"), k);
		CHECK(!strcmp(run_str(r, "builder"), name));
		CHECK(num(r, "options", "bins") == bins[k]);
		CHECK_CONTAINS(md, name);
		CHECK_CONTAINS(html, name);
	}
	free(md);
	free(html);
	cJSON_Delete(doc);
}

/* A value out of the option's range: the key, the grid position and the value. */
static void test_grid_range(void)
{
	const char *cfg = write_config("badgrid.json",
		"{ \"output\": \"out-badgrid\", \"repeat\": 1,\n"
		"  \"scenes\": [ { \"generator\": \"icosphere\", \"frequency\": 4 } ],\n"
		"  \"builders\": [ { \"plugin\": \"sah_seq\",\n"
		"    \"options\": { \"bins\": { \"grid\": [4, 8, 1000] } } } ] }\n");
	CHECK_INT(run(ARGS("plan", cfg, "--out", path_in("badplan"))), 2);
	CHECK_CONTAINS(err_text, "badgrid.json:4:43: builder 'sah_seq[bins=1000]'");
	CHECK_CONTAINS(err_text, "option 'bins'");
	CHECK_CONTAINS(err_text, "1000 not in [2, 256]");
	CHECK_CONTAINS(err_text, "(options.bins.grid[2])");
	CHECK(!exists(path_in("badplan/plan.json")));
	/* `run` refuses it too, like any bad option, before making the output folder. */
	CHECK_INT(run(ARGS("run", "--quiet", cfg)), 2);
	CHECK_CONTAINS(err_text, "(options.bins.grid[2])");
	CHECK(!exists(path_in("out-badgrid")));
}

/* Malformed grids are config errors (exit 2) at their position. */
static void test_grid_syntax(void)
{
	static const char *const cases[][2] = {
		{"{ \"grid\": [] }", "'builders[0].options.bins.grid' must be a non-empty array"},
		{"{ \"grid\": [4], \"step\": 2 }", "a grid is {\"grid\": [values...]} with no other key"},
		{"{ \"grid\": [4, [8]] }", "'builders[0].options.bins.grid[1]' must be a number"},
	};
	for (size_t k = 0; k < sizeof(cases) / sizeof(cases[0]); k++) {
		cli_refused_with("syntax.json",
		                 "{ \"scenes\": [ { \"generator\": \"icosphere\" } ],\n"
		                 "  \"builders\": [ { \"plugin\": \"sah_seq\", \"options\": { \"bins\": %s } } ] }\n",
		                 cases[k][0], cases[k][1]);
		CHECK_CONTAINS(err_text, "syntax.json:2:");
	}
}


/* ---- bad input ------------------------------------------------------------------ */

/* A parallel builder: its two thread counts are two runs. */
static const char small_config[] =
	"{ \"repeat\": 1, \"threads\": [1, 2], \"validate_rays\": 16, \"rays\": { \"width\": 8, \"height\": 8 },\n"
	"  \"scenes\": [ { \"generator\": \"soup\", \"count\": 200 } ],\n"
	"  \"builders\": [ { \"plugin\": \"sah_tasks\" } ] }\n";

/* A part of the plan in DIR: `run DIR/plan.json --only ID --out PART`. */
static int run_part(const char *dir, const char *id, const char *part)
{
	char plan[512];
	snprintf(plan, sizeof(plan), "%s/plan.json", path_in(dir));
	return run(ARGS("run", "--quiet", plan, "--only", id, "--out", path_in(part)));
}

static void check_unchanged(const char *dir, const char *name, const char *before)
{
	char *after = read_file(path_in(dir), name);
	CHECK(after && before && !strcmp(after, before));
	free(after);
}

/* The plan's config file changed: its runs, merge and --missing all refuse. */
static void test_changed_config(void)
{
	const char *cfg = write_config("changed.json", small_config);
	CHECK_INT(run(ARGS("plan", cfg, "--out", path_in("chg"))), 0);
	write_config("changed.json",
	             "{ \"repeat\": 1, \"threads\": [2, 1],\n"
	             "  \"scenes\": [ { \"generator\": \"soup\", \"count\": 200 } ],\n"
	             "  \"builders\": [ { \"plugin\": \"sah_tasks\" } ] }\n");
	CHECK_INT(run_part("chg", "0", "chg/parts/0"), 2);
	CHECK_CONTAINS(err_text, "changed.json has changed since planning");
	CHECK(!exists(path_in("chg/parts/0")));
	CHECK_INT(run(ARGS("plan", "--missing", path_in("chg"))), 2);
	CHECK_CONTAINS(err_text, "has changed since planning");
	/* Planning the changed config into the same folder would renumber its runs. */
	char *before = read_file(path_in("chg"), "plan.json");
	CHECK_INT(run(ARGS("plan", cfg, "--out", path_in("chg"))), 2);
	CHECK_CONTAINS(err_text, "holds another plan");
	check_unchanged("chg", "plan.json", before);
	free(before);
}

/* --only with an id the config does not have, or with --threads. */
static void test_bad_only(void)
{
	const char *cfg = write_config("small.json", small_config);
	CHECK_INT(run(ARGS("run", "--quiet", cfg, "--only", "2", "--out", path_in("only"))), 2);
	CHECK_CONTAINS(err_text, "--only: there is no run 2; this config has 2 runs (ids 0 to 1");
	CHECK_INT(run(ARGS("run", "--quiet", cfg, "--only", "0,x", "--out", path_in("only"))), 2);
	CHECK_CONTAINS(err_text, "--only needs run ids like 3,7,10-12, not '0,x'");
	CHECK_INT(run(ARGS("run", "--quiet", cfg, "--only", "0", "--threads", "1",
	                   "--out", path_in("only"))), 2);
	CHECK_CONTAINS(err_text, "--threads cannot be combined with --only");
	CHECK(!exists(path_in("only")));
	/* One run of a config, by id: the second (sah_tasks, 2 threads). */
	CHECK_INT(run(ARGS("run", "--quiet", cfg, "--only", "1", "--out", path_in("only"))), 0);
	cJSON *doc = load_results(path_in("only"));
	const cJSON *r = cJSON_GetArrayItem(cJSON_GetObjectItem(doc, "runs"), 0);
	CHECK_INT(cJSON_GetArraySize(cJSON_GetObjectItem(doc, "runs")), 1);
	CHECK(num(r, "id", NULL) == 1 && num(r, "threads", NULL) == 2);
	cJSON_Delete(doc);
}

/* Parts that do not fit: no results.json, the same run twice, another plan. */
static void test_bad_parts(void)
{
	const char *cfg = write_config("merge.json", small_config);
	CHECK_INT(run(ARGS("plan", cfg, "--out", path_in("m"))), 0);
	CHECK_INT(run_part("m", "0", "m/parts/0"), 0);
	mkdir(path_in("m/parts/empty"), 0777);
	CHECK_INT(run(ARGS("merge", path_in("m/parts/0"), path_in("m/parts/empty"), "--out",
	                   path_in("m"))), 2);
	CHECK_CONTAINS(err_text, "part ");
	CHECK_CONTAINS(err_text, "m/parts/empty has no results.json");
	CHECK(!exists(path_in("m/results.json")));
	CHECK_INT(run_part("m", "0", "m/again"), 0);
	CHECK_INT(run(ARGS("merge", path_in("m/parts/0"), path_in("m/again"), "--out",
	                   path_in("m"))), 2);
	CHECK_CONTAINS(err_text, "run 0 (soup, sah_tasks) is claimed by two parts");
	CHECK_CONTAINS(err_text, "m/again: remove one of them");
	write_config("other.json", "{ \"repeat\": 2, \"scenes\": [ { \"generator\": \"soup\", "
	             "\"count\": 200 } ], \"builders\": [ { \"plugin\": \"sah_seq\" } ] }\n");
	CHECK_INT(run(ARGS("plan", path_in("other.json"), "--out", path_in("o"))), 0);
	CHECK_INT(run_part("o", "0", "o/parts/0"), 0);
	CHECK_INT(run(ARGS("merge", path_in("m/parts/0"), path_in("o/parts/0"), "--out",
	                   path_in("m"))), 2);
	CHECK_CONTAINS(err_text, "o/parts/0 comes from another plan");
	CHECK(!exists(path_in("m/results.json")));
	/* A plain run's results are not a part of any plan. */
	CHECK_INT(run(ARGS("run", "--quiet", path_in("merge.json"), "--only", "1", "--out",
	                   path_in("plain"))), 0);
	CHECK_INT(run(ARGS("merge", path_in("plain"), "--out", path_in("m"))), 2);
	CHECK_CONTAINS(err_text, "plain was not run from a plan");
	/* Nor is its folder a place to merge into: its results.json stays. */
	char *before = read_file(path_in("plain"), "results.json");
	char plan[512];
	snprintf(plan, sizeof(plan), "%s/plan.json", path_in("m"));
	CHECK_INT(run(ARGS("merge", path_in("m/parts/0"), "--plan", plan, "--out", path_in("plain"))),
	          2);
	CHECK_CONTAINS(err_text, "results.json is not an earlier merge of this plan");
	check_unchanged("plain", "results.json", before);
	free(before);
}

/* A partial set merges, names what is missing and invents nothing. */
static void test_partial(void)
{
	CHECK_INT(run(ARGS("merge", path_in("m/parts/0"), "--out", path_in("m"))), 1);
	CHECK_CONTAINS(err_text, "merged 1 of the plan's 2 runs");
	CHECK_CONTAINS(err_text, "missing: run 1 (soup, sah_tasks, 2 threads)");
	cJSON *doc = load_results(path_in("m"));
	const cJSON *runs = cJSON_GetObjectItem(doc, "runs");
	CHECK_INT(cJSON_GetArraySize(runs), 1);
	CHECK(num(cJSON_GetArrayItem(runs, 0), "id", NULL) == 0);
	cJSON_Delete(doc);
	CHECK_INT(run(ARGS("plan", "--missing", path_in("m"))), 0);
	CHECK_INT(count_lines(out_text), 1);
	CHECK_CONTAINS(out_text, "--only 1 --out ");
}

/* Runs from two machines: merge says so and the reports list both. */
static void test_two_machines(void)
{
	CHECK_INT(run_part("m", "1", "m/parts/1"), 0);
	cJSON *doc = load_results(path_in("m/parts/1"));
	cJSON *machine = cJSON_GetObjectItem(doc, "machine");
	cJSON_ReplaceItemInObject(machine, "hostname", cJSON_CreateString("elsewhere"));
	char *text = cJSON_Print(doc);
	write_config("m/parts/1/results.json", text);
	free(text);
	cJSON_Delete(doc);
	CHECK_INT(run(ARGS("merge", path_in("m/parts/0"), path_in("m/parts/1"), "--out",
	                   path_in("m"))), 0);
	CHECK_CONTAINS(err_text, "measured on 2 different machines");
	char *md = read_file(path_in("m"), "report.md"), *html = read_file(path_in("m"), "report.html");
	CHECK_CONTAINS(md, "## Machines");
	CHECK_CONTAINS(md, "| M2 | elsewhere |");
	CHECK_CONTAINS(html, "<td>elsewhere</td>");
	free(md);
	free(html);
	doc = load_results(path_in("m"));
	const cJSON *r1 = cJSON_GetArrayItem(cJSON_GetObjectItem(doc, "runs"), 1);
	CHECK(!strcmp(run_str(cJSON_GetObjectItem(r1, "machine"), "hostname"), "elsewhere"));
	cJSON_Delete(doc);
}

/* A failed run is merged as it was recorded, and named. */
static void test_failed_run(void)
{
	const char *cfg = write_config("fail.json",
		"{ \"repeat\": 1, \"scenes\": [ { \"generator\": \"soup\", \"count\": 50 } ],\n"
		"  \"builders\": [ { \"plugin\": \"fake_good\" },\n"
		"    { \"plugin\": \"fake_good\", \"name\": \"err\", \"options\": { \"fail\": \"error\" } } ] }\n");
	CHECK_INT(run(ARGS("plan", cfg, "--out", path_in("f"))), 0);
	CHECK_INT(run_part("f", "0", "f/parts/0"), 0);
	CHECK_INT(run_part("f", "1", "f/parts/1"), 1);
	CHECK_INT(run(ARGS("merge", path_in("f/parts/0"), path_in("f/parts/1"), "--out",
	                   path_in("f"))), 1);
	CHECK_CONTAINS(err_text, "merged 2 of the plan's 2 runs");
	CHECK_CONTAINS(err_text, "not ok: run 1 (soup, err, 1 threads)");
	cJSON *merged = load_results(path_in("f")), *part = load_results(path_in("f/parts/1"));
	const cJSON *a = cJSON_GetArrayItem(cJSON_GetObjectItem(merged, "runs"), 1);
	const cJSON *b = cJSON_GetArrayItem(cJSON_GetObjectItem(part, "runs"), 0);
	CHECK(!strcmp(run_str(a, "status"), "failed"));
	CHECK(*run_str(a, "error") && !strcmp(run_str(a, "error"), run_str(b, "error")));
	cJSON_Delete(merged);
	cJSON_Delete(part);
}

static void test_usage(void)
{
	CHECK_INT(run(ARGS("plan", "--help")), 0);
	CHECK_CONTAINS(out_text, "--missing DIR");
	CHECK_INT(run(ARGS("merge", "--help")), 0);
	CHECK_CONTAINS(out_text, "PART... --out DIR");
	CHECK_INT(run(ARGS("plan", path_in("small.json"))), 2);
	CHECK_CONTAINS(err_text, "expected CONFIG.json --out DIR");
	CHECK_INT(run(ARGS("plan", path_in("small.json"), "--out", path_in("f"), "--format", "xml")), 2);
	CHECK_CONTAINS(err_text, "--format must be lines, slurm or json, not 'xml'");
	CHECK_INT(run(ARGS("merge", path_in("m/parts/0"), "--out", path_in("nowhere"))), 2);
	CHECK_CONTAINS(err_text, "nowhere/plan.json");
}

/* The slurm format: one array task per run, exclusive nodes. */
static void test_slurm_file(void)
{
	CHECK_INT(run(ARGS("plan", path_in("merge.json"), "--out", path_in("m"), "--format", "slurm",
	                   "--jobs", "3")), 0);
	char *sb = read_file(path_in("m"), "sweep.sbatch");
	CHECK_CONTAINS(sb, "#SBATCH --array=0-1%3\n");
	CHECK_CONTAINS(sb, "#SBATCH --exclusive\n");
	CHECK_CONTAINS(sb, "#SBATCH --cpus-per-task=2\n");
	CHECK_CONTAINS(sb, " --only \"$SLURM_ARRAY_TASK_ID\" --out ");
	free(sb);
	/* json: the plan's runs with their commands. */
	CHECK_INT(run(ARGS("plan", path_in("merge.json"), "--out", path_in("m"), "--format", "json")),
	          0);
	cJSON *runs = cJSON_Parse(out_text);
	CHECK_INT(cJSON_GetArraySize(runs), 2);
	const cJSON *second = cJSON_GetArrayItem(runs, 1);
	CHECK(num(second, "id", NULL) == 1 && num(second, "threads_configured", NULL) == 2);
	CHECK(!strcmp(run_str(second, "builder"), "sah_tasks"));
	CHECK_CONTAINS(run_str(second, "command"), "/m/plan.json --only 1 --out ");
	cJSON_Delete(runs);
}

static void test_errors(void)
{
	test_changed_config();
	test_bad_only();
	test_bad_parts();
	test_partial();
	test_two_machines();
	test_failed_run();
	test_usage();
	test_slurm_file();
}

static bool have_parallel(void)
{
	return system("parallel --version >/dev/null 2>&1") == 0;
}

/*
 * Ten runs through GNU parallel with two jobs, stopped after six have
 * finished (--halt now,done=6 kills the rest), then completed from
 * `plan --missing`; the merge equals one `bvhlab run` of the config.
 */
static void test_parallel(void)
{
	const char *cfg = write_config("sweep.json", sweep_config);
	CHECK_INT(run(ARGS("plan", cfg, "--out", path_in("sweep"))), 0);
	CHECK_INT(count_lines(out_text), 10);
	CHECK_CONTAINS(out_text, "--only 9 --out ");
	/* A stopped parallel exits non-zero: that is the point here. */
	shell("'%s' plan sweep.json --out sweep | parallel --will-cite --jobs 2 "
	      "--halt now,done=6 >/dev/null 2>&1%s", exe, "");
	CHECK_INT(run(ARGS("plan", "--missing", path_in("sweep"))), 0);
	int missing = count_lines(out_text);
	CHECK(missing >= 2 && missing <= 4); /* at most two were running when it stopped */
	CHECK_INT(shell("'%s' merge sweep/parts/* --out sweep%s", exe, " 2>merge.err"), 1);
	char *err = read_file(tmpdir, "merge.err");
	CHECK_CONTAINS(err, "runs missing");
	free(err);
	cJSON *partial = load_results(path_in("sweep"));
	CHECK_INT(cJSON_GetArraySize(cJSON_GetObjectItem(partial, "runs")), 10 - missing);
	cJSON_Delete(partial);
	CHECK_INT(shell("'%s' plan --missing sweep | parallel --will-cite --jobs 2%s", exe,
	                " >/dev/null"), 0);
	CHECK_INT(run(ARGS("plan", "--missing", path_in("sweep"))), 0);
	CHECK_INT(count_lines(out_text), 0);
	CHECK_INT(shell("'%s' merge sweep/parts/* --out sweep%s", exe, ""), 0);
	/* The plan and one run share the run list: the serial sweep once per scene. */
	CHECK_INT(run(ARGS("run", "--quiet", cfg, "--out", path_in("single"))), 0);
	cJSON *merged = load_results(path_in("sweep")), *single = load_results(path_in("single"));
	check_same_runs(merged, single);
	char heat[400];
	snprintf(heat, sizeof(heat), "sweep/%.380s",
	         run_str(cJSON_GetArrayItem(cJSON_GetObjectItem(merged, "runs"), 0), "heat_image"));
	CHECK_CONTAINS(heat, "icosphere--sah_tasks_bins_4_");
	CHECK(exists(path_in(heat)));
	CHECK(exists(path_in("sweep/report.html")) && exists(path_in("sweep/results.csv")));
	cJSON_Delete(merged);
	cJSON_Delete(single);
}

/* ---- a serial builder in a plan ------------------------------------------------ */

/* sah_seq has no PARALLEL flag: once per scene, its 2 threads not applicable. */
static const char serial_config[] =
	"{ \"repeat\": 1, \"threads\": [1, 2], \"validate_rays\": 16,\n"
	"  \"rays\": { \"width\": 8, \"height\": 8, \"min_ms\": 1 },\n"
	"  \"scenes\": [ { \"generator\": \"soup\", \"count\": 200 },\n"
	"              { \"generator\": \"icosphere\", \"frequency\": 4 } ],\n"
	"  \"builders\": [ { \"plugin\": \"sah_seq\" }, { \"plugin\": \"sah_tasks\" } ] }\n";

/* "id scene builder threads" of every run, one per line, in order. */
static char *identities(const cJSON *doc)
{
	static char buf[4096];
	size_t used = 0;
	const cJSON *r;
	buf[0] = '\0';
	cJSON_ArrayForEach(r, cJSON_GetObjectItem(doc, "runs"))
		used += (size_t)snprintf(buf + used, sizeof(buf) - used, "%g %s %s %g %s\n",
		                         num(r, "id", NULL), run_str(r, "scene"), run_str(r, "builder"),
		                         num(r, "threads", NULL), run_str(r, "options_hash"));
	return buf;
}

/* Planned into parts, each part run, merged: the runs and not_applicable of
 * one `bvhlab run` of the same config, no more. */
static void test_serial(void)
{
	const char *cfg = write_config("serial.json", serial_config);
	CHECK_INT(run(ARGS("plan", cfg, "--out", path_in("ser"))), 0);
	int planned = count_lines(out_text);
	CHECK_INT(planned, 6); /* 2 scenes x (sah_seq once + sah_tasks at 1 and 2) */
	for (int id = 0; id < planned; id++) {
		char ids[16], part[64];
		snprintf(ids, sizeof(ids), "%d", id);
		snprintf(part, sizeof(part), "ser/parts/%d", id);
		CHECK_INT(run_part("ser", ids, part), 0);
	}
	CHECK_INT(shell("'%s' merge ser/parts/* --out ser%s", exe, " 2>/dev/null"), 0);
	CHECK_INT(run(ARGS("run", "--quiet", cfg, "--out", path_in("ser-single"))), 0);
	cJSON *merged = load_results(path_in("ser")), *single = load_results(path_in("ser-single"));
	char *want = strdup(identities(single));
	CHECK_INT(cJSON_GetArraySize(cJSON_GetObjectItem(single, "runs")), 6);
	CHECK(want && !strcmp(identities(merged), want));
	CHECK_CONTAINS(want, "0 soup sah_seq 1 ");
	CHECK(!strstr(want, "sah_seq 2 "));
	const cJSON *na = cJSON_GetObjectItem(single, "not_applicable");
	CHECK_INT(cJSON_GetArraySize(na), 1);
	char *a = cJSON_PrintUnformatted(na);
	char *b = cJSON_PrintUnformatted(cJSON_GetObjectItem(merged, "not_applicable"));
	CHECK(a && b && !strcmp(a, b));
	CHECK_CONTAINS(a, "\"builder\":\"sah_seq\",\"threads\":[2]");
	free(a);
	free(b);
	free(want);
	cJSON_Delete(merged);
	cJSON_Delete(single);
}

int main(int argc, char **argv)
{
	if (!cli_begin(argc, argv))
		return fprintf(stderr, "usage: test-cli-plan BVHLAB_EXE grid|errors|parallel|serial\n"),
		       2;
	const char *mode = argv[2];
	static char abs_exe[4096];
	/* The shell pipelines run in tmpdir: the command's path must not be relative. */
	if (realpath(exe, abs_exe))
		exe = abs_exe;
	if (!strcmp(mode, "grid")) {
		test_grid_runs();
		test_grid_range();
		test_grid_syntax();
	} else if (!strcmp(mode, "errors")) {
		test_errors();
	} else if (!strcmp(mode, "serial")) {
		test_serial();
	} else if (!strcmp(mode, "parallel")) {
		if (!have_parallel()) {
			printf("skipped: GNU parallel is not installed (scripts/setup.sh installs it)\n");
			cli_end();
			return TEST_SKIP;
		}
		test_parallel();
	}
	return cli_end();
}
