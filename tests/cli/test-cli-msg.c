/*
 * Issue 43's statuses, figures, versions, messages and escaping, one mode
 * per group, each a meson test of its own (cli-rel-MODE):
 *   status    out of memory while validating is "failed", not "invalid";
 *             an update plugin that crashes names the frame and the plugin
 *             and keeps frame 0; untraced rays leave figures null, name no
 *             cheapest strategy, and every failed traversal is kept
 *   version   bvhlab_version names the commit; merge refuses parts of other
 *             versions (--allow-mixed-versions records each); --repeat on a
 *             plan part refused
 *   config    bad options, names and coordinates refused before any output
 *   escape    names and errors escaped in report.md, CSV cells guarded
 *   images    images that cannot be written (a full disk) named, counted,
 *             the runs kept
 *   pocl      a POCL_CACHE_DIR PoCL cannot use named as the likely cause of
 *             a failed kernel build or a missing device, on one line
 * Usage: test-cli-msg BVHLAB_EXE MODE
 */
#include <sys/resource.h>
#include <sys/stat.h>

#include "cliutil.h"

/* Runs config `text` as `name` (from tmpdir): its exit status; the results
 * of folder `out` into *doc (checked to be there), NULL after exit 2. */
static int sweep(const char *name, const char *text, const char *out, cJSON **doc)
{
	int status = run_in(tmpdir, ARGS("run", "--quiet", write_config(name, text)));
	*doc = status == 2 ? NULL : load_results(cli_path_in(out));
	return status;
}

static const cJSON *first_run(const cJSON *doc)
{
	return cJSON_GetArrayItem(cJSON_GetObjectItem(doc, "runs"), 0);
}

static const cJSON *frame_at(const cJSON *run, int f)
{
	return cJSON_GetArrayItem(cJSON_GetObjectItem(run, "frames"), f);
}

/* 4. No memory left to validate: the tree is not called invalid. */
static void status_validate_oom(void)
{
#if UNDER_ASAN || UNDER_TSAN
	/* Sanitizers reserve terabytes of address space: no limit can apply. */
#else
	cJSON *doc;
	CHECK_INT(sweep("hog.json",
		"{ \"output\": \"out-hog\", \"repeat\": 1, \"warmup\": 0, \"memory_limit_mb\": 1024,\n"
		"  \"scenes\": [ { \"generator\": \"soup\", \"count\": 1000 } ],\n"
		"  \"builders\": [ { \"plugin\": \"fake_good\", \"options\": { \"fail\": \"hog\" } } ] }\n",
		"out-hog", &doc), 1);
	const cJSON *run = first_run(doc);
	CHECK_CONTAINS(run_str(run, "status"), "failed");
	CHECK_CONTAINS(run_str(run, "error"), "out of memory validating");
	CHECK_CONTAINS(run_str(run, "error"), "not found invalid");
	CHECK_CONTAINS(run_str(run, "error"), "(under memory_limit_mb = 1024)");
	cJSON_Delete(doc);
#endif
}

/* 9. An update plugin that crashes in frame 1: named with its frame, frame 0 kept. */
static void status_update_crash(void)
{
	cJSON *doc;
	plain_crashes();
	CHECK_INT(sweep("up.json",
		"{ \"output\": \"out-up\", \"repeat\": 1, \"warmup\": 0,\n"
		"  \"scenes\": [ { \"name\": \"s\", \"generator\": \"soup\", \"count\": 200,\n"
		"                \"frames\": 3, \"deform\": \"wave\" } ],\n"
		"  \"builders\": [ { \"name\": \"h12\", \"plugin\": \"fake_good\",\n"
		"                  \"animation\": { \"update\": \"fake_upcrash\" } } ] }\n",
		"out-up", &doc), 1);
	const cJSON *run = first_run(doc);
	CHECK_INT(count_runs(doc, "h12", "crashed"), 1);
	CHECK_CONTAINS(run_str(run, "error"), "frame 1, updated by 'fake_upcrash': killed by SIGSEGV");
	CHECK(!strstr(run_str(run, "error"), "builder 'h12'"));
	CHECK_INT(cJSON_GetArraySize(cJSON_GetObjectItem(run, "frames")), 1);
	CHECK(cJSON_IsNumber(cJSON_GetObjectItem(frame_at(run, 0), "sah")));
	CHECK(cJSON_IsNumber(cJSON_GetObjectItem(cJSON_GetObjectItem(run, "build_ms"), "median")));
	cJSON_Delete(doc);
}

/* 5, 9. Device traversals that cannot run (no OpenCL platform): the frames'
 * ray figures and costs null, no cheapest strategy, both errors kept. */
static void status_untraced(void)
{
	cJSON *doc;
	CHECK(mkdir(cli_path_in("no-icd"), 0755) == 0);
	setenv("OCL_ICD_VENDORS", cli_path_in("no-icd"), 1);
	int status = sweep("nr.json",
		"{ \"output\": \"out-nr\", \"repeat\": 1, \"warmup\": 0,\n"
		"  \"rays\": { \"width\": 16, \"height\": 16,\n"
		"            \"traversal\": [ {\"name\": \"stack\", \"device\": true},\n"
		"              {\"name\": \"stackless\", \"device\": true} ] },\n"
		"  \"scenes\": [ { \"name\": \"s\", \"generator\": \"soup\", \"count\": 200,\n"
		"                \"frames\": 3, \"deform\": \"wave\" } ],\n"
		"  \"builders\": [ { \"name\": \"a\", \"plugin\": \"lbvh\",\n"
		"                  \"animation\": { \"update\": \"refit\" } } ] }\n", "out-nr", &doc);
	unsetenv("OCL_ICD_VENDORS");
	if (status == 2 && strstr(err_text, "OpenCL")) {
		fprintf(stderr, "built without OpenCL: the untraced frames are not checked\n");
		return;
	}
	CHECK_INT(status, 0);
	const cJSON *run = first_run(doc);
	CHECK_INT(cJSON_GetArraySize(cJSON_GetObjectItem(run, "frames")), 3);
	for (int f = 0; f < 3; f++) {
		const cJSON *fr = frame_at(run, f);
		CHECK(cJSON_IsNumber(cJSON_GetObjectItem(fr, "sah")));
		CHECK(cJSON_IsNull(cJSON_GetObjectItem(fr, "nodes_per_ray")));
		CHECK(cJSON_IsNull(cJSON_GetObjectItem(fr, "mrays_per_s")));
		CHECK(cJSON_IsNull(cJSON_GetObjectItem(fr, "cost_ms")));
	}
	char *md = read_file(cli_path_in("out-nr"), "report.md");
	CHECK(md && !strstr(md, "Cheapest over the animation") && !strstr(md, "nan"));
	CHECK_CONTAINS(md ? md : "", "not measured");
	CHECK_CONTAINS(md ? md : "", "No strategy's cost was measured");
	free(md);
	cJSON_Delete(doc);
	/* The main traversal's failure fails the batch; a static scene's rays
	 * with a CPU main and two device ones keep both devices' errors. */
	setenv("OCL_ICD_VENDORS", cli_path_in("no-icd"), 1);
	CHECK_INT(sweep("nr2.json",
		"{ \"output\": \"out-nr2\", \"repeat\": 1, \"warmup\": 0,\n"
		"  \"rays\": { \"width\": 16, \"height\": 16,\n"
		"            \"traversal\": [ \"stack\", {\"name\": \"stack\", \"device\": true},\n"
		"              {\"name\": \"stackless\", \"device\": true} ] },\n"
		"  \"scenes\": [ { \"name\": \"s\", \"generator\": \"soup\", \"count\": 200 } ],\n"
		"  \"builders\": [ { \"plugin\": \"lbvh\" } ] }\n", "out-nr2", &doc), 0);
	unsetenv("OCL_ICD_VENDORS");
	const char *e = run_str(cJSON_GetObjectItem(first_run(doc), "rays"), "error");
	CHECK_CONTAINS(e, "device_stack: ");
	CHECK_CONTAINS(e, "; device_stackless: ");
	CHECK(!strchr(e, '\n'));
	cJSON_Delete(doc);
}

static void test_status(void)
{
	status_validate_oom();
	status_update_crash();
	status_untraced();
}

/* Replaces the bvhlab_version in dir/results.json with `version`. */
static void set_version(const char *dir, const char *version)
{
	cJSON *doc = load_results(dir);
	cJSON_ReplaceItemInObject(doc, "bvhlab_version", cJSON_CreateString(version));
	char *text = cJSON_Print(doc), path[700];
	snprintf(path, sizeof(path), "%s/results.json", dir);
	FILE *f = fopen(path, "w");
	CHECK(f && text && fputs(text, f) >= 0);
	if (f)
		fclose(f);
	free(text);
	cJSON_Delete(doc);
}

/* 7. The version names the commit; merge checks and keeps each part's;
 * --repeat on a plan part is refused like --threads. */
static void test_version(void)
{
	CHECK_INT(run_in(tmpdir, ARGS("--version")), 0);
	/* "bvhlab 0.1.0+COMMIT (plugin ABI ...)": a commit, or "unknown" outside git. */
	CHECK(strstr(out_text, "0.1.0+") != NULL);
	cli_plan_ab("v.json", "", "pv");
	CHECK_INT(run_in(tmpdir, ARGS("run", cli_path_in("pv/plan.json"), "--only", "0", "--repeat",
	                              "7", "--out", cli_path_in("pv/parts/0"), "--quiet")), 2);
	CHECK_CONTAINS(err_text, "--repeat cannot be combined with a plan");
	CHECK(!cli_exists(cli_path_in("pv/parts/0")));
	for (int k = 0; k < 2; k++)
		CHECK_INT(cli_run_part("pv", k), 0);
	set_version(cli_path_in("pv/parts/1"), "0.0.9+000000000000");
	CHECK_INT(run_in(tmpdir, ARGS("merge", cli_path_in("pv/parts/0"), cli_path_in("pv/parts/1"),
	                              "--out", cli_path_in("pv"))), 2);
	CHECK_CONTAINS(err_text, "by bvhlab 0.0.9+000000000000");
	CHECK_CONTAINS(err_text, "--allow-mixed-versions");
	CHECK(!cli_exists(cli_path_in("pv/results.json")));
	CHECK_INT(run_in(tmpdir, ARGS("merge", cli_path_in("pv/parts/0"), cli_path_in("pv/parts/1"),
	                              "--out", cli_path_in("pv"), "--allow-mixed-versions")), 0);
	cJSON *doc = load_results(cli_path_in("pv"));
	CHECK_CONTAINS(run_str(doc, "bvhlab_version"), "mixed");
	CHECK_CONTAINS(run_str(find_run(doc, "s", "b", 1), "bvhlab_version"), "0.0.9+000000000000");
	CHECK_CONTAINS(run_str(find_run(doc, "s", "a", 1), "bvhlab_version"), "0.1.0+");
	const cJSON *versions = cJSON_GetObjectItem(cJSON_GetObjectItem(doc, "merged"), "versions");
	CHECK_INT(cJSON_GetArraySize(versions), 2);
	cJSON_Delete(doc);
}

#define LOADCRASH_DIR BVHLAB_TEST_BUILDDIR "/fake/loadcrash"

/* Runs config `text` as `name` expecting exit 2 before any output folder
 * (`out`) exists, with `message` on stderr. */
static void refused(const char *name, const char *text, const char *out, const char *message)
{
	cli_refused(name, text, message);
	CHECK(!cli_exists(cli_path_in(out)));
}

/* 9. Options no declaration states, names and coordinates: config errors. */
static void config_errors(void)
{
	refused("leaf.json",
		"{ \"output\": \"out-leaf\",\n"
		"  \"scenes\": [ { \"generator\": \"soup\", \"count\": 100 } ],\n"
		"  \"builders\": [ { \"plugin\": \"bvh2\", \"options\": { \"min_leaf\": 9 } },\n"
		"                  { \"plugin\": \"embree\", \"name\": \"e\",\n"
		"                    \"options\": { \"min_leaf\": 6, \"max_leaf\": 4 } } ] }\n",
		"out-leaf", "");
	if (!strstr(err_text, "plugin 'bvh2' not found")) /* built with bvh2 (optional) */
		CHECK_CONTAINS(err_text, "builder 'bvh2': option 'min_leaf' of plugin 'bvh2' is 9, "
		               "more than 'max_leaf' (8)");
	if (strstr(err_text, "'embree'")) /* built with Embree */
		CHECK_CONTAINS(err_text, "builder 'e': option 'min_leaf' of plugin 'embree' is 6");
	refused("dev.json",
		"{ \"output\": \"out-dev\",\n"
		"  \"scenes\": [ { \"generator\": \"soup\", \"count\": 100 } ],\n"
		"  \"builders\": [ { \"plugin\": \"cl_lbvh\", \"options\": { \"device\": \"\" } } ] }\n",
		"out-dev", "");
	if (!strstr(err_text, "plugin 'cl_lbvh' not found")) /* built with OpenCL */
		CHECK_CONTAINS(err_text, "builder 'cl_lbvh': option 'device' of plugin 'cl_lbvh' "
		               "must not be empty (default 'auto')");
	FILE *f = fopen(cli_path_in("big.obj"), "w");
	CHECK(f && fputs("v 0 0 0\nv 1 0 0\nv 0 -1e38 0\nf 1 2 3\n", f) >= 0);
	if (f)
		fclose(f);
	CHECK_INT(run_in(tmpdir, ARGS("build", "lbvh", cli_path_in("big.obj"))), 2);
	CHECK_CONTAINS(err_text, "big.obj:3: coordinate beyond +-1e18");
}

/* 9. Phase times: over 1e12 ms and longer than the build, each with its rule. */
static void config_phases(void)
{
	cJSON *doc;
	CHECK_INT(sweep("ph.json",
		"{ \"output\": \"out-ph\", \"repeat\": 1,\n"
		"  \"scenes\": [ { \"generator\": \"soup\", \"count\": 100 } ],\n"
		"  \"builders\": [ { \"plugin\": \"fake_good\", \"name\": \"huge\",\n"
		"                    \"options\": { \"phases\": \"huge\" } },\n"
		"                  { \"plugin\": \"fake_good\", \"name\": \"long\",\n"
		"                    \"options\": { \"phases\": \"long\" } } ] }\n", "out-ph", &doc),
		1);
	CHECK_CONTAINS(run_str(find_run(doc, "soup", "huge", 1), "error"),
	               "'device' (2e+12 ms): times are finite, >= 0 and at most 1e12 ms");
	CHECK_CONTAINS(run_str(find_run(doc, "soup", "long", 1), "error"),
	               "'device' (5000 ms) in a build that took");
	cJSON_Delete(doc);
}

/* 9. bvhlab build isolates the plugin: a C++ static constructor that
 * throws, or a crash while loading, is exit status 1 naming the plugin. */
static void config_build_isolated(void)
{
	plain_crashes();
	CHECK_INT(run_in(tmpdir, ARGS("build", LOADCRASH_DIR "/throw_ctor.so", "soup:count=50")), 1);
	CHECK_CONTAINS(err_text, "throw_ctor.so' on soup:count=50: killed by SIGABRT");
	CHECK_CONTAINS(err_text, "fake_throw: escaped build() unguarded");
	CHECK_INT(run_in(tmpdir, ARGS("build", LOADCRASH_DIR "/crash_ctor.so", "soup:count=50")), 1);
	CHECK_CONTAINS(err_text, "killed by SIGSEGV");
	CHECK_INT(run_in(tmpdir, ARGS("build", "fake_good", "soup:count=50")), 0);
	CHECK_CONTAINS(out_text, "valid:      yes");
	CHECK_INT(run_in(tmpdir, ARGS("build", "fake_good", "soup:count=50", "-o", "alpha=99")), 2);
	CHECK_CONTAINS(err_text, "option 'alpha' of plugin 'fake_good' is out of range");
}

/* 9. Device layers under a memory limit say so, not "install a driver". */
static void config_memory_messages(void)
{
#if UNDER_ASAN || UNDER_TSAN
	/* Sanitizers reserve terabytes of address space: no limit can apply. */
#else
	cJSON *doc;
	int status = sweep("lim.json",
		"{ \"output\": \"out-lim\", \"repeat\": 1, \"warmup\": 0, \"memory_limit_mb\": 100,\n"
		"  \"threads\": [2],\n"
		"  \"scenes\": [ { \"generator\": \"soup\", \"count\": 1000 } ],\n"
		"  \"builders\": [ { \"plugin\": \"cl_lbvh\", \"optional\": true },\n"
		"                  { \"plugin\": \"embree\", \"optional\": true } ] }\n", "out-lim", &doc);
	CHECK(status == 1 || status == 0);
	const cJSON *cl = find_run(doc, "soup", "cl_lbvh", 2), *em = find_run(doc, "soup", "embree", 2);
	if (cl) {
		CHECK_CONTAINS(run_str(cl, "error"), "no OpenCL platform could be opened: this "
		               "process's address space is limited to 100 MB (memory_limit_mb)");
		CHECK(!strstr(run_str(cl, "error"), "install an OpenCL driver"));
	}
	if (em)
		CHECK_CONTAINS(run_str(em, "error"), "rtcNewDevice(threads=2) failed: out of memory; "
		               "the address space is limited to 100 MB");
	cJSON_Delete(doc);
#endif
}

static void test_config(void)
{
	config_errors();
	config_phases();
	config_build_isolated();
	config_memory_messages();
}

/* 10. Names and errors escaped in report.md (tables and text), CSV cells
 * that a spreadsheet would run guarded, names refused that are blank or
 * hold control or bidirectional characters. */
static void test_escape(void)
{
	cJSON *doc;
	write_config("bad <!-- m.obj", "v 0 0 0\n"); /* opens, but has no triangle */
	CHECK_INT(sweep("esc.json",
		"{ \"output\": \"out-esc\", \"repeat\": 1, \"warmup\": 0,\n"
		"  \"rays\": { \"width\": 8, \"height\": 8 },\n"
		"  \"scenes\": [ { \"name\": \"=1+2 <script>s</script>\", \"generator\": \"soup\",\n"
		"                \"count\": 100, \"frames\": 2, \"deform\": \"wave\" },\n"
		"                { \"name\": \"-x\", \"path\": \"bad <!-- m.obj\" } ],\n"
		"  \"builders\": [ { \"plugin\": \"lbvh\", \"name\": \"a|b <!-- c\",\n"
		"                    \"animation\": { \"update\": \"refit\",\n"
		"                                    \"allow_static\": true } },\n"
		"                  { \"plugin\": \"lbvh\", \"name\": \"@sum\" } ] }\n", "out-esc", &doc),
		1);
	cJSON_Delete(doc);
	char *md = read_file(cli_path_in("out-esc"), "report.md");
	CHECK(md != NULL);
	if (md) {
		CHECK(!strstr(md, "<script") && !strstr(md, "<!--"));
		const char *anim = strstr(md, "### Animation");
		CHECK_CONTAINS(anim ? anim : "", "| a\\|b &lt;!-- c | 1 | 2 | yes |");
		CHECK_CONTAINS(md, "## =1+2 &lt;script&gt;s&lt;/script&gt;");
		CHECK_CONTAINS(md, "bad &lt;!-- m.obj");
	}
	free(md);
	char *csv = read_file(cli_path_in("out-esc"), "results.csv");
	CHECK(csv != NULL);
	if (csv) {
		CHECK_CONTAINS(csv, "\n\"'=1+2 <script>s</script>\",a|b <!-- c,lbvh,");
		CHECK_CONTAINS(csv, "\n\"'-x\",\"'@sum\",");
		CHECK(!strstr(csv, "\n=") && !strstr(csv, ",=") && !strstr(csv, ",@"));
	}
	free(csv);
	char *frames = read_file(cli_path_in("out-esc"), "frames.csv");
	CHECK_CONTAINS(frames ? frames : "", "\n\"'=1+2 <script>s</script>\",a|b <!-- c,lbvh,");
	free(frames);
	static const char *const bad[][2] = {
		{"\"  \"", "its scene name is only blanks"},
		{"\"a\\u202eb\"", "its scene name holds the bidirectional control U+202E"},
		{"\"a\\u0007b\"", "its scene name holds the control character U+0007"},
		{"\"a\\u0085b\"", "its scene name holds the control character U+0085"},
	};
	for (size_t k = 0; k < sizeof(bad) / sizeof(bad[0]); k++) {
		cli_refused_with("bad.json",
		                 "{ \"output\": \"out-bad\", \"scenes\": [ { \"name\": %s, \"generator\": "
		                 "\"soup\", \"count\": 100 } ], \"builders\": [ { \"plugin\": \"lbvh\" } ] }\n",
		                 bad[k][0], bad[k][1]);
		CHECK(!cli_exists(cli_path_in("out-bad")));
	}
}

/* Runs config `text` as `name` with files limited to `kib` KiB
 * (RLIMIT_FSIZE, SIGXFSZ ignored: writes past it fail with EFBIG, as on a
 * full disk); its exit status and results, like sweep(). */
static int sweep_limited(const char *format, const char *out, rlim_t kib, cJSON **doc)
{
	char text[1024], name[64];
	snprintf(text, sizeof(text), format, out);
	snprintf(name, sizeof(name), "%s.json", out);
	const char *cfg = write_config(name, text);
	struct rlimit old, rl;
	CHECK_INT(getrlimit(RLIMIT_FSIZE, &old), 0);
	rl = (struct rlimit){.rlim_cur = kib << 10, .rlim_max = old.rlim_max};
	void (*was)(int) = signal(SIGXFSZ, SIG_IGN);
	CHECK_INT(setrlimit(RLIMIT_FSIZE, &rl), 0);
	int status = run_in(tmpdir, ARGS("run", cfg));
	CHECK_INT(setrlimit(RLIMIT_FSIZE, &old), 0);
	signal(SIGXFSZ, was);
	*doc = load_results(cli_path_in(out));
	return status;
}

/* Both runs kept, ok and measured, and no raw image file left behind. */
static void check_runs_kept(const cJSON *doc, const char *out)
{
	for (const char *const *b = (const char *const[]){"a", "b", NULL}; *b; b++) {
		const cJSON *run = find_run(doc, "s", *b, 1);
		CHECK_CONTAINS(run_str(run, "status"), "ok");
		CHECK(cJSON_IsNumber(cJSON_GetObjectItem(cJSON_GetObjectItem(run, "tree"), "sah_cost")));
		CHECK(!cJSON_GetObjectItem(run, "heat_image"));
	}
	char *md = read_file(cli_path_in(out), "report.md");
	CHECK(md != NULL);
	free(md);
	char raw[64];
	snprintf(raw, sizeof(raw), "%s/.heat-0-0.raw", out);
	CHECK(!cli_exists(cli_path_in(raw)));
	snprintf(raw, sizeof(raw), "%s/.shade-0-0.raw", out);
	CHECK(!cli_exists(cli_path_in(raw)));
}

/* stderr's line for an image of scene 's' lost, naming its file in tmpdir. */
static void check_lost(const char *what, const char *file)
{
	char line[1024];
	snprintf(line, sizeof(line), "bvhlab: images of scene 's': %s lost: cannot write %s: "
	         "File too large\n", what, cli_path_in(file));
	CHECK_CONTAINS(err_text, line);
}

/* 8. Images lost on a full disk: each lost one named with its file on
 * stderr, counted in the last line, exit status 1; the runs, the results
 * and the images that fit are kept. The heat maps' raw files (160 x 120 x
 * 4 bytes) do not fit 64 KiB, the shaded render's (x 3) does; in 40 KiB
 * neither does. */
static void test_images(void)
{
	static const char format[] =
		"{ \"output\": \"%s\", \"repeat\": 1, \"warmup\": 0, \"images\": true,\n"
		"  \"rays\": { \"width\": 160, \"height\": 120, \"min_ms\": 1 },\n"
		"  \"scenes\": [ { \"name\": \"s\", \"generator\": \"soup\", \"count\": 300 } ],\n"
		"  \"builders\": [ { \"plugin\": \"lbvh\", \"name\": \"a\" },\n"
		"                  { \"plugin\": \"sah_seq\", \"name\": \"b\" } ] }\n";
	cJSON *doc;
	int status = sweep_limited(format, "out-img", 64, &doc);
	if (strstr(err_text, "images skipped")) { /* built without the images module */
		fprintf(stderr, "no images module: images on a full disk not checked\n");
		cJSON_Delete(doc);
		return;
	}
	CHECK_INT(status, 1);
	check_lost("the heat map of builder 'a'", "out-img/.heat-0-0.raw");
	check_lost("the heat map of builder 'b'", "out-img/.heat-0-1.raw");
	CHECK(!strstr(err_text, "shaded render"));
	CHECK_CONTAINS(err_text, "; 2 images could not be written (see above)\n");
	check_runs_kept(doc, "out-img");
	const cJSON *images = cJSON_GetObjectItem(
		cJSON_GetArrayItem(cJSON_GetObjectItem(doc, "scenes"), 0), "images");
	CHECK_CONTAINS(run_str(images, "shaded"), "images/s.png");
	CHECK(cli_exists(cli_path_in("out-img/images/s.png")));
	cJSON_Delete(doc);

	CHECK_INT(sweep_limited(format, "out-full", 40, &doc), 1);
	check_lost("the shaded render", "out-full/.shade-0-0.raw");
	CHECK_CONTAINS(err_text, "; 3 images could not be written (see above)\n");
	check_runs_kept(doc, "out-full");
	CHECK(!cJSON_GetObjectItem(cJSON_GetArrayItem(cJSON_GetObjectItem(doc, "scenes"), 0),
	                           "images"));
	cJSON_Delete(doc);
}

static int count_of(const char *text, const char *needle)
{
	int n = 0;
	for (const char *p = strstr(text, needle); p; p = strstr(p + 1, needle))
		n++;
	return n;
}

/* The line of stderr holding `needle` (to its newline), "" if none. */
static const char *line_of(const char *text, const char *needle, char *line, size_t size)
{
	const char *at = strstr(text, needle), *start = at, *end;
	line[0] = '\0';
	if (!at)
		return line;
	while (start > text && start[-1] != '\n')
		start--;
	end = strchr(at, '\n');
	size_t n = end ? (size_t)(end - start) : strlen(start);
	snprintf(line, size, "%.*s", (int)(n < size ? n : size - 1), start);
	return line;
}

/* A sweep of cl_lbvh and of lbvh with device stack rays under POCL_CACHE_DIR =
 * `cache`: both failures name it, on one line each (errors and progress
 * lines alike). False when the device ran anyway (not PoCL: nothing to
 * check). */
static bool pocl_sweep(const char *out, const char *cache)
{
	char text[1024], name[64], line[4096], want[600];
	snprintf(text, sizeof(text),
	         "{ \"output\": \"%s\", \"repeat\": 1, \"warmup\": 0,\n"
	         "  \"rays\": { \"width\": 8, \"height\": 8, \"traversal\": [\"stack\",\n"
	         "    { \"name\": \"stack\", \"device\": true }] },\n"
	         "  \"scenes\": [ { \"name\": \"s\", \"generator\": \"soup\", \"count\": 200 } ],\n"
	         "  \"builders\": [ { \"plugin\": \"cl_lbvh\" }, { \"plugin\": \"lbvh\" } ] }\n", out);
	snprintf(name, sizeof(name), "%s.json", out);
	setenv("POCL_CACHE_DIR", cache, 1);
	int status = run_in(tmpdir, ARGS("run", write_config(name, text)));
	unsetenv("POCL_CACHE_DIR");
	cJSON *doc = load_results(cli_path_in(out));
	const cJSON *cl = find_run(doc, "s", "cl_lbvh", 1);
	const char *rays = run_str(cJSON_GetObjectItem(find_run(doc, "s", "lbvh", 1), "rays"), "error");
	bool failed = status == 1 && !strcmp(run_str(cl, "status"), "failed");
	snprintf(want, sizeof(want), "POCL_CACHE_DIR=%s is not a folder PoCL can use", cache);
	if (failed) {
		CHECK_CONTAINS(run_str(cl, "error"), want);
		CHECK_CONTAINS(rays, "device_stack: cl: ");
		CHECK_CONTAINS(rays, want);
		CHECK(!strchr(run_str(cl, "error"), '\n') && !strchr(rays, '\n'));
		/* The progress lines stay whole: the message and the time on one. */
		line_of(err_text, "s / cl_lbvh / 1 thread: failed", line, sizeof(line));
		CHECK_CONTAINS(line, want);
		CHECK_CONTAINS(line, " elapsed, ");
		line_of(err_text, "s / lbvh / 1 thread: ok", line, sizeof(line));
		CHECK_CONTAINS(line, want);
		CHECK_CONTAINS(line, " elapsed, ");
	}
	cJSON_Delete(doc);
	return failed;
}

/* 9. An unusable POCL_CACHE_DIR: a regular file (PoCL's kernel build fails,
 * its log ending in a newline) and a folder under one (PoCL offers no
 * device), each named as the likely cause. */
static void test_pocl(void)
{
	FILE *f = fopen(cli_path_in("not-a-folder"), "w");
	CHECK(f != NULL);
	if (f)
		fclose(f);
	run_in(tmpdir, ARGS("list")); /* exit 1: the fake plugins' broken ones */
	if (!strstr(out_text, "cl_lbvh")) {
		fprintf(stderr, "built without OpenCL: POCL_CACHE_DIR's messages not checked\n");
		return;
	}
	bool a = pocl_sweep("out-file", cli_path_in("not-a-folder"));
	bool b = pocl_sweep("out-under", cli_path_in("not-a-folder/cache"));
	CHECK_INT(run_in(tmpdir, ARGS("info", "--machine")), 0);
	/* Where every OpenCL device is PoCL's, both must have failed. */
	int pocl = count_of(out_text, "(Portable Computing Language)");
	if (pocl > 0 && pocl == count_of(out_text, " compute units, "))
		CHECK(a && b);
	else if (!a || !b)
		fprintf(stderr, "the OpenCL device ran despite POCL_CACHE_DIR (not PoCL): some "
		        "messages not checked\n");
}

int main(int argc, char **argv)
{
	static const struct cli_mode modes[] = {
		{"status", test_status},
		{"version", test_version},
		{"config", test_config},
		{"escape", test_escape},
		{"images", test_images},
		{"pocl", test_pocl},
	};
	return cli_main_modes(argc, argv, "test-cli-msg", modes, sizeof(modes) / sizeof(modes[0]));
}
