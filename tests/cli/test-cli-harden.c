/*
 * Hostile and careless input against `bvhlab run`, one mode per case of
 * issue 18, each a meson test of its own (cli-harden-MODE):
 *   fifo       a FIFO as a scene path is refused at once, before any output
 *   loadcrash  plugins that crash or hang while loading cost their runs only
 *   output     a folder with results is refused without --resume / --force
 *   symlink    nothing is written through a link planted in the output
 *   images     names that sanitise alike get images of their own, none hidden
 *   threads    one thread limit (1024) for config and command line
 *   search     bare NAME.so and the build tree's plugins/ are not loader magic
 *   resume     --resume refuses a results.json the config cannot have made
 *   limits     generator seeds are digits; memory-limit failures say so
 *   crashsafe  a kill between writing and renaming keeps the last results.json
 * Usage: test-cli-harden BVHLAB_EXE MODE
 */
#include <signal.h>
#include <sys/stat.h>

#include "cliutil.h"

#define LOADCRASH_DIR BVHLAB_TEST_BUILDDIR "/fake/loadcrash"
#define FAKE_DIR BVHLAB_TEST_BUILDDIR "/fake"
#define SHIM BVHLAB_TEST_BUILDDIR "/fake/shim/rename_fault.so"
static void path_in(char *buf, size_t size, const char *name)
{
	snprintf(buf, size, "%s/%s", tmpdir, name);
}

/* Config `text` written as `name`; its output folder `out` into dir (room
 * for 512). */
static const char *config_out(const char *name, const char *text, const char *out, char *dir)
{
	path_in(dir, 512, out);
	return write_config(name, text);
}

/* `bvhlab run --quiet` on config_out(name, text, out, dir), which must exit
 * with `status`: the results it wrote. */
static cJSON *run_config(const char *name, const char *text, int status, const char *out,
                         char *dir)
{
	CHECK_INT(run_in(NULL, ARGS("run", "--quiet", config_out(name, text, out, dir))), status);
	return load_results(dir);
}

static void check_run(const cJSON *doc, const char *scene, const char *builder, int threads,
                      const char *status, const char *error)
{
	const cJSON *r = find_run(doc, scene, builder, threads);
	if (!r) {
		fprintf(stderr, "no run %s / %s / %d\n", scene, builder, threads);
		test_failures++;
		return;
	}
	CHECK_CONTAINS(run_str(r, "status"), status);
	if (error)
		CHECK_CONTAINS(run_str(r, "error"), error);
}

/* 1. A FIFO named as a scene: refused at once (never waited on), the
 * config before its output folder exists. */
static void test_fifo(void)
{
	char fifo[512], dir[512];
	path_in(fifo, sizeof(fifo), "f.obj");
	CHECK_INT(mkfifo(fifo, 0644), 0);
	CHECK_INT(run_in(NULL, ARGS("info", fifo)), 2);
	CHECK_CONTAINS(err_text, "f.obj: not a regular file");
	CHECK_INT(run_in(NULL, ARGS("run", "--quiet", config_out("fifo.json",
		"{ \"output\": \"out-fifo\", \"repeat\": 1,\n"
		"  \"scenes\": [ { \"path\": \"f.obj\" }, { \"generator\": \"soup\", \"count\": 100 } ],\n"
		"  \"builders\": [ { \"plugin\": \"fake_good\" } ] }\n", "out-fifo", dir))), 2);
	CHECK_CONTAINS(err_text, "scene 'f': ");
	CHECK_CONTAINS(err_text, "f.obj: not a regular file");
	CHECK(access(dir, F_OK) != 0);
}

/* 2. Crashes and a hang while loading: recorded per run, the sweep goes on. */
static void test_loadcrash(void)
{
	char text[2048], dir[512];
	plain_crashes();
	snprintf(text, sizeof(text),
	         "{ \"output\": \"out-load\", \"repeat\": 1, \"threads\": [1, 2],\n"
	         "  \"scenes\": [ { \"generator\": \"soup\", \"count\": 100 } ],\n"
	         "  \"builders\": [ { \"plugin\": \"%s/crash_ctor.so\" },\n"
	         "    { \"plugin\": \"%s/crash_entry.so\" },\n"
	         "    { \"plugin\": \"%s/hang_entry.so\", \"timeout_s\": 1 },\n"
	         "    { \"plugin\": \"fake_good\" } ] }\n",
	         LOADCRASH_DIR, LOADCRASH_DIR, LOADCRASH_DIR);
	cJSON *doc = run_config("load.json", text, 1, "out-load", dir);
	/* A plugin that never loaded keeps all its runs (its flags are unknown);
	 * fake_good, not PARALLEL, runs at 1 thread only. */
	CHECK_INT(cJSON_GetArraySize(cJSON_GetObjectItem(doc, "runs")), 7);
	for (int t = 1; t <= 2; t++) {
		check_run(doc, "soup", "crash_ctor", t, "crashed", "killed by SIGSEGV");
		check_run(doc, "soup", "crash_entry", t, "crashed", "while loading");
		check_run(doc, "soup", "hang_entry", t, "timeout", "hung while loading");
	}
	check_run(doc, "soup", "fake_good", 1, "ok", NULL);
	cJSON_Delete(doc);
}

static const char small_config[] =
	"{ \"output\": \"%s\", \"repeat\": 1, \"threads\": [1],\n"
	"  \"scenes\": [ { \"generator\": \"soup\", \"count\": 100 } ],\n"
	"  \"builders\": [ { \"plugin\": \"fake_good\" } ] }\n";

/* 3. Earlier results are never replaced unasked. */
static void test_output(void)
{
	char text[1024], dir[512];
	snprintf(text, sizeof(text), small_config, "out-o");
	const char *cfg = write_config("o.json", text);
	path_in(dir, sizeof(dir), "out-o");
	CHECK_INT(run_in(NULL, ARGS("run", "--quiet", cfg)), 0);
	char *first = read_file(dir, "results.json");
	CHECK_INT(run_in(NULL, ARGS("run", "--quiet", cfg)), 2);
	CHECK_CONTAINS(err_text, "out-o already holds a results.json");
	CHECK_CONTAINS(err_text, "--resume");
	CHECK_CONTAINS(err_text, "--force");
	char *after = read_file(dir, "results.json");
	CHECK(first && after && !strcmp(first, after));
	CHECK_INT(run(ARGS("run", "--quiet", "--force", cfg)), 0);
	char *aside = read_file(dir, "results.json.1");
	CHECK(first && aside && !strcmp(first, aside));
	/* "output": "/" is refused in test-safe-file: a bvhlab without the check
	 * would write /results.json, as root. */
	free(first);
	free(after);
	free(aside);
}

static void plant(const char *dir, const char *name, const char *target)
{
	char path[1400];
	snprintf(path, sizeof(path), "%s/%s", dir, name);
	CHECK_INT(symlink(target, path), 0);
}

/* 4. Links planted where the harness writes: replaced, never followed. */
static void test_symlink(void)
{
	char text[1024], dir[512], images[600], precious[512];
	path_in(precious, sizeof(precious), "precious.txt");
	FILE *f = fopen(precious, "w");
	fputs("precious\n", f);
	fclose(f);
	path_in(dir, sizeof(dir), "out-link");
	snprintf(images, sizeof(images), "%s/images", dir);
	CHECK_INT(mkdir(dir, 0755), 0);
	CHECK_INT(mkdir(images, 0755), 0);
	plant(dir, ".results.json.tmp", precious);
	plant(dir, ".report.md.tmp", precious);
	plant(dir, ".heat-0-0.raw", precious);
	plant(images, "s.png", precious);
	plant(images, ".tmp-s.png", precious);
	snprintf(text, sizeof(text),
	         "{ \"output\": \"out-link\", \"repeat\": 1, \"images\": true,\n"
	         "  \"rays\": { \"width\": 8, \"height\": 8, \"diffuse\": 0 },\n"
	         "  \"scenes\": [ { \"name\": \"s\", \"generator\": \"soup\", \"count\": 200 } ],\n"
	         "  \"builders\": [ { \"plugin\": \"fake_good\" } ] }\n");
	CHECK_INT(run_in(NULL, ARGS("run", "--quiet", write_config("link.json", text))), 0);
	char *kept = read_file(tmpdir, "precious.txt");
	CHECK(kept && !strcmp(kept, "precious\n"));
	free(kept);
	struct stat st;
	char png[700];
	snprintf(png, sizeof(png), "%s/s.png", images);
	CHECK(lstat(png, &st) == 0 && S_ISREG(st.st_mode));
	cJSON *doc = load_results(dir);
	check_run(doc, "s", "fake_good", 1, "ok", NULL);
	cJSON_Delete(doc);
}

/* Every image name of the document, checked unique, visible and present. */
static void check_image_name(const char *dir, const char *name, const char **seen, int *n)
{
	char path[700];
	const char *base = strrchr(name, '/') ? strrchr(name, '/') + 1 : name;
	CHECK(*name && base[0] != '.');
	for (int k = 0; k < *n; k++)
		if (!strcmp(seen[k], name)) {
			fprintf(stderr, "image %s used twice\n", name);
			test_failures++;
		}
	seen[(*n)++] = name;
	snprintf(path, sizeof(path), "%s/%s", dir, name);
	CHECK(access(path, R_OK) == 0);
}

/* 5. Names that sanitise to the same file name get images of their own. */
static void test_images(void)
{
	static const char *const scenes[] = {"a b", "a_b", "a/b", "\xc3\xbc", "\xc3\xa9", ".hid"};
	char text[4096], dir[512];
	int n = snprintf(text, sizeof(text),
	                 "{ \"output\": \"out-img\", \"repeat\": 1, \"images\": true,\n"
	                 "  \"rays\": { \"width\": 8, \"height\": 8, \"diffuse\": 0 },\n"
	                 "  \"scenes\": [");
	for (int k = 0; k < 6; k++)
		n += snprintf(text + n, sizeof(text) - (size_t)n,
		              "%s { \"name\": \"%s\", \"generator\": \"soup\", \"count\": 100, "
		              "\"seed\": %d }", k ? "," : "", scenes[k], k);
	snprintf(text + n, sizeof(text) - (size_t)n,
	         " ],\n  \"builders\": [ { \"plugin\": \"fake_good\", \"name\": \"x y\" },\n"
	         "    { \"plugin\": \"fake_good\", \"name\": \"x_y\" } ] }\n");
	cJSON *doc = run_config("img.json", text, 0, "out-img", dir);
	const char *seen[64];
	int count = 0;
	const cJSON *s, *r;
	cJSON_ArrayForEach(s, cJSON_GetObjectItem(doc, "scenes"))
		check_image_name(dir, run_str(cJSON_GetObjectItem(s, "images"), "shaded"), seen, &count);
	cJSON_ArrayForEach(r, cJSON_GetObjectItem(doc, "runs"))
		check_image_name(dir, run_str(r, "heat_image"), seen, &count);
	CHECK_INT(count, 18);
	CHECK_INT(count_runs(doc, "x y", "ok"), 6);
	cJSON_Delete(doc);
}

/* 6. One thread limit, named, for the config and the command line. */
static void test_threads(void)
{
	char text[1024];
	snprintf(text, sizeof(text),
	         "{ \"output\": \"out-thr\", \"repeat\": 1, \"threads\": [4294967295],\n"
	         "  \"scenes\": [ { \"generator\": \"soup\", \"count\": 100 } ],\n"
	         "  \"builders\": [ { \"plugin\": \"fake_good\" } ] }\n");
	CHECK_INT(run_in(NULL, ARGS("run", "--quiet", write_config("thr.json", text))), 2);
	CHECK_CONTAINS(err_text, "'threads[0]' must be a non-negative integer up to 1024");
	snprintf(text, sizeof(text), small_config, "out-thr2");
	const char *cfg = write_config("thr2.json", text);
	CHECK_INT(run_in(NULL, ARGS("run", "--quiet", "--threads", "1,5000", cfg)), 2);
	CHECK_CONTAINS(err_text, "--threads: 5000 is more than the limit of 1024 threads");
	CHECK_INT(run_in(NULL, ARGS("run", "--quiet", "--threads", "1024", cfg)), 0);
}

/* 7. Plugin lookup owes nothing to the loader's search path or to a
 * build tree the binary does not run from. */
static void test_search(void)
{
	char bin[512], copy[600], cmd[1400];
	setenv("LD_LIBRARY_PATH", FAKE_DIR, 1);
	CHECK_INT(run_in(tmpdir, ARGS("build", "fake_good.so", "soup:count=10")), 2);
	CHECK_CONTAINS(err_text, "./fake_good.so");
	unsetenv("LD_LIBRARY_PATH");
	CHECK_INT(run_in(FAKE_DIR, ARGS("build", "fake_good.so", "soup:count=10")), 0);

	unsetenv("BVHLAB_PLUGIN_PATH");
	CHECK_INT(run_in(NULL, ARGS("build", "sah_seq", "soup:count=10")), 0);
	path_in(bin, sizeof(bin), "bin");
	snprintf(copy, sizeof(copy), "%s/bvhlab", bin);
	snprintf(cmd, sizeof(cmd), "mkdir -p '%s' && cp '%s' '%s'", bin, exe, copy);
	CHECK_INT(system(cmd), 0);
	const char *built = exe;
	exe = copy; /* as installed elsewhere: the build tree is not its own */
	CHECK_INT(run_in(NULL, ARGS("build", "sah_seq", "soup:count=10")), 2);
	CHECK_CONTAINS(err_text, "plugin 'sah_seq' not found");
	run_in(NULL, ARGS("list"));
	CHECK(!strstr(out_text, "sah_seq"));
	exe = built;
}

/* Writes `text` as dir/results.json, then resumes the sweep of cfg from it:
 * bvhlab's exit status. */
static int resume_from(const char *dir, const char *cfg, const char *text)
{
	char path[600];
	snprintf(path, sizeof(path), "%s/results.json", dir);
	FILE *f = fopen(path, "w");
	fputs(text, f);
	fclose(f);
	return run_in(NULL, ARGS("run", "--quiet", "--resume", cfg));
}

/* Runs --resume on a results.json edited by `edit`: refused, file as it was. */
static void refused(const char *dir, const char *cfg, const char *good, void (*edit)(cJSON *),
                    const char *message)
{
	cJSON *doc = cJSON_Parse(good);
	edit(cJSON_GetObjectItem(doc, "runs"));
	char *text = cJSON_Print(doc);
	CHECK_INT(resume_from(dir, cfg, text), 2);
	CHECK_CONTAINS(err_text, message);
	char *after = read_file(dir, "results.json");
	CHECK(after && !strcmp(after, text));
	free(after);
	free(text);
	cJSON_Delete(doc);
}

static cJSON *run0(cJSON *runs)
{
	return cJSON_GetArrayItem(runs, 0);
}

static void set_threads(cJSON *runs, double t)
{
	cJSON_ReplaceItemInObject(run0(runs), "threads", cJSON_CreateNumber(t));
}

static void duplicate(cJSON *runs)
{
	cJSON_AddItemToArray(runs, cJSON_Duplicate(run0(runs), 1));
}
static void foreign_scene(cJSON *runs)
{
	cJSON_ReplaceItemInObject(run0(runs), "scene", cJSON_CreateString("nope"));
}
static void negative(cJSON *runs)
{
	set_threads(runs, -1);
}
static void fraction(cJSON *runs)
{
	set_threads(runs, 2.5);
}
static void huge(cJSON *runs)
{
	set_threads(runs, 1e300);
}
static void wrong_type(cJSON *runs)
{
	cJSON_ReplaceItemInObject(run0(runs), "build_ms", cJSON_CreateString("fast"));
}
static void odd_status(cJSON *runs)
{
	cJSON_ReplaceItemInObject(run0(runs), "status", cJSON_CreateString("done?"));
}

/* 8. --resume takes only what this config could have written. */
static void test_resume(void)
{
	char dir[512];
	const char *cfg = config_out("res.json",
		"{ \"output\": \"out-res\", \"repeat\": 1, \"threads\": [1, 2],\n"
		"  \"scenes\": [ { \"generator\": \"soup\", \"count\": 100 } ],\n"
		"  \"builders\": [ { \"plugin\": \"fake_good\" } ] }\n", "out-res", dir);
	CHECK_INT(run_in(NULL, ARGS("run", "--quiet", cfg)), 0);
	char *good = read_file(dir, "results.json");
	if (!good)
		return;
	/* fake_good is not PARALLEL: its one run (at 1 thread) is runs[0], the copy runs[1]. */
	refused(dir, cfg, good, duplicate, "runs[1] (scene 'soup', builder 'fake_good') repeats");
	refused(dir, cfg, good, foreign_scene, "runs[0] (scene 'nope', builder 'fake_good') is not "
	        "a run of this config");
	refused(dir, cfg, good, negative, "runs[0] (scene 'soup', builder 'fake_good') \"threads\"");
	refused(dir, cfg, good, fraction, "runs[0] (scene 'soup', builder 'fake_good') \"threads\"");
	refused(dir, cfg, good, huge, "\"threads\" is not a whole number");
	refused(dir, cfg, good, wrong_type, "\"build_ms\" has the wrong type");
	refused(dir, cfg, good, odd_status, "\"status\" is none of");
	/* The untouched document still resumes. */
	CHECK_INT(resume_from(dir, cfg, good), 0);
	free(good);
}

/* 9. Seeds are digits; a memory limit names itself when it is what failed. */
static void test_limits(void)
{
	CHECK_INT(run_in(NULL, ARGS("info", "soup:count=10,seed=-1")), 2);
	CHECK_CONTAINS(err_text, "bad generator parameter 'seed=-1'");
#if defined(__SANITIZE_ADDRESS__) || defined(__SANITIZE_THREAD__)
	/* Sanitizers reserve terabytes of address space: no limit can apply. */
#else
	char dir[512];
	cJSON *doc = run_config("mem.json",
		"{ \"output\": \"out-mem\", \"repeat\": 1, \"memory_limit_mb\": 64,\n"
		"  \"scenes\": [ { \"generator\": \"icosphere\", \"frequency\": 300 },\n"
		"    { \"name\": \"fine\", \"generator\": \"icosphere\", \"frequency\": 10,\n"
		"      \"subdivide\": 7 } ],\n"
		"  \"builders\": [ { \"plugin\": \"fake_good\" } ] }\n", 1, "out-mem", dir);
	check_run(doc, "icosphere", "fake_good", 1, "failed", "memory_limit_mb = 64");
	/* Under a limit the probe subdivides too (33M triangles), so the
	 * parent never makes a scene the limit cannot hold. */
	check_run(doc, "fine", "fake_good", 1, "failed", "subdivide: out of memory splitting ");
	check_run(doc, "fine", "fake_good", 1, "failed", " (under memory_limit_mb = 64)");
	cJSON_Delete(doc);
#endif
}

/* A kill just before the Nth rename onto results.json (rename_fault.so). */
static int killed_at_rename(const char *cfg, const char *n, bool resume)
{
	setenv("BVHLAB_FAULT_RENAME", n, 1);
	setenv("LD_PRELOAD", SHIM, 1);
	/* ASan wants to come first in the library list; the shim is harmless. */
	const char *asan = getenv("ASAN_OPTIONS");
	char opts[512];
	snprintf(opts, sizeof(opts), "%s%sverify_asan_link_order=0", asan ? asan : "",
	         asan && *asan ? ":" : "");
	setenv("ASAN_OPTIONS", opts, 1);
	int status = resume ? run_in(NULL, ARGS("run", "--quiet", "--resume", cfg))
	                    : run_in(NULL, ARGS("run", "--quiet", cfg));
	unsetenv("LD_PRELOAD");
	unsetenv("BVHLAB_FAULT_RENAME");
	if (asan)
		setenv("ASAN_OPTIONS", asan, 1);
	return status;
}

/* 10. results.json is replaced whole or not at all. */
static void test_crashsafe(void)
{
	char dir[512];
	const char *cfg = config_out("crash.json",
		"{ \"output\": \"out-crash\", \"repeat\": 1,\n"
		"  \"scenes\": [ { \"name\": \"a\", \"generator\": \"soup\", \"count\": 100 },\n"
		"    { \"name\": \"b\", \"generator\": \"soup\", \"count\": 100, \"seed\": 2 },\n"
		"    { \"name\": \"c\", \"generator\": \"soup\", \"count\": 100, \"seed\": 3 } ],\n"
		"  \"builders\": [ { \"plugin\": \"fake_good\" } ] }\n", "out-crash", dir);
	/* Renames: 1 the empty document, 2 after the first run, 3 after the second. */
	CHECK_INT(killed_at_rename(cfg, "3", false), 128 + SIGKILL);
	CHECK_INT(runs_written(dir), 1);
	/* Killed again while resuming, before its first new run lands. */
	CHECK_INT(killed_at_rename(cfg, "2", true), 128 + SIGKILL);
	CHECK_INT(runs_written(dir), 1);
	CHECK_INT(run_in(NULL, ARGS("run", "--quiet", "--resume", cfg)), 0);
	CHECK_INT(runs_written(dir), 3);
}

int main(int argc, char **argv)
{
	static const struct cli_mode modes[] = {
		{"fifo", test_fifo},       {"loadcrash", test_loadcrash}, {"output", test_output},
		{"symlink", test_symlink}, {"images", test_images},       {"threads", test_threads},
		{"search", test_search},   {"resume", test_resume},       {"limits", test_limits},
		{"crashsafe", test_crashsafe},
	};
	return cli_main_modes(argc, argv, "test-cli-harden", modes, sizeof(modes) / sizeof(modes[0]));
}
