/*
 * The bvhlab command end to end: runs it as a user would and checks exit
 * statuses, messages and the files it writes.
 * Usage: test-cli BVHLAB_EXE basic|errors|shared
 */
#include <errno.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>
#include <unistd.h>

#include <cJSON.h>

#include "cliutil.h"

static const char *path_in(const char *name)
{
	static char buf[512];
	snprintf(buf, sizeof(buf), "%s/%s", tmpdir, name);
	return buf;
}

static bool exists(const char *path)
{
	struct stat st;
	return stat(path, &st) == 0;
}

static void test_help(void)
{
	CHECK_INT(run(ARGS("--help")), 0);
	CHECK_CONTAINS(out_text, "usage: bvhlab COMMAND");
	const char *cmds[] = {"run", "list", "info", "build"};
	for (int k = 0; k < 4; k++) {
		CHECK_INT(run(ARGS(cmds[k], "--help")), 0);
		CHECK_CONTAINS(out_text, "usage: bvhlab");
		CHECK_CONTAINS(out_text, cmds[k]);
	}
	CHECK_INT(run(ARGS("frobnicate")), 2);
	CHECK_CONTAINS(err_text, "unknown command 'frobnicate'");
	CHECK_INT(run(ARGS("version")), 0);
	CHECK_CONTAINS(out_text, "plugin ABI 1.");
}

static const char good_config[] =
	"{ \"format_version\": 1, \"output\": \"out-good\", \"repeat\": 2, \"warmup\": 1,\n"
	"  \"rays\": { \"min_ms\": 1, \"width\": 64, \"height\": 64 },\n"
	"  \"threads\": [1, 2],\n"
	"  \"scenes\": [ { \"name\": \"ico\", \"generator\": \"icosphere\", \"frequency\": 12 },\n"
	"              { \"generator\": \"soup\", \"count\": 3000, \"seed\": 7 } ],\n"
	"  \"builders\": [ { \"plugin\": \"sah_seq\", \"name\": \"sweep\", \"threads\": [1] },\n"
	"                { \"plugin\": \"sah_seq\", \"name\": \"binned\", \"threads\": [1],\n"
	"                  \"options\": { \"method\": \"binned\", \"bins\": 16 } },\n"
	"                { \"plugin\": \"fake_good\", \"options\": { \"phases\": \"two\" } } ] }\n";

/* fake_good reports upload twice (1 + 0.5 ms) and device (2.5 ms) in every
 * build: build_phases holds their medians, sah_seq's runs have none; own_ms
 * is build_ms's median, as neither is a translation phase. */
static void check_phases(const cJSON *doc, const char *csv)
{
	const cJSON *run;
	int with = 0;
	cJSON_ArrayForEach(run, cJSON_GetObjectItem(doc, "runs")) {
		const cJSON *ph = cJSON_GetObjectItem(run, "build_phases");
		if (strcmp(run_str(run, "builder"), "fake_good") != 0) {
			CHECK(ph == NULL);
			continue;
		}
		with++;
		CHECK(cJSON_GetArraySize(ph) == 2);
		CHECK(!strcmp(cJSON_GetArrayItem(ph, 0)->string, "upload"));
		CHECK(cJSON_GetObjectItem(ph, "upload")->valuedouble == 1.5);
		CHECK(cJSON_GetObjectItem(ph, "device")->valuedouble == 2.5);
		/* own_ms takes out input and convert only: a device's upload stays. */
		const cJSON *t = cJSON_GetObjectItem(run, "build_ms");
		CHECK(cJSON_GetObjectItem(run, "own_ms")->valuedouble ==
		      cJSON_GetObjectItem(t, "median")->valuedouble);
	}
	CHECK_INT(with, 2); /* fake_good is not PARALLEL: one run per scene */
	CHECK_CONTAINS(csv, ",build_phases,error\n");
	CHECK_CONTAINS(csv, ",upload=1.5000;device=2.5000,");
}

static void check_good_results(const char *dir)
{
	cJSON *doc = load_results(dir);
	if (!doc)
		return;
	CHECK_INT(cJSON_GetArraySize(cJSON_GetObjectItem(doc, "runs")), 6);
	CHECK_INT(count_runs(doc, "sweep", "ok"), 2);
	CHECK_INT(count_runs(doc, "binned", "ok"), 2);
	/* fake_good has no PARALLEL flag: one run per scene, at 1 thread; its
	 * thread count 2 is listed as not applicable. */
	CHECK_INT(count_runs(doc, "fake_good", "ok"), 2);
	const cJSON *runs = cJSON_GetObjectItem(doc, "runs"), *r;
	cJSON_ArrayForEach(r, runs)
		CHECK_INT(cJSON_GetObjectItem(r, "threads")->valueint, 1);
	const cJSON *na = cJSON_GetObjectItem(doc, "not_applicable");
	CHECK_INT(cJSON_GetArraySize(na), 1);
	CHECK(!strcmp(run_str(cJSON_GetArrayItem(na, 0), "builder"), "fake_good"));
	const cJSON *na_threads = cJSON_GetObjectItem(cJSON_GetArrayItem(na, 0), "threads");
	CHECK_INT(cJSON_GetArraySize(na_threads), 1);
	CHECK_INT(cJSON_GetArrayItem(na_threads, 0)->valueint, 2);
	const cJSON *scenes = cJSON_GetObjectItem(doc, "scenes");
	CHECK_INT(cJSON_GetArraySize(scenes), 2);
	const cJSON *ico = cJSON_GetArrayItem(scenes, 0);
	CHECK_INT(cJSON_GetObjectItem(ico, "triangles")->valueint, 20 * 12 * 12);
	CHECK(!strcmp(run_str(cJSON_GetArrayItem(scenes, 1), "name"), "soup"));
	const cJSON *run0 = cJSON_GetArrayItem(cJSON_GetObjectItem(doc, "runs"), 0);
	CHECK(cJSON_IsTrue(cJSON_GetObjectItem(cJSON_GetObjectItem(run0, "validation"), "valid")));
	CHECK_INT(cJSON_GetArraySize(cJSON_GetObjectItem(cJSON_GetObjectItem(run0, "build_ms"),
	                                                 "samples")), 2);
	/* The first build is timed apart: a time, and no sample of the median. */
	const cJSON *cold = cJSON_GetObjectItem(cJSON_GetObjectItem(run0, "build_ms"), "cold");
	CHECK(cJSON_IsNumber(cold) && cold->valuedouble > 0);
	CHECK(cJSON_GetObjectItem(cJSON_GetObjectItem(run0, "tree"), "sah_cost")->valuedouble > 1);
	CHECK(!strcmp(run_str(cJSON_GetObjectItem(run0, "options"), "method"), "sweep"));
	/* The load average around the run, as /proc/loadavg gave it. */
	const cJSON *load = cJSON_GetObjectItem(run0, "load_before");
	CHECK(cJSON_IsNumber(load) && load->valuedouble >= 0);
	CHECK(cJSON_IsNumber(cJSON_GetObjectItem(run0, "load_after")));

	char *csv = read_file(dir, "results.csv");
	char *md = read_file(dir, "report.md");
	check_phases(doc, csv);
	cJSON_Delete(doc);
	CHECK_CONTAINS(csv, "scene,builder,plugin,status,threads,build_ms.median");
	CHECK_CONTAINS(csv, "build_ms.max,build_ms.cold,");
	CHECK_CONTAINS(csv, "soup,binned,sah_seq,ok,1,");
	CHECK_CONTAINS(md, "## ico");
	CHECK_CONTAINS(md, "## soup");
	CHECK_CONTAINS(md, "| binned | 1 | ok |");
	free(csv);
	free(md);
}

static void test_run_good(void)
{
	const char *cfg = write_config("good.json", good_config);
	CHECK_INT(run(ARGS("run", "--quiet", cfg)), 0);
	char dir[512];
	snprintf(dir, sizeof(dir), "%s/out-good", tmpdir);
	check_good_results(dir);

	/* --out and --repeat override the config. */
	snprintf(dir, sizeof(dir), "%s/out-override", tmpdir);
	CHECK_INT(run(ARGS("run", cfg, "--out", dir, "--repeat", "1")), 0);
	CHECK_CONTAINS(err_text, "[6/6");
	CHECK_CONTAINS(err_text, "builder 'fake_good': not a parallel builder (no PARALLEL flag): "
	                         "one run per scene, at 1 thread; thread count 2 not applicable");
	cJSON *doc = load_results(dir);
	const cJSON *run0 = cJSON_GetArrayItem(cJSON_GetObjectItem(doc, "runs"), 0);
	CHECK_INT(cJSON_GetArraySize(cJSON_GetObjectItem(cJSON_GetObjectItem(run0, "build_ms"),
	                                                 "samples")), 1);
	cJSON_Delete(doc);
}

/* "pin": true reaches plugins through host->pin_thread; false leaves it a no-op. */
static void test_pin(void)
{
	static const char fmt[] =
		"{ \"output\": \"out-pin-%s\", \"repeat\": 1, \"pin\": %s, \"threads\": [2],\n"
		"  \"rays\": { \"min_ms\": 1, \"width\": 64, \"height\": 64 },\n"
		"  \"scenes\": [ { \"generator\": \"soup\", \"count\": 2000 } ],\n"
		"  \"builders\": [ { \"plugin\": \"%s/pin_probe.so\",\n"
		"                  \"options\": { \"expect\": \"%s\" } } ] }\n";
	char text[1024], dir[512];
	for (int on = 0; on < 2; on++) {
		snprintf(text, sizeof(text), fmt, on ? "on" : "off", on ? "true" : "false",
		         BVHLAB_TEST_BUILDDIR, on ? "pinned" : "free");
		CHECK_INT(run(ARGS("run", "--quiet", write_config("pin.json", text))), 0);
		snprintf(dir, sizeof(dir), "%s/out-pin-%s", tmpdir, on ? "on" : "off");
		cJSON *doc = load_results(dir);
		CHECK_INT(count_runs(doc, "pin_probe", "ok"), 1);
		cJSON_Delete(doc);
	}
}

static void test_info_build_list(void)
{
	CHECK_INT(run(ARGS("info", "soup:count=1000,seed=3", "--json")), 0);
	cJSON *o = cJSON_Parse(out_text);
	CHECK(o && cJSON_GetObjectItem(o, "triangles")->valueint == 1000);
	cJSON_Delete(o);
	CHECK_INT(run(ARGS("info", "icosphere:frequency=4", "--subdivide", "1")), 0);
	CHECK_CONTAINS(out_text, "triangles:  1280");
	CHECK_INT(run(ARGS("info", "/nonexistent/mesh.obj")), 2);
	CHECK_CONTAINS(err_text, "/nonexistent/mesh.obj");

	CHECK_INT(run(ARGS("build", "sah_seq", "icosphere:frequency=8", "-o", "method=binned",
	                   "--repeat", "2")), 0);
	CHECK_CONTAINS(out_text, "valid:      yes");
	CHECK_CONTAINS(out_text, "cold:       ");
	CHECK_CONTAINS(out_text, "SAH cost:");
	CHECK_INT(run(ARGS("build", "fake_good", "soup:count=50", "-o", "phases=two")), 0);
	CHECK_CONTAINS(out_text, "phase:      upload 1.500 ms median\nphase:      device 2.500");
	CHECK_INT(run(ARGS("build", "sah_seq", "soup:count=500", "-o", "bins=1")), 2);
	CHECK_CONTAINS(err_text, "option 'bins' of plugin 'sah_seq' is out of range");
	CHECK_INT(run(ARGS("build", "no_such_plugin", "soup")), 2);
	CHECK_CONTAINS(err_text, "plugin 'no_such_plugin' not found");

	CHECK_INT(run(ARGS("list", "sah_seq")), 0);
	CHECK_CONTAINS(out_text, "sah_seq");
	CHECK_CONTAINS(out_text, "method");
	CHECK_CONTAINS(out_text, "sweep|binned");
	CHECK_INT(run(ARGS("list")), 1); /* the broken fake plugins are on the path */
	CHECK_CONTAINS(out_text, "fake_abi2: NOT USABLE");
	CHECK_CONTAINS(out_text, "fake_good");
	/* Integer ranges as integers, not 1.07374e+09. */
	CHECK_INT(run(ARGS("list", "sah_tasks")), 0);
	CHECK_CONTAINS(out_text, "range [128, 1073741824]");
	CHECK(!strstr(out_text, "e+"));
	/* Names only, one a line, none loaded (the broken ones are listed too). */
	CHECK_INT(run(ARGS("list", "--names")), 0);
	CHECK_CONTAINS(out_text, "\nfake_good\n");
	CHECK_CONTAINS(out_text, "\nsah_seq\n");
	CHECK(!strstr(out_text, "NOT USABLE") && !strstr(out_text, "options"));
}

static void test_config_errors(void)
{
	const char *cfg = write_config("typo.json",
		"{ \"format_version\": 1,\n"
		"  \"scenes\": [ { \"generator\": \"soup\" } ],\n"
		"  \"builders\": [ { \"plugin\": \"sah_seq\",\n"
		"                  \"threds\": [1] } ] }\n");
	CHECK_INT(run(ARGS("run", cfg)), 2);
	CHECK_CONTAINS(err_text, "typo.json:4:19: unknown key 'threds'");
	CHECK_CONTAINS(err_text, "did you mean 'threads'?");

	cfg = write_config("syntax.json", "{ \"format_version\": 1,\n  \"scenes\": [ }\n");
	CHECK_INT(run(ARGS("run", cfg)), 2);
	CHECK_CONTAINS(err_text, "syntax.json:2:");

	CHECK_INT(run(ARGS("run", "/nonexistent/config.json")), 2);
	CHECK_CONTAINS(err_text, "/nonexistent/config.json");
}

/* How often needle occurs in hay. */
static int occurrences(const char *hay, const char *needle)
{
	int n = 0;
	for (const char *p = hay; (p = strstr(p, needle)); p += strlen(needle))
		n++;
	return n;
}

/*
 * Builders whose config is wrong (unknown plugin, unknown option, an
 * option of the wrong type, a plugin of another ABI, and a second error in
 * the same file) refuse the whole config before anything runs: exit 2,
 * every error printed once with its position, no output folder.
 */
static void test_bad_builders(void)
{
	const char *cfg = write_config("bad.json",
		"{ \"output\": \"out-bad\", \"repeat\": 1, \"rays\": { \"min_ms\": 1 },\n"
		"  \"scenes\": [ { \"generator\": \"soup\", \"count\": 500 } ],\n"
		"  \"builders\": [ { \"plugin\": \"no_such_plugin\" },\n"
		"                { \"plugin\": \"fake_abi2\" },\n"
		"                { \"plugin\": \"fake_good\", \"name\": \"typed\",\n"
		"                  \"options\": { \"alpha\": \"two\" } },\n"
		"                { \"plugin\": \"fake_good\", \"name\": \"typo\",\n"
		"                  \"options\": { \"alpah\": 2 } },\n"
		"                { \"plugin\": \"sah_seq\" } ] }\n");
	CHECK_INT(run(ARGS("run", "--quiet", cfg)), 2);
	CHECK_CONTAINS(err_text, "bad.json:3:17: builder 'no_such_plugin': plugin "
	                         "'no_such_plugin' not found");
	CHECK_CONTAINS(err_text, "bad.json:4:17: builder 'fake_abi2': ");
	CHECK_CONTAINS(err_text, "built for ABI 2.0");
	CHECK_CONTAINS(err_text, "bad.json:6:32: builder 'typed': option 'alpha' of plugin "
	                         "'fake_good' must be");
	CHECK_CONTAINS(err_text, "bad.json:8:32: builder 'typo': unknown option 'alpah' for plugin "
	                         "'fake_good'");
	CHECK_CONTAINS(err_text, "4 builders cannot run as configured");
	CHECK_INT(occurrences(err_text, "builder 'typo'"), 1); /* said once, not twice */
	CHECK_INT(occurrences(err_text, "builder 'no_such_plugin'"), 1);
	CHECK(!exists(path_in("out-bad")));

	/* A grid's builders share a bad plugin: one message, not one per value. */
	cfg = write_config("badgrid.json",
		"{ \"output\": \"out-badgrid\", \"scenes\": [ { \"generator\": \"soup\" } ],\n"
		"  \"builders\": [ { \"plugin\": \"no_such_plugin\",\n"
		"                  \"options\": { \"bins\": { \"grid\": [4, 8] } } } ] }\n");
	CHECK_INT(run(ARGS("run", "--quiet", cfg)), 2);
	CHECK_INT(occurrences(err_text, "not found on the search path"), 1);
	CHECK(!exists(path_in("out-badgrid")));
}

/*
 * A scene file that is not there (a mesh, a composite's part, a frame file
 * of an animation) refuses the config before anything runs: exit 2, the
 * scene and the path named at the scene's position, no output folder. So
 * does a PLY whose header does not parse; every bad file is said at once.
 */
static void test_missing_scene_files(void)
{
	static const char *const scenes[] = {
		"{ \"path\": \"gone.obj\" }",
		"{ \"name\": \"comp\", \"parts\": [ { \"generator\": \"soup\", \"count\": 10 },\n"
		"                                  { \"path\": \"sub/gone.ply\" } ] }",
		"{ \"name\": \"anim\", \"frames\": { \"pattern\": \"gone%02d.obj\", \"count\": 2 } }"};
	static const char *const said[] = {
		"m0.json:2:15: scene 'gone': ", "m1.json:2:15: scene 'comp': part 1: ",
		"m2.json:2:15: scene 'anim': frame 0: "};
	static const char *const paths[] = {"gone.obj", "sub/gone.ply", "gone00.obj"};
	char text[1024], name[32], expected[256];
	for (int k = 0; k < 3; k++) {
		snprintf(text, sizeof(text), "{ \"output\": \"out-gone\", \"repeat\": 1,\n"
		         "  \"scenes\": [ %s ],\n  \"builders\": [ { \"plugin\": \"sah_seq\" } ] }\n",
		         scenes[k]);
		snprintf(name, sizeof(name), "m%d.json", k);
		snprintf(expected, sizeof(expected), "%s%s/%s: cannot open: No such file or directory",
		         said[k], tmpdir, paths[k]);
		cli_refused(name, text, expected);
		CHECK_CONTAINS(err_text, k < 2 ? "1 scene file cannot be read (above); nothing was run"
		                               : "2 scene files cannot be read");
		CHECK(!exists(path_in("out-gone")));
	}
	/* Present but with a broken PLY header, beside a missing frame 1. */
	write_config("head.ply", "ply\nformat ascii 1.0\nelement vertex 3\nwhat\nend_header\n");
	write_config("here00.obj", "v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 3\n");
	cli_refused("m3.json",
		"{ \"output\": \"out-gone\", \"scenes\": [ { \"path\": \"head.ply\" },\n"
		"  { \"name\": \"a\", \"frames\": { \"pattern\": \"here%02d.obj\", \"count\": 2 } } ],\n"
		"  \"builders\": [ { \"plugin\": \"sah_seq\" } ] }\n",
		"head.ply:4: bad PLY header");
	CHECK_CONTAINS(err_text, "scene 'head': ");
	CHECK_CONTAINS(err_text, "scene 'a': frame 1: ");
	CHECK(!strstr(err_text, "frame 0"));
	CHECK_CONTAINS(err_text, "2 scene files cannot be read");
	CHECK(!exists(path_in("out-gone")));
}

/* Failures at run time (a build that fails, a scene that does not load)
 * are recorded as failed runs; the rest still run. */
static void test_failed_runs(void)
{
	/* It opens, so the config is fine; its face's vertex is missing. */
	write_config("broken.obj", "v 0 0 0\nf 1 2 3\n");
	const char *cfg = write_config("fails.json",
		"{ \"output\": \"out-fails\", \"repeat\": 1, \"rays\": { \"min_ms\": 1 },\n"
		"  \"scenes\": [ { \"generator\": \"soup\", \"count\": 500 },\n"
		"              { \"path\": \"broken.obj\" } ],\n"
		"  \"builders\": [ { \"plugin\": \"fake_good\", \"name\": \"fails\",\n"
		"                  \"options\": { \"fail\": \"error\" } },\n"
		"                { \"plugin\": \"sah_seq\" } ] }\n");
	CHECK_INT(run(ARGS("run", "--quiet", cfg)), 1);
	char dir[512];
	snprintf(dir, sizeof(dir), "%s/out-fails", tmpdir);
	cJSON *doc = load_results(dir);
	if (!doc)
		return;
	CHECK_INT(cJSON_GetArraySize(cJSON_GetObjectItem(doc, "runs")), 4);
	CHECK_INT(count_runs(doc, "sah_seq", "ok"), 1);
	CHECK_INT(count_runs(doc, "sah_seq", "failed"), 1); /* the broken scene */
	CHECK_INT(count_runs(doc, "fails", "failed"), 2);
	char *json = cJSON_PrintUnformatted(doc);
	CHECK_CONTAINS(json, "builder 'fake_good': asked to fail");
	CHECK_CONTAINS(json, "broken.obj:2: vertex index 3 out of range");
	free(json);
	cJSON_Delete(doc);
}

/*
 * A C++ exception out of build(), behind bvhlab::guarded_build
 * (include/bvhlab/builder.hpp): its what() is the run's error in
 * results.json and what `bvhlab build` prints, not an abort. One that
 * escapes unwrapped kills the run's child: libstdc++'s last words, from
 * its stderr, are the run's error.
 */
static void test_cxx_exception(void)
{
	CHECK_INT(run(ARGS("build", "fake_throw", "soup:count=100")), 1);
	CHECK_CONTAINS(err_text, "builder 'fake_throw': fake_throw: thrown from build() on purpose");
	CHECK_INT(run(ARGS("build", "fake_throw", "soup:count=100", "-o", "throw=int")), 1);
	CHECK_CONTAINS(err_text, "a C++ exception that is not a std::exception");
	CHECK_INT(run(ARGS("build", "fake_throw", "soup:count=100", "-o", "throw=none")), 0);
	const char *cfg = write_config("throw.json",
		"{ \"output\": \"out-throw\", \"repeat\": 1, \"rays\": { \"min_ms\": 1 },\n"
		"  \"scenes\": [ { \"generator\": \"soup\", \"count\": 200 } ],\n"
		"  \"builders\": [ { \"plugin\": \"fake_throw\" },\n"
		"                { \"plugin\": \"fake_throw\", \"name\": \"oom\",\n"
		"                  \"options\": { \"throw\": \"bad_alloc\" } },\n"
		"                { \"plugin\": \"fake_throw\", \"name\": \"escape\",\n"
		"                  \"options\": { \"throw\": \"escape\" } } ] }\n");
	CHECK_INT(run(ARGS("run", "--quiet", cfg)), 1);
	cJSON *doc = load_results(path_in("out-throw"));
	if (!doc)
		return;
	CHECK_INT(count_runs(doc, "fake_throw", "failed"), 1);
	CHECK_INT(count_runs(doc, "oom", "failed"), 1);
	char *json = cJSON_PrintUnformatted(doc);
	CHECK_CONTAINS(json, "fake_throw: thrown from build() on purpose");
	CHECK_CONTAINS(json, "out of memory (std::bad_alloc) for 200 primitives");
	/* Unwrapped, the child dies; the end of its stderr is in the run's error. */
	CHECK_INT(count_runs(doc, "escape", "crashed"), 1);
	CHECK_CONTAINS(json, "killed by SIGABRT (Aborted); its stderr ended: terminate called "
	                     "after throwing an instance of 'std::runtime_error' what(): "
	                     "fake_throw: escaped build() unguarded");
	free(json);
	cJSON_Delete(doc);
}

/* All five shared meshes, both sah_seq methods: valid, sweep SAH <= binned SAH. */
static void test_shared_meshes(void)
{
	static const char *meshes[] = {"stanford-bunny.obj", "ogre.obj", "nefertiti.obj",
	                               "horse.ply", "igea.ply"};
	char text[4096];
	int n = snprintf(text, sizeof(text),
	                 "{ \"output\": \"out-shared\", \"repeat\": 1, \"warmup\": 0,\n"
	                 "  \"rays\": { \"min_ms\": 1, \"width\": 64, \"height\": 64 },\n"
	                 "  \"validate_rays\": 64, \"scenes\": [");
	for (int k = 0; k < 5; k++)
		n += snprintf(text + n, sizeof(text) - (size_t)n, "%s{ \"path\": \"%s/%s\" }",
		              k ? ", " : "", BVHLAB_SHARED_SCENES, meshes[k]);
	snprintf(text + n, sizeof(text) - (size_t)n,
	         "],\n  \"builders\": [ { \"plugin\": \"sah_seq\", \"name\": \"sweep\" },\n"
	         "  { \"plugin\": \"sah_seq\", \"name\": \"binned\", "
	         "\"options\": { \"method\": \"binned\" } } ] }\n");
	CHECK_INT(run(ARGS("run", "--quiet", write_config("shared.json", text))), 0);
	char dir[512];
	snprintf(dir, sizeof(dir), "%s/out-shared", tmpdir);
	cJSON *doc = load_results(dir);
	if (!doc)
		return;
	const cJSON *runs = cJSON_GetObjectItem(doc, "runs");
	CHECK_INT(cJSON_GetArraySize(runs), 10);
	CHECK_INT(count_runs(doc, "sweep", "ok"), 5);
	CHECK_INT(count_runs(doc, "binned", "ok"), 5);
	for (int k = 0; k + 1 < cJSON_GetArraySize(runs); k += 2) {
		const cJSON *sweep = cJSON_GetArrayItem(runs, k), *binned = cJSON_GetArrayItem(runs, k + 1);
		double s = cJSON_GetObjectItem(cJSON_GetObjectItem(sweep, "tree"), "sah_cost")->valuedouble;
		double b = cJSON_GetObjectItem(cJSON_GetObjectItem(binned, "tree"), "sah_cost")->valuedouble;
		printf("%s: sweep SAH %.4f, binned SAH %.4f\n", run_str(sweep, "scene"), s, b);
		CHECK(!strcmp(run_str(sweep, "scene"), run_str(binned, "scene")));
		CHECK(s <= b);
	}
	cJSON_Delete(doc);
}

int main(int argc, char **argv)
{
	if (!cli_begin(argc, argv))
		return 2;
	if (!strcmp(argv[2], "basic")) {
		test_help();
		test_run_good();
		test_pin();
		test_info_build_list();
	} else if (!strcmp(argv[2], "errors")) {
		test_config_errors();
		test_bad_builders();
		test_missing_scene_files();
		test_failed_runs();
		test_cxx_exception();
	} else if (!strcmp(argv[2], "shared")) {
		if (access(BVHLAB_SHARED_SCENES "/ogre.obj", R_OK) != 0)
			return TEST_SKIP;
		test_shared_meshes();
	}
	return cli_end();
}
