/*
 * Issue 29's cases, one mode per mechanism, each a meson test of its own
 * (cli-rel-MODE):
 *   probe     every plugin opened (builder, refine stage; run, plan, list)
 *             is tried in a forked probe first
 *   lock      one writer per output folder, the second told the holder's pid
 *   threads   0 resolved once: [0, N] with N the machine's count is a duplicate
 *   temps     new folders appear whole, leftovers are hidden and swept,
 *             out/, out/. and 250-byte names work
 *   identity  a run's options are part of its identity (resume, merge),
 *             --retry-failed, parts of other plans or scene data refused
 *   measure   a missing measurement says why; stale heat data is never drawn
 *   force     a kill during --force's move-aside loses nothing
 * Usage: test-cli-rel BVHLAB_EXE MODE
 */
#include <signal.h>
#include <stdint.h>
#include <sys/file.h>
#include <sys/stat.h>

#include "cliutil.h"

#define LOADCRASH_DIR BVHLAB_TEST_BUILDDIR "/fake/loadcrash"
static const cJSON *run_of(const cJSON *doc, const char *builder, int threads)
{
	const cJSON *r;
	cJSON_ArrayForEach(r, cJSON_GetObjectItem(doc, "runs"))
		if (!strcmp(run_str(r, "builder"), builder) &&
		    cJSON_GetObjectItem(r, "threads")->valueint == threads)
			return r;
	return NULL;
}

static void check_run(const cJSON *doc, const char *builder, int threads, const char *status,
                      const char *error)
{
	const cJSON *r = run_of(doc, builder, threads);
	if (!r) {
		fprintf(stderr, "no run %s / %d\n", builder, threads);
		test_failures++;
		return;
	}
	CHECK_CONTAINS(run_str(r, "status"), status);
	if (error)
		CHECK_CONTAINS(run_str(r, "error"), error);
}

/* `bvhlab plan --out out` on one scene of 100 triangles and `builders`
 * (a JSON list's items), written as `name`: must exit with `status`. */
static void plan_builders(const char *name, const char *builders, const char *out, int status)
{
	char text[1024];
	snprintf(text, sizeof(text),
	         "{ \"repeat\": 1, \"scenes\": [ { \"generator\": \"soup\", \"count\": 100 } ],\n"
	         "  \"builders\": [ %s ] }\n", builders);
	CHECK_INT(run_in(tmpdir, ARGS("plan", write_config(name, text), "--out", out)), status);
}

/* 1. Refine stages that crash or hang while loading cost their builder's
 * runs only; plan and list probe too, and plan checks stages' options. */
static void test_probe(void)
{
	char text[2048];
	plain_crashes();
	snprintf(text, sizeof(text),
	         "{ \"output\": \"out-probe\", \"repeat\": 1, \"timeout_s\": 5,\n"
	         "  \"scenes\": [ { \"generator\": \"soup\", \"count\": 100 } ],\n"
	         "  \"builders\": [\n"
	         "    { \"plugin\": \"fake_good\", \"name\": \"c\",\n"
	         "      \"refine\": [ { \"plugin\": \"%s/crash_ctor.so\" } ] },\n"
	         "    { \"plugin\": \"fake_good\", \"name\": \"h\", \"timeout_s\": 1,\n"
	         "      \"refine\": [ { \"plugin\": \"%s/hang_entry.so\" } ] },\n"
	         "    { \"plugin\": \"fake_good\", \"name\": \"good\" } ] }\n",
	         LOADCRASH_DIR, LOADCRASH_DIR);
	const char *cfg = write_config("probe.json", text);
	CHECK_INT(run_in(tmpdir, ARGS("run", "--quiet", cfg)), 1);
	cJSON *doc = load_results(cli_path_in("out-probe"));
	check_run(doc, "c", 1, "crashed", "refine stage 1: plugin");
	check_run(doc, "c", 1, "crashed", "died while loading");
	check_run(doc, "h", 1, "timeout", "hung while loading");
	check_run(doc, "good", 1, "ok", NULL);
	cJSON_Delete(doc);

	CHECK_INT(run_in(tmpdir, ARGS("plan", cfg, "--out", "plan-probe")), 2);
	CHECK_CONTAINS(err_text, "builder 'c': refine stage 1: plugin");
	CHECK_CONTAINS(err_text, "died while loading");
	CHECK(!cli_exists(cli_path_in("plan-probe/plan.json")));

	plan_builders("refopt.json",
	              "{ \"plugin\": \"fake_good\",\n"
	              "    \"refine\": [ { \"plugin\": \"reinsert\", \"options\": { \"nope\": 1 } } ] }",
	              "plan-opt", 2);
	CHECK_CONTAINS(err_text, "nope");
	plan_builders("optional.json",
	              "{ \"plugin\": \"fake_good\" },\n"
	              "    { \"plugin\": \"not_built_here\", \"optional\": true }",
	              "plan-optional", 0);
	CHECK_CONTAINS(err_text, "optional builder skipped");
	CHECK_CONTAINS(err_text, "builder 'not_built_here'");

	char crash[600];
	snprintf(crash, sizeof(crash), "%s/crash_ctor.so", LOADCRASH_DIR);
	CHECK_INT(run_in(tmpdir, ARGS("list", crash, "fake_good")), 1);
	CHECK_CONTAINS(out_text, "NOT USABLE");
	CHECK_CONTAINS(out_text, "died while loading");
	CHECK_CONTAINS(out_text, "fake_good");
}

/* Holds dir's lock as another bvhlab would, with `pid` written in it. */
static int hold_lock(const char *dir, const char *pid)
{
	char path[700];
	snprintf(path, sizeof(path), "%s/.bvhlab.lock", dir);
	int fd = open(path, O_RDWR | O_CREAT, 0644);
	CHECK(fd >= 0 && flock(fd, LOCK_EX | LOCK_NB) == 0);
	CHECK(write(fd, pid, strlen(pid)) == (ssize_t)strlen(pid));
	return fd;
}

/* Two runs: fake_good is not a parallel builder, so one run per scene each. */
static const char small[] =
	"{ \"output\": \"%s\", \"repeat\": 1, \"threads\": [1],\n"
	"  \"rays\": { \"width\": 8, \"height\": 8, \"diffuse\": 0, \"min_ms\": 1 },\n"
	"  \"scenes\": [ { \"generator\": \"soup\", \"count\": 100 } ],\n"
	"  \"builders\": [ { \"plugin\": \"fake_good\", \"name\": \"a\" },\n"
	"                  { \"plugin\": \"fake_good\", \"name\": \"b\" } ] }\n";

/* `small` with output folder `out`, written as `name`: its path; the
 * output folder's path into dir. */
static const char *write_small(const char *name, const char *out, char dir[static 600])
{
	char text[1024];
	snprintf(text, sizeof(text), small, out);
	snprintf(dir, 600, "%s", cli_path_in(out));
	return write_config(name, text);
}

/* 2. A second writer is refused, naming the first, and nothing is lost. */
static void test_lock(void)
{
	char dir[600];
	const char *cfg = write_small("lock.json", "out-lock", dir);
	CHECK_INT(run_in(tmpdir, ARGS("run", "--quiet", "--only", "0", cfg)), 0);
	char *before = read_file(dir, "results.json");
	int fd = hold_lock(dir, "4242\n");
	CHECK_INT(run_in(tmpdir, ARGS("run", "--quiet", "--resume", cfg)), 2);
	CHECK_CONTAINS(err_text, "out-lock is in use by another bvhlab (pid 4242)");
	CHECK_INT(run_in(tmpdir, ARGS("run", "--quiet", "--force", cfg)), 2);
	CHECK_CONTAINS(err_text, "pid 4242");
	char *after = read_file(dir, "results.json");
	CHECK(before && after && !strcmp(before, after));
	CHECK(!cli_exists(cli_path_in("out-lock/results.json.1")));
	close(fd);
	CHECK_INT(run(ARGS("run", "--quiet", "--resume", cfg)), 0);
	cJSON *doc = load_results(dir);
	CHECK_INT(count_runs(doc, "a", "ok") + count_runs(doc, "b", "ok"), 2);
	cJSON_Delete(doc);
	free(before);
	free(after);
}

/* 3, 13. Thread counts are checked after 0 is resolved. */
static void test_threads(void)
{
	char text[1024], list[32];
	long cores = sysconf(_SC_NPROCESSORS_ONLN);
	snprintf(text, sizeof(text),
	         "{ \"output\": \"out-thr\", \"repeat\": 1, \"threads\": [0, %ld],\n"
	         "  \"scenes\": [ { \"generator\": \"soup\", \"count\": 100 } ],\n"
	         "  \"builders\": [ { \"plugin\": \"fake_good\" } ] }\n", cores);
	const char *cfg = write_config("thr.json", text);
	CHECK_INT(run_in(tmpdir, ARGS("run", "--quiet", cfg)), 2);
	CHECK_CONTAINS(err_text, "duplicate thread count");
	CHECK(!cli_exists(cli_path_in("out-thr")));
	CHECK_INT(run_in(tmpdir, ARGS("plan", cfg, "--out", "plan-thr")), 2);
	CHECK_CONTAINS(err_text, "duplicate thread count");
	snprintf(list, sizeof(list), "%ld,0", cores);
	snprintf(text, sizeof(text), small, "out-thr2");
	const char *ok = write_config("thr2.json", text);
	CHECK_INT(run_in(tmpdir, ARGS("run", "--quiet", "--threads", list, ok)), 2);
	CHECK_CONTAINS(err_text, "duplicate thread count");
	CHECK_INT(run_in(tmpdir, ARGS("run", "--quiet", "--threads", "2,2", ok)), 2);
	CHECK_CONTAINS(err_text, "--threads: duplicate thread count 2");
	CHECK(!strstr(err_text, "out of memory"));
}

/* 4, 12. New folders appear whole; what a killed start leaves is hidden and swept. */
static void test_temps(void)
{
	char text[1024], name[300];
	snprintf(text, sizeof(text), small, "parts/6");
	const char *cfg = write_config("tmp.json", text);
	/* What a sweep killed while making parts/7 leaves: a hidden folder
	 * holding a complete results.json, its lock free. */
	char leftover[700];
	snprintf(leftover, sizeof(leftover), "mkdir -p '%s/parts/.bvhlab-new-abc123' && "
	         "echo '{\"runs\": []}' > '%s/parts/.bvhlab-new-abc123/results.json' && "
	         "touch '%s/parts/.bvhlab-new-abc123/.bvhlab.lock'", tmpdir, tmpdir, tmpdir);
	CHECK_INT(system(leftover), 0);
	CHECK_INT(run_in(tmpdir, ARGS("run", "--quiet", cfg)), 0);
	CHECK(cli_exists(cli_path_in("parts/6/results.json")));
	CHECK(!cli_exists(cli_path_in("parts/.bvhlab-new-abc123")));

	CHECK_INT(run_in(tmpdir, ARGS("run", "--quiet", "--out", "trail/", cfg)), 0);
	CHECK(cli_exists(cli_path_in("trail/results.json")));
	CHECK_INT(run_in(tmpdir, ARGS("run", "--quiet", "--out", "dot/.", cfg)), 0);
	CHECK(cli_exists(cli_path_in("dot/results.json")));
	memset(name, 'x', 250);
	name[250] = '\0';
	CHECK_INT(run_in(tmpdir, ARGS("run", "--quiet", "--out", name, cfg)), 0);
	CHECK_INT(runs_written(cli_path_in(name)), 2);
}

/* Two runs, ids 0 (tri) and 1 (soup), of one builder. */
static const char alpha_config[] =
	"{ \"output\": \"out-id\", \"repeat\": 1,\n"
	"  \"rays\": { \"width\": 8, \"height\": 8, \"diffuse\": 0, \"min_ms\": 1 },\n"
	"  \"scenes\": [ { \"path\": \"tri.obj\" },\n"
	"              { \"generator\": \"soup\", \"count\": 10 } ],\n"
	"  \"builders\": [ { \"plugin\": \"fake_good\", \"options\": { \"alpha\": %d } } ] }\n";

static void write_mesh(const char *text)
{
	FILE *f = fopen(cli_path_in("tri.obj"), "w");
	fputs(text, f);
	fclose(f);
}

static const char *alpha(int value)
{
	char text[1024], name[32];
	snprintf(text, sizeof(text), alpha_config, value);
	snprintf(name, sizeof(name), "id-%d.json", value);
	return write_config(name, text);
}

static int alpha_of(const cJSON *run)
{
	return cJSON_GetObjectItem(cJSON_GetObjectItem(run, "options"), "alpha")->valueint;
}

/* Resumed runs made with other options, or on a scene file that appeared
 * since, run again; --retry-failed reruns failures. */
static void identity_resume(void)
{
	char dir[600];
	snprintf(dir, sizeof(dir), "%s", cli_path_in("out-id"));
	write_mesh("v 0 0 0\n"); /* no face yet: its run fails */
	CHECK_INT(run_in(tmpdir, ARGS("run", "--quiet", alpha(2))), 1);
	CHECK_INT(run_in(tmpdir, ARGS("run", "--resume", alpha(2))), 1);
	CHECK_CONTAINS(err_text, "2 finished runs kept");
	CHECK_INT(run_in(tmpdir, ARGS("run", "--resume", "--retry-failed", alpha(2))), 1);
	CHECK_CONTAINS(err_text, "--retry-failed: 1 run that did not end ok will run again");
	write_mesh("v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 3\n");
	CHECK_INT(run_in(tmpdir, ARGS("run", "--resume", alpha(2))), 0);
	CHECK_CONTAINS(err_text, "1 finished run kept");
	CHECK_CONTAINS(err_text, "1 run rerun: scene 'tri' changed");
	CHECK_INT(run_in(tmpdir, ARGS("run", "--resume", alpha(3))), 0);
	CHECK_CONTAINS(err_text, "2 runs rerun: builder 'fake_good' changed");
	cJSON *doc = load_results(dir);
	CHECK_INT(count_runs(doc, "fake_good", "ok"), 2);
	const cJSON *r;
	cJSON_ArrayForEach(r, cJSON_GetObjectItem(doc, "runs")) {
		CHECK_INT(alpha_of(r), 3);
		CHECK(strlen(run_str(r, "options_hash")) == 16);
	}
	cJSON_Delete(doc);
}

/* Parts: of another plan (other options), on other scene data, or
 * disagreeing on options are refused. */
static void identity_parts(void)
{
	CHECK_INT(run_in(tmpdir, ARGS("plan", alpha(2), "--out", "pa")), 0);
	CHECK_INT(run_in(tmpdir, ARGS("plan", alpha(5), "--out", "pb")), 0);
	CHECK_INT(run_in(tmpdir, ARGS("run", cli_path_in("pa/plan.json"), "--only", "0", "--out",
	                              cli_path_in("pa/parts/0"), "--quiet")), 0);
	CHECK_INT(run_in(tmpdir, ARGS("run", cli_path_in("pa/plan.json"), "--only", "1", "--out",
	                              cli_path_in("pa/parts/1"), "--quiet")), 0);
	char cmd[1400];
	snprintf(cmd, sizeof(cmd), "cp -r '%s/pa/parts' '%s/pb/'", tmpdir, tmpdir);
	CHECK_INT(system(cmd), 0);
	CHECK_INT(run_in(tmpdir, ARGS("run", cli_path_in("pb/plan.json"), "--only", "0", "--out",
	                              cli_path_in("pb/parts/0"), "--resume", "--quiet")), 2);
	CHECK_CONTAINS(err_text, "its runs were made from plan");
	CHECK_INT(run_in(tmpdir, ARGS("merge", cli_path_in("pb/parts/0"), "--out", cli_path_in("pb"))), 2);
	CHECK_CONTAINS(err_text, "comes from another plan");

	/* A part whose options_hash differs from another part's run of its builder. */
	snprintf(cmd, sizeof(cmd), "sed -i 's/\"options_hash\":[[:space:]]*\"[0-9a-f]*\"/\"options_hash\": "
	         "\"00000000deadbeef\"/' '%s/pa/parts/1/results.json'", tmpdir);
	CHECK_INT(system(cmd), 0);
	CHECK_INT(run_in(tmpdir, ARGS("merge", cli_path_in("pa/parts/0"), cli_path_in("pa/parts/1"),
	                              "--out", cli_path_in("pa"))), 2);
	CHECK_CONTAINS(err_text, "were made with other options");

	/* The mesh regenerated after planning: its runs are refused. */
	write_mesh("v 0 0 0\nv 2 0 0\nv 0 2 0\nf 1 2 3\n");
	CHECK_INT(run_in(tmpdir, ARGS("run", cli_path_in("pb/plan.json"), "--only", "1", "--out",
	                              cli_path_in("pb/parts/9"), "--quiet")), 2);
	CHECK_CONTAINS(err_text, "tri.obj has changed since planning");
	CHECK(!cli_exists(cli_path_in("pb/parts/9")));
}

static void test_identity(void)
{
	identity_resume();
	identity_parts();
}

#define SHIM BVHLAB_TEST_BUILDDIR "/fake/shim/rename_fault.so"

/* bvhlab killed just before its nth rename (or link) onto a name ending in
 * `to` (rename_fault.so): its exit status. */
static int killed_at(const char *to, const char *n, const char *const *args)
{
	setenv("BVHLAB_FAULT_RENAME", n, 1);
	setenv("BVHLAB_FAULT_TO", to, 1);
	setenv("LD_PRELOAD", SHIM, 1);
	/* ASan wants to come first in the library list; the shim is harmless. */
	const char *asan = getenv("ASAN_OPTIONS");
	char *saved = asan ? strdup(asan) : NULL, opts[512];
	snprintf(opts, sizeof(opts), "%s%sverify_asan_link_order=0", asan ? asan : "",
	         asan && *asan ? ":" : "");
	setenv("ASAN_OPTIONS", opts, 1);
	int status = run_in(tmpdir, args);
	unsetenv("LD_PRELOAD");
	unsetenv("BVHLAB_FAULT_RENAME");
	unsetenv("BVHLAB_FAULT_TO");
	if (saved)
		setenv("ASAN_OPTIONS", saved, 1);
	else
		unsetenv("ASAN_OPTIONS");
	free(saved);
	return status;
}

static const cJSON *rays_of(const cJSON *run)
{
	return cJSON_GetObjectItem(run, "rays");
}

/* 7. Tracing that fails says so, in the run and the last line. */
static void measure_rays_error(void)
{
	const char *cfg = write_config("cam.json",
		"{ \"output\": \"out-cam\", \"repeat\": 1,\n"
		"  \"rays\": { \"width\": 8, \"height\": 8, \"diffuse\": 0, \"min_ms\": 1,\n"
		"            \"camera\": { \"position\": [1e20, 1e20, 1e20], \"target\": [0, 0, 0] } },\n"
		"  \"scenes\": [ { \"generator\": \"soup\", \"count\": 100 } ],\n"
		"  \"builders\": [ { \"plugin\": \"fake_good\" } ] }\n");
	CHECK_INT(run_in(tmpdir, ARGS("run", cfg)), 0);
	CHECK_CONTAINS(err_text, "1 run traced no rays (see their rays.error)");
	cJSON *doc = load_results(cli_path_in("out-cam"));
	check_run(doc, "fake_good", 1, "ok", NULL);
	CHECK(run_str(rays_of(run_of(doc, "fake_good", 1)), "error")[0] != '\0');
	cJSON_Delete(doc);
}

/* 8. Killed in the rounds: the resumed sweep times those runs again, draws
 * the images and leaves no raw data behind. */
static void measure_rounds(void)
{
	char dir[600];
	snprintf(dir, sizeof(dir), "%s", cli_path_in("out-rounds"));
	const char *cfg = write_config("rounds.json",
		"{ \"output\": \"out-rounds\", \"repeat\": 1, \"images\": true,\n"
		"  \"rays\": { \"width\": 8, \"height\": 8, \"diffuse\": 0, \"min_ms\": 2, \"rounds\": 2 },\n"
		"  \"scenes\": [ { \"generator\": \"soup\", \"count\": 100 } ],\n"
		"  \"builders\": [ { \"plugin\": \"fake_good\", \"name\": \"a\" },\n"
		"                  { \"plugin\": \"fake_good\", \"name\": \"b\" } ] }\n");
	/* Renames of results.json: 1 the empty document, 2 and 3 the runs, 4 the rounds. */
	CHECK_INT(killed_at("/results.json", "4", ARGS("run", "--quiet", cfg)), 128 + SIGKILL);
	cJSON *doc = load_results(dir);
	const cJSON *r = run_of(doc, "b", 1);
	CHECK(r && cJSON_IsTrue(cJSON_GetObjectItem(rays_of(r), "provisional")));
	cJSON_Delete(doc);
	CHECK(cli_exists(cli_path_in("out-rounds/.heat-0-0.raw")));
	CHECK_INT(run_in(tmpdir, ARGS("run", "--resume", cfg)), 0);
	CHECK_CONTAINS(err_text, "2 resumed runs with provisional ray timings");
	doc = load_results(dir);
	cJSON_ArrayForEach(r, cJSON_GetObjectItem(doc, "runs")) {
		CHECK_INT(cJSON_GetObjectItem(rays_of(r), "rounds")->valueint, 2);
		CHECK(!cJSON_GetObjectItem(rays_of(r), "provisional"));
	}
	CHECK(run_str(run_of(doc, "a", 1), "heat_image")[0] != '\0');
	cJSON_Delete(doc);
	CHECK(!cli_exists(cli_path_in("out-rounds/.heat-0-0.raw")));
	CHECK(!cli_exists(cli_path_in("out-rounds/.shade-0-0.raw")));
}

/* 9. Heat data an earlier sweep left is not drawn for a run that timed out. */
static void measure_stale_heat(void)
{
	uint32_t stale[64];
	for (int k = 0; k < 64; k++)
		stale[k] = 999;
	CHECK_INT(mkdir(cli_path_in("out-stale"), 0755), 0);
	FILE *f = fopen(cli_path_in("out-stale/.heat-0-0.raw"), "wb");
	CHECK(f && fwrite(stale, sizeof(stale), 1, f) == 1);
	fclose(f);
	const char *cfg = write_config("stale.json",
		"{ \"output\": \"out-stale\", \"repeat\": 1, \"images\": true,\n"
		"  \"rays\": { \"width\": 8, \"height\": 8, \"diffuse\": 0, \"min_ms\": 1 },\n"
		"  \"scenes\": [ { \"name\": \"s\", \"generator\": \"soup\", \"count\": 100 } ],\n"
		"  \"builders\": [ { \"plugin\": \"fake_good\", \"name\": \"slow\", \"timeout_s\": 1,\n"
		"                    \"options\": { \"fail\": \"loop\" } },\n"
		"                  { \"plugin\": \"fake_good\" } ] }\n");
	CHECK_INT(run_in(tmpdir, ARGS("run", "--quiet", cfg)), 1);
	cJSON *doc = load_results(cli_path_in("out-stale"));
	check_run(doc, "slow", 1, "timeout", NULL);
	CHECK(!cJSON_GetObjectItem(run_of(doc, "slow", 1), "heat_image"));
	const cJSON *images = cJSON_GetObjectItem(cJSON_GetArrayItem(cJSON_GetObjectItem(doc,
	                                          "scenes"), 0), "images");
	const cJSON *hi = cJSON_GetObjectItem(images, "heat_max");
	CHECK(cJSON_IsNumber(hi) && hi->valuedouble < 999);
	cJSON_Delete(doc);
}

static void test_measure(void)
{
	plain_crashes();
	measure_rays_error();
	measure_rounds();
	measure_stale_heat();
}

/* 10. Killed while --force moves the old results aside: nothing new is
 * written over them, and the next --force finishes the move. */
static void test_force(void)
{
	char dir[600];
	const char *cfg = write_small("force.json", "out-force", dir);
	CHECK_INT(run_in(tmpdir, ARGS("run", "--quiet", cfg)), 0);
	char *json = read_file(dir, "results.json"), *csv = read_file(dir, "results.csv");
	CHECK_INT(killed_at("/report.md.1", "1", ARGS("run", "--quiet", "--force", cfg)),
	          128 + SIGKILL);
	CHECK(cli_exists(cli_path_in("out-force/results.csv.1")));
	CHECK(!cli_exists(cli_path_in("out-force/results.json.1")));
	CHECK_INT(run_in(tmpdir, ARGS("run", "--quiet", cfg)), 2);
	CHECK_CONTAINS(err_text, "already holds a results.json");
	CHECK_INT(run_in(tmpdir, ARGS("run", "--quiet", "--force", cfg)), 0);
	char *json1 = read_file(dir, "results.json.1"), *csv1 = read_file(dir, "results.csv.1");
	CHECK(json && json1 && !strcmp(json, json1));
	CHECK(csv && csv1 && !strcmp(csv, csv1));
	CHECK(cli_exists(cli_path_in("out-force/report.md.1")));
	CHECK(!cli_exists(cli_path_in("out-force/results.csv.2")));
	CHECK_INT(runs_written(dir), 2);
	free(json);
	free(csv);
	free(json1);
	free(csv1);
}

static int shell(const char *fmt, const char *arg)
{
	char cmd[1600], line[1400];
	snprintf(line, sizeof(line), fmt, arg);
	snprintf(cmd, sizeof(cmd), "cd '%s' && %s", tmpdir, line);
	return system(cmd);
}

/* 11, 17. Merge: heat scales of parts are not stated as one; links in a
 * part's images/ are not followed. */
static void misc_merge(void)
{
	cli_plan_ab("heat.json",
	            "\"images\": true,\n"
	            "  \"rays\": { \"width\": 8, \"height\": 8, \"diffuse\": 0, \"min_ms\": 1 },",
	            "ph");
	CHECK_INT(cli_run_part("ph", 0), 0);
	CHECK_INT(cli_run_part("ph", 1), 0);
	CHECK_INT(shell("sed -i 's/\"heat_max\":[[:space:]]*[0-9.]*/\"heat_max\": 77/' "
	                "ph/parts/1/results.json%s", ""), 0);
	CHECK_INT(shell("echo secret > secret.txt && ln -s '%s/secret.txt' ph/parts/1/images/"
	                "s--stolen.png", tmpdir), 0);
	CHECK_INT(run_in(tmpdir, ARGS("merge", cli_path_in("ph/parts/0"), cli_path_in("ph/parts/1"),
	                              "--out", cli_path_in("ph"))), 0);
	CHECK(!cli_exists(cli_path_in("ph/images/s--stolen.png")));
	cJSON *doc = load_results(cli_path_in("ph"));
	const cJSON *images = cJSON_GetObjectItem(cJSON_GetArrayItem(cJSON_GetObjectItem(doc,
	                                          "scenes"), 0), "images");
	CHECK(!cJSON_GetObjectItem(images, "heat_max"));
	CHECK(cJSON_IsTrue(cJSON_GetObjectItem(images, "heat_scales_differ")));
	const cJSON *scale = cJSON_GetObjectItem(run_of(doc, "b", 1), "heat_scale");
	CHECK(cJSON_IsNumber(cJSON_GetObjectItem(scale, "max")) &&
	      cJSON_GetObjectItem(scale, "max")->valuedouble == 77);
	cJSON_Delete(doc);
	char *md = read_file(cli_path_in("ph"), "report.md");
	CHECK(md && !strstr(md, "nan"));
	free(md);
}

/* 15. A full disk: the runs not saved are counted as such, not as failed. */
static void misc_full(void)
{
	const char *cfg = write_config("full.json",
		"{ \"output\": \"out-full\", \"repeat\": 1,\n"
		"  \"rays\": { \"width\": 8, \"height\": 8, \"diffuse\": 0, \"min_ms\": 1 },\n"
		"  \"scenes\": [ { \"generator\": \"soup\", \"count\": 10 } ],\n"
		"  \"builders\": [ { \"plugin\": \"fake_good\", \"name\": \"a\" },\n"
		"    { \"plugin\": \"fake_good\", \"name\": \"b\" },\n"
		"    { \"plugin\": \"fake_good\", \"name\": \"c\" } ] }\n");
	setenv("BVHLAB_FAULT_FULL", "1", 1);
	/* Renames: 1 the empty document, 2 the first run; the disk is full from 3. */
	CHECK_INT(killed_at("/results.json", "3", ARGS("run", cfg)), 1);
	unsetenv("BVHLAB_FAULT_FULL");
	CHECK_CONTAINS(err_text, "2 finished runs could not be saved");
	CHECK(!strstr(err_text, "some runs failed or were invalid"));
	CHECK_INT(runs_written(cli_path_in("out-full")), 1);
}

/* 17. JSON nested past the reader's limit, names that are not UTF-8. */
static void misc_input(void)
{
	static char deep[2 * 1200 + 2];
	memset(deep, '[', 1200);
	memset(deep + 1200, ']', 1200);
	CHECK_INT(run_in(tmpdir, ARGS("run", write_config("deep.json", deep))), 2);
	CHECK_CONTAINS(err_text, "JSON nested deeper than 1000 levels");
	const char *cfg = write_config("latin1.json",
		"{ \"output\": \"out-latin1\", \"repeat\": 1,\n"
		"  \"scenes\": [ { \"name\": \"caf\xe9\", \"generator\": \"soup\", \"count\": 10 } ],\n"
		"  \"builders\": [ { \"plugin\": \"fake_good\" } ] }\n");
	CHECK_INT(run_in(tmpdir, ARGS("run", "--quiet", cfg)), 2);
	CHECK_CONTAINS(err_text, "its scene name is not valid UTF-8");
	CHECK(!cli_exists(cli_path_in("out-latin1")));
}

/* 14, 16. A plan folder with a newline; report over another sweep's folder. */
static void test_misc(void)
{
	char text[1024];
	misc_merge();
	misc_full();
	misc_input();
	snprintf(text, sizeof(text), small, "out-m1");
	const char *a = write_config("m1.json", text);
	CHECK_INT(run_in(tmpdir, ARGS("plan", a, "--out", "bad\nname")), 2);
	CHECK_CONTAINS(err_text, "control character");
	CHECK(!cli_exists(cli_path_in("bad\nname")));
	CHECK_INT(run_in(tmpdir, ARGS("run", "--quiet", a)), 0);
	snprintf(text, sizeof(text), small, "out-m2");
	CHECK_INT(run_in(tmpdir, ARGS("run", "--quiet", write_config("m2.json", text))), 0);
	char *before = read_file(cli_path_in("out-m2"), "report.md");
	CHECK_INT(run_in(tmpdir, ARGS("report", cli_path_in("out-m1/results.json"), "--out",
	                              cli_path_in("out-m2"))), 2);
	CHECK_CONTAINS(err_text, "holds the results.json of another sweep");
	char *after = read_file(cli_path_in("out-m2"), "report.md");
	CHECK(before && after && !strcmp(before, after));
	CHECK_INT(run_in(tmpdir, ARGS("report", cli_path_in("out-m1/results.json"))), 0);
	free(before);
	free(after);
}

int main(int argc, char **argv)
{
	static const struct cli_mode modes[] = {
		{"probe", test_probe},     {"lock", test_lock}, {"threads", test_threads},
		{"temps", test_temps},     {"identity", test_identity}, {"measure", test_measure},
		{"force", test_force},     {"misc", test_misc},
	};
	return cli_main_modes(argc, argv, "test-cli-rel", modes, sizeof(modes) / sizeof(modes[0]));
}
