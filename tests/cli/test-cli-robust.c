/*
 * The bvhlab command when things go wrong: plugins that crash, hang, exit
 * or return broken trees, a sweep killed mid-way and resumed, bad input.
 * Usage: test-cli-robust BVHLAB_EXE all
 */
#include <stdbool.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>
#include <unistd.h>

#include <cJSON.h>

#include "cliutil.h"

static bool run_valid(const cJSON *run)
{
	return run && !strcmp(run_str(run, "status"), "ok") &&
	       cJSON_IsTrue(cJSON_GetObjectItem(cJSON_GetObjectItem(run, "validation"), "valid"));
}

/*
 * Sanitizer builds would turn a plugin's segfault into their own report
 * and check the crashed children for leaks; here the signal is the point.
 */
static void crashes_unreported(void)
{
	append_option("ASAN_OPTIONS", "handle_segv=0:detect_leaks=0:allocator_may_return_null=1");
	append_option("TSAN_OPTIONS", "handle_segv=0");
}

static const char misbehaving_config[] =
	"{ \"output\": \"out-mis\", \"repeat\": 2, \"threads\": [1, 2],\n"
	"  \"rays\": { \"min_ms\": 1, \"width\": 64, \"height\": 64 },\n"
	"  \"scenes\": [ { \"generator\": \"soup\", \"count\": 300 } ],\n"
	"  \"builders\": [\n"
	"    { \"plugin\": \"fake_good\", \"name\": \"segv\", \"options\": { \"fail\": \"segfault\" } },\n"
	"    { \"plugin\": \"fake_good\", \"name\": \"abrt\", \"options\": { \"fail\": \"abort\" } },\n"
	"    { \"plugin\": \"fake_good\", \"name\": \"hang\", \"timeout_s\": 0.5,\n"
	"      \"options\": { \"fail\": \"loop\" } },\n"
	"    { \"plugin\": \"fake_good\", \"name\": \"quit\", \"options\": { \"fail\": \"exit\" } },\n"
	"    { \"plugin\": \"fake_good\", \"name\": \"bad\", \"options\": { \"fail\": \"invalid\" } },\n"
	"    { \"plugin\": \"fake_good\", \"name\": \"hog\", \"memory_limit_mb\": 256,\n"
	"      \"options\": { \"fail\": \"alloc\" } },\n"
	"    { \"plugin\": \"sah_seq\" },\n"
	"    { \"plugin\": \"fake_good\" } ] }\n";

/* Writes the config as `name`, runs it (every test here has a failing
 * run: exit status 1) and loads the results.json of its output `out`. */
static cJSON *run_failing(const char *name, const char *text, const char *out)
{
	char dir[512];

	CHECK_INT(run(ARGS("run", "--quiet", write_config(name, text))), 1);
	snprintf(dir, sizeof(dir), "%s/%s", tmpdir, out);
	return load_results(dir);
}

/* Every misbehaving plugin is reported as such; the others still run, valid.
 * (A plugin of another ABI is a config error: test-cli errors.) None of
 * these builders is PARALLEL: each runs once, at 1 thread of [1, 2]. */
static void test_misbehaving(void)
{
	cJSON *doc = run_failing("mis.json", misbehaving_config, "out-mis");
	if (!doc)
		return;
	CHECK_INT(cJSON_GetArraySize(cJSON_GetObjectItem(doc, "runs")), 8);
	static const char *const expect[][3] = {
		{"segv", "crashed", "killed by SIGSEGV"},
		{"abrt", "crashed", "killed by SIGABRT"},
		{"hang", "timeout", "no result after 0.5 s (timeout_s); killed"},
		{"quit", "crashed", "exited with status 3 before reporting"},
		{"bad", "invalid", "primitive 299 is referenced by no leaf"},
	};
	{ /* the 1-thread runs: the only ones */
		const int t = 1;
		for (size_t k = 0; k < sizeof(expect) / sizeof(expect[0]); k++) {
			const cJSON *r = find_run(doc, "soup", expect[k][0], t);
			CHECK(r && !strcmp(run_str(r, "status"), expect[k][1]));
			CHECK_CONTAINS(run_str(r, "error"), expect[k][2]);
		}
		/* Out of its memory limit: the plugin's allocation fails, or the child dies. */
		const cJSON *hog = find_run(doc, "soup", "hog", t);
		const char *status = hog ? run_str(hog, "status") : "";
		CHECK(!strcmp(status, "failed") || !strcmp(status, "crashed"));
		CHECK(!strstr(run_str(hog, "error"), "no memory limit"));
		CHECK(run_valid(find_run(doc, "soup", "sah_seq", t)));
		CHECK(run_valid(find_run(doc, "soup", "fake_good", t)));
	}
	const cJSON *bad = find_run(doc, "soup", "bad", 1);
	CHECK(bad && cJSON_IsFalse(cJSON_GetObjectItem(cJSON_GetObjectItem(bad, "validation"),
	                                               "valid")));
	cJSON_Delete(doc);
}

/* "isolate": false runs in this process, with the same statuses. */
static void test_in_process(void)
{
	cJSON *doc = run_failing("inproc.json",
		"{ \"output\": \"out-inproc\", \"repeat\": 1, \"isolate\": false,\n"
		"  \"rays\": { \"min_ms\": 1, \"width\": 64, \"height\": 64 },\n"
		"  \"scenes\": [ { \"generator\": \"soup\", \"count\": 100 } ],\n"
		"  \"builders\": [ { \"plugin\": \"fake_good\" },\n"
		"    { \"plugin\": \"fake_good\", \"name\": \"bad\", \"options\": { \"fail\": \"invalid\" } },\n"
		"    { \"plugin\": \"fake_good\", \"name\": \"err\",\n"
		"      \"options\": { \"fail\": \"error\" } } ] }\n", "out-inproc");
	if (!doc)
		return;
	CHECK(run_valid(find_run(doc, "soup", "fake_good", 1)));
	CHECK_INT(count_runs(doc, "bad", "invalid"), 1);
	CHECK_INT(count_runs(doc, "err", "failed"), 1);
	cJSON_Delete(doc);
}

/* "validate": false skips the rays against brute force, not the structure
 * check: a tree whose links are not a tree is still judged invalid, with
 * the node named, and gets no ray figures. */
static void test_unvalidated_dag(void)
{
	cJSON *doc = run_failing("dag.json",
		"{ \"output\": \"out-dag\", \"repeat\": 1, \"validate\": false,\n"
		"  \"rays\": { \"min_ms\": 1, \"width\": 16, \"height\": 16 },\n"
		"  \"scenes\": [ { \"generator\": \"soup\", \"count\": 100 } ],\n"
		"  \"builders\": [ { \"plugin\": \"fake_good\" },\n"
		"    { \"plugin\": \"fake_good\", \"name\": \"dag\", \"options\": { \"fail\": \"shared\" } } ] }\n",
		"out-dag");
	if (!doc)
		return;
	const cJSON *dag = find_run(doc, "soup", "dag", 1);
	CHECK(dag && !strcmp(run_str(dag, "status"), "invalid"));
	CHECK_CONTAINS(run_str(dag, "error"), "node 3 reachable twice");
	CHECK(dag && !cJSON_GetObjectItem(dag, "rays"));
	CHECK(run_valid(find_run(doc, "soup", "fake_good", 1)));
	cJSON_Delete(doc);
}

static bool same_run(const cJSON *a, const cJSON *b)
{
	return !strcmp(run_str(a, "scene"), run_str(b, "scene")) &&
	       !strcmp(run_str(a, "builder"), run_str(b, "builder")) &&
	       cJSON_GetObjectItem(a, "threads")->valueint ==
	               cJSON_GetObjectItem(b, "threads")->valueint;
}

static void check_no_duplicates(const cJSON *doc)
{
	const cJSON *a, *b;
	int dups = 0;
	cJSON_ArrayForEach(a, cJSON_GetObjectItem(doc, "runs"))
		for (b = a->next; b; b = b->next)
			dups += same_run(a, b);
	CHECK_INT(dups, 0);
}

/* Three scenes, the "gated" builder among three (struct kill_sweep). rounds
 * 1: a run is finished when it is recorded (with rounds its ray figures are
 * provisional until the scene's rounds, and a resumed sweep measures it
 * again: cli-rel-measure). */
static const char kill_config[] =
	"{ \"output\": \"out-kill\", \"repeat\": 3, \"threads\": [1, 2],\n"
	"  \"rays\": { \"min_ms\": 1, \"width\": 64, \"height\": 64, \"rounds\": 1 },\n"
	"  \"scenes\": [ { \"name\": \"a\", \"generator\": \"soup\", \"count\": 200 },\n"
	"    { \"name\": \"b\", \"generator\": \"icosphere\", \"frequency\": 4 },\n"
	"    { \"name\": \"c\", \"generator\": \"soup\", \"count\": 300, \"seed\": 5 } ],\n"
	"  \"builders\": [ { \"plugin\": \"fake_good\" },\n"
	"    { \"plugin\": \"fake_good\", \"name\": \"gated\",\n"
	"      \"options\": { \"wait_for\": \"%s\" } },\n"
	"    { \"plugin\": \"sah_seq\", \"threads\": [1] } ] }\n";

/*
 * A sweep killed mid-way keeps valid results with its finished runs, and
 * --resume completes it without running those again.
 */
static void test_kill_and_resume(void)
{
	struct kill_sweep k;
	CHECK(kill_sweep_start(&k, kill_config) >= 1);

	cJSON *doc = load_results(k.dir);
	if (!doc)
		return;
	int kept = cJSON_GetArraySize(cJSON_GetObjectItem(doc, "runs"));
	CHECK_INT(kept, 1); /* fake_good's run of scene a (not PARALLEL: at 1 thread only) */
	const cJSON *first = find_run(doc, "a", "fake_good", 1);
	CHECK(run_valid(first));
	char *samples = run_item_text(first, "build_ms");
	char *created = strdup(run_str(doc, "created"));
	cJSON_Delete(doc);

	CHECK_INT(kill_sweep_resume(&k), 0);
	CHECK_CONTAINS(err_text, "bvhlab: resuming");
	doc = load_results(k.dir);
	if (doc) {
		CHECK_INT(cJSON_GetArraySize(cJSON_GetObjectItem(doc, "runs")), 9);
		check_no_duplicates(doc);
		CHECK_INT(count_runs(doc, "gated", "ok"), 3);
		/* The finished run was kept, not run again. */
		first = find_run(doc, "a", "fake_good", 1);
		char *again = run_item_text(first, "build_ms");
		CHECK(samples && again && !strcmp(samples, again));
		CHECK(!strcmp(run_str(doc, "created"), created));
		CHECK_INT(cJSON_GetArraySize(cJSON_GetObjectItem(doc, "scenes")), 3);
		free(again);
		cJSON_Delete(doc);
	}
	free(samples);
	free(created);
	/* Nothing left to run: every run is kept. */
	CHECK_INT(run(ARGS("run", k.cfg, "--resume")), 0);
	CHECK_CONTAINS(err_text, "9 finished runs kept");
	CHECK_INT(runs_written(k.dir), 9);
}

static void test_resume_errors(void)
{
	const char *cfg = write_config("resume.json",
		"{ \"output\": \"out-resume\", \"repeat\": 1,\n"
		"  \"rays\": { \"min_ms\": 1, \"width\": 64, \"height\": 64 },\n"
		"  \"scenes\": [ { \"generator\": \"soup\", \"count\": 100 } ],\n"
		"  \"builders\": [ { \"plugin\": \"fake_good\" } ] }\n");
	char dir[512], path[600];
	snprintf(dir, sizeof(dir), "%s/out-resume", tmpdir);
	CHECK_INT(run(ARGS("run", cfg, "--resume")), 0); /* no results yet: a fresh start */
	CHECK_CONTAINS(err_text, "nothing to resume");
	CHECK_INT(runs_written(dir), 1);

	snprintf(path, sizeof(path), "%s/results.json", dir);
	FILE *f = fopen(path, "w");
	fputs("{ \"runs\": [ { \"scene\": \"soup\",", f);
	fclose(f);
	CHECK_INT(run(ARGS("run", cfg, "--resume")), 2);
	CHECK_CONTAINS(err_text, "cannot resume from");
	CHECK_CONTAINS(err_text, "out-resume/results.json: not a valid JSON object");
	f = fopen(path, "w");
	fputs("{ \"runs\": 3 }", f);
	fclose(f);
	CHECK_INT(run(ARGS("run", cfg, "--resume")), 2);
	CHECK_CONTAINS(err_text, "no \"runs\" array");
	/* Left alone for the user to look at. */
	char *text = read_file(dir, "results.json");
	CHECK(text && !strcmp(text, "{ \"runs\": 3 }"));
	free(text);
}

/* Bad input through the command: the message reaches the user. */
static void test_bad_input(void)
{
	const char *degen = write_config("degen.obj",
		"v 0 0 0\nv 1 0 0\nv 2 0 0\nv 0 1 0\nf 1 2 3\nf 1 1 4\nf 1 2 4\n");
	CHECK_INT(run(ARGS("info", degen)), 0);
	CHECK_CONTAINS(out_text, "triangles:  3");
	CHECK_CONTAINS(out_text, "degenerate: 2");
	CHECK_INT(run(ARGS("info", degen, "--json")), 0);
	CHECK_CONTAINS(out_text, "\"degenerate\":\t2");

	char folder[512];
	snprintf(folder, sizeof(folder), "%s/folder.ply", tmpdir);
	mkdir(folder, 0755);
	CHECK_INT(run(ARGS("info", folder)), 2);
	CHECK_CONTAINS(err_text, "folder.ply: not a regular file");
	CHECK_INT(run(ARGS("info", write_config("nan.obj", "v 0 0 0\nv nan 0 0\nv 0 1 0\nf 1 2 3\n"))),
	          2);
	CHECK_CONTAINS(err_text, "nan.obj:2: coordinate is NaN or infinite");
	CHECK_INT(run(ARGS("build", "fake_godo", "soup")), 2);
	CHECK_CONTAINS(err_text, "plugin 'fake_godo' not found");
	CHECK_CONTAINS(err_text, "(available: ");
	CHECK_CONTAINS(err_text, "fake_abi2, fake_badopt, fake_good, ");
	CHECK_INT(run(ARGS("run", write_config("types.json",
		"{ \"timeout_s\": \"soon\", \"scenes\": [ { \"generator\": \"soup\" } ],\n"
		"  \"builders\": [ { \"plugin\": \"fake_good\" } ] }\n"))), 2);
	CHECK_CONTAINS(err_text, "types.json:1:16: 'timeout_s' must be a number > 0, not a string");
	CHECK_INT(run(ARGS("build", "fake_good", "soup", "-o", "alpha=11")), 2);
	CHECK_CONTAINS(err_text, "alpha");
	CHECK_CONTAINS(err_text, "out of range");
}

int main(int argc, char **argv)
{
	if (!cli_begin(argc, argv))
		return 2;
	crashes_unreported();
	test_misbehaving();
	test_in_process();
	test_unvalidated_dag();
	test_kill_and_resume();
	test_resume_errors();
	test_bad_input();
	return cli_end();
}
