/*
 * Issue 43's identity cases (1, 2, 3, 6), one mode each, meson tests
 * cli-rel-MODE:
 *   rerun      --resume makes again every run whose scene (count,
 *              subdivide), builder (its animation) or measurement (rays,
 *              repeat, rays_per_frame) changed, saying why; each run keeps
 *              the config fragment it was made with; runs at a thread count
 *              no longer made are dropped
 *   planpaths  a plan in a deep folder of a composite and a frame-file
 *              scene runs every part; a frame changed after planning is
 *              refused; plan --missing gives failed runs again
 *   subcfg     a frame pattern in sub/cfg.json is resolved once
 *   animcheck  a bad update plugin, refine option or an animation beside a
 *              static scene is exit 2 before any folder, for run and plan
 * Usage: test-cli-ident BVHLAB_EXE MODE
 */
#include <sys/stat.h>

#include "cliutil.h"

/* A quad of two triangles at height z (the same topology in every frame). */
static void write_frame(const char *name, double z)
{
	FILE *f = fopen(cli_path_in(name), "w");
	CHECK(f != NULL);
	if (!f)
		return;
	fprintf(f, "v 0 0 %g\nv 1 0 %g\nv 1 1 %g\nv 0 1 %g\nf 1 2 3\nf 1 3 4\n", z, z, 2 * z, z);
	fclose(f);
}

/* out-r/results.json's run of builder on scene s at 1 thread: its member
 * key's member sub as text ("" when missing; a static buffer). */
static const char *member_text(const char *builder, const char *key, const char *sub)
{
	static char text[512];
	cJSON *doc = load_results(cli_path_in("out-r"));
	const cJSON *run = doc ? find_run(doc, "s", builder, 1) : NULL;
	const cJSON *v = cJSON_GetObjectItem(cJSON_GetObjectItem(run, key), sub);
	char *t = v ? cJSON_PrintUnformatted(v) : NULL;
	snprintf(text, sizeof(text), "%s", t ? t : "");
	free(t);
	cJSON_Delete(doc);
	return text;
}

/* The rerun config: scene `scene`, builders A (and B when `two`), `more`
 * top-level members. */
static const char *rerun_config(const char *scene, const char *anim, const char *more)
{
	char text[2048];
	snprintf(text, sizeof(text),
	         "{ \"output\": \"out-r\", \"warmup\": 0, %s\n"
	         "  \"scenes\": [ { \"name\": \"s\", %s } ],\n"
	         "  \"builders\": [ { \"plugin\": \"lbvh\", \"name\": \"A\"%s } ] }\n",
	         more, scene, anim);
	return write_config("rerun.json", text);
}

static int resume(const char *cfg)
{
	return run_in(tmpdir, ARGS("run", "--resume", cfg));
}

static void test_rerun(void)
{
	static const char rays[] = "\"repeat\": 1, \"rays\": { \"width\": 8, \"height\": 8, "
	                           "\"min_ms\": 1, \"rounds\": 1 },";
	static const char soup[] = "\"generator\": \"soup\", \"count\": 100";
	CHECK_INT(run_in(tmpdir, ARGS("run", "--quiet", rerun_config(soup, "", rays))), 0);
	CHECK_INT(resume(rerun_config(soup, "", rays)), 0);
	CHECK_CONTAINS(err_text, "1 finished run kept");
	CHECK(!strstr(err_text, "rerun"));
	/* The scene: count and subdivide. */
	CHECK_INT(resume(rerun_config("\"generator\": \"soup\", \"count\": 500, \"subdivide\": 1",
	                              "", rays)), 0);
	CHECK_CONTAINS(err_text, "1 run rerun: scene 's' changed");
	CHECK_INT(atoi(member_text("A", "tree", "refs")), 2000);
	CHECK_CONTAINS(member_text("A", "config", "scene"), "\"count\":500,\"subdivide\":1");
	/* The measurement: rays, then repeat. */
	static const char scene[] = "\"generator\": \"soup\", \"count\": 500, \"subdivide\": 1";
	CHECK_INT(resume(rerun_config(scene, "", "\"repeat\": 1, \"rays\": { \"width\": 4, "
	                              "\"height\": 4, \"min_ms\": 1, \"rounds\": 1 },")), 0);
	CHECK_CONTAINS(err_text, "1 run rerun: measurement settings changed");
	CHECK_INT(resume(rerun_config(scene, "", "\"repeat\": 2, \"rays\": { \"width\": 4, "
	                              "\"height\": 4, \"min_ms\": 1, \"rounds\": 1 },")), 0);
	CHECK_CONTAINS(err_text, "1 run rerun: measurement settings changed");
	cJSON *samples = cJSON_Parse(member_text("A", "build_ms", "samples"));
	CHECK_INT(cJSON_GetArraySize(samples), 2);
	cJSON_Delete(samples);
	CHECK_CONTAINS(member_text("A", "config", "measure"), "\"repeat\":2");

	/* An animated scene: the animation block, then rays_per_frame. */
	static const char anim_scene[] = "\"generator\": \"soup\", \"count\": 100, \"frames\": 3, "
	                                 "\"deform\": \"wave\"";
	static const char refit[] = ", \"animation\": { \"update\": \"refit\" }";
	static const char every[] = ", \"animation\": { \"update\": \"refit\", \"rebuild_every\": 2 }";
	CHECK_INT(run_in(tmpdir, ARGS("run", "--quiet", "--force",
	                              rerun_config(anim_scene, refit, rays))), 0);
	CHECK_INT(resume(rerun_config(anim_scene, every, rays)), 0);
	CHECK_CONTAINS(err_text, "1 run rerun: builder 'A' changed");
	CHECK_CONTAINS(member_text("A", "config", "builder"), "\"rebuild_every\":2");
	CHECK_INT(resume(rerun_config(anim_scene, every, "\"rays_per_frame\": 1, \"repeat\": 1, "
	                              "\"rays\": { \"width\": 8, \"height\": 8, \"min_ms\": 1, "
	                              "\"rounds\": 1 },")), 0);
	CHECK_CONTAINS(err_text, "1 run rerun: measurement settings changed");
	CHECK_CONTAINS(member_text("A", "config", "measure"), "\"rays_per_frame\":1");
	CHECK(strlen(member_text("A", "identity", "hash")) == 18); /* 16 digits, quoted */

	/* A thread count dropped from the config: its runs dropped, the others
	 * kept (a plugin unknown then, now serial, drops its runs alike). */
	static const char two[] = "\"threads\": [1, 2], \"repeat\": 1, \"rays\": { \"width\": 4, "
	                          "\"height\": 4, \"min_ms\": 1, \"rounds\": 1 },";
	CHECK_INT(run_in(tmpdir, ARGS("run", "--quiet", "--force", rerun_config(soup, "", two))), 0);
	CHECK_INT(resume(rerun_config(soup, "", two + strlen("\"threads\": [1, 2],"))), 0);
	CHECK_CONTAINS(err_text, "1 finished run kept\n");
	CHECK_CONTAINS(err_text, "1 run dropped: made at a thread count its builder no longer runs");
	cJSON *doc = load_results(cli_path_in("out-r"));
	CHECK_INT(cJSON_GetArraySize(cJSON_GetObjectItem(doc, "runs")), 1);
	CHECK(find_run(doc, "s", "A", 1) != NULL);
	cJSON_Delete(doc);
}

/* A composite of two mesh parts and a frame-file scene, planned into a deep
 * folder; every part's run must find its files. */
static void test_planpaths(void)
{
	static const char text[] =
		"{ \"repeat\": 1, \"warmup\": 0,\n"
		"  \"rays\": { \"width\": 8, \"height\": 8, \"min_ms\": 1, \"rounds\": 1 },\n"
		"  \"scenes\": [ { \"name\": \"comp\", \"parts\": [ { \"path\": \"m/a.obj\" },\n"
		"      { \"path\": \"m/b.obj\", \"translate\": [3, 0, 0] } ] },\n"
		"    { \"name\": \"walk\", \"frames\": { \"pattern\": \"m/f%03d.obj\", \"count\": 3 } } ],\n"
		"  \"builders\": [ { \"plugin\": \"lbvh\", \"animation\": { \"update\": \"refit\", "
		"\"allow_static\": true } },\n"
		"    { \"plugin\": \"fake_good\", \"options\": { \"fail\": \"error\" } } ] }\n";
	mkdir(cli_path_in("m"), 0755);
	write_frame("m/a.obj", 0);
	write_frame("m/b.obj", 1);
	for (int k = 0; k < 3; k++) {
		char name[32];
		snprintf(name, sizeof(name), "m/f%03d.obj", k);
		write_frame(name, 0.5 * k);
	}
	const char *cfg = write_config("paths.json", text);
	CHECK_INT(run_in(tmpdir, ARGS("plan", cfg, "--out", "d1/d2/d3/sweep")), 0);
	char plan[600];
	snprintf(plan, sizeof(plan), "%s", cli_path_in("d1/d2/d3/sweep/plan.json"));
	for (int id = 0; id < 4; id++) {
		char ids[8], out[64];
		snprintf(ids, sizeof(ids), "%d", id);
		snprintf(out, sizeof(out), "d1/d2/d3/sweep/parts/%d", id);
		CHECK_INT(run_in(cli_path_in("d1"), ARGS("run", plan, "--only", ids, "--out",
		                                     cli_path_in(out), "--quiet")), id % 2);
	}
	CHECK_INT(run_in(cli_path_in("d1/d2/d3/sweep"), ARGS("merge", "parts/0", "parts/1", "parts/2",
	                                                 "parts/3", "--out", ".")), 1);
	cJSON *doc = load_results(cli_path_in("d1/d2/d3/sweep"));
	CHECK_INT(count_runs(doc, "lbvh+refit", "ok"), 2);
	CHECK_INT(count_runs(doc, "fake_good", "failed"), 2);
	cJSON_Delete(doc);
	/* plan --missing: the failed runs (1, 3) are not done. */
	CHECK_INT(run_in(tmpdir, ARGS("plan", "--missing", cli_path_in("d1/d2/d3/sweep"))), 0);
	CHECK_CONTAINS(out_text, "--only 1 ");
	CHECK_CONTAINS(out_text, "--only 3 ");
	CHECK(!strstr(out_text, "--only 0 ") && !strstr(out_text, "--only 2 "));
	CHECK_CONTAINS(out_text, "--retry-failed");
	/* The last frame changed after planning: its runs are refused. */
	write_frame("m/f002.obj", 7);
	CHECK_INT(run_in(tmpdir, ARGS("run", plan, "--only", "2", "--out",
	                              cli_path_in("d1/d2/d3/sweep/parts/9"), "--quiet")), 2);
	CHECK_CONTAINS(err_text, "f002.obj has changed since planning");
	CHECK(!cli_exists(cli_path_in("d1/d2/d3/sweep/parts/9")));
}

static void test_subcfg(void)
{
	static const char text[] =
		"{ \"output\": \"out\", \"repeat\": 1, \"warmup\": 0,\n"
		"  \"rays\": { \"width\": 8, \"height\": 8, \"min_ms\": 1, \"rounds\": 1 },\n"
		"  \"scenes\": [ { \"frames\": { \"pattern\": \"fr/ok%03d.obj\", \"count\": 4 } } ],\n"
		"  \"builders\": [ { \"plugin\": \"lbvh\", \"animation\": { \"update\": \"refit\" } } ] }\n";
	mkdir(cli_path_in("sub"), 0755);
	mkdir(cli_path_in("sub/fr"), 0755);
	for (int k = 0; k < 4; k++) {
		char name[32];
		snprintf(name, sizeof(name), "sub/fr/ok%03d.obj", k);
		write_frame(name, 0.25 * k);
	}
	FILE *f = fopen(cli_path_in("sub/cfg.json"), "w");
	CHECK(f != NULL);
	if (f) {
		fputs(text, f);
		fclose(f);
	}
	CHECK_INT(run_in(tmpdir, ARGS("run", "--quiet", "sub/cfg.json")), 0);
	cJSON *doc = load_results(cli_path_in("sub/out"));
	CHECK_INT(count_runs(doc, "lbvh+refit", "ok"), 1);
	const cJSON *run = cJSON_GetArrayItem(cJSON_GetObjectItem(doc, "runs"), 0);
	CHECK_INT(cJSON_GetArraySize(cJSON_GetObjectItem(run, "frames")), 4);
	cJSON_Delete(doc);
}

/* A config of one animated scene (and `more` scenes) and builder `b`:
 * run and plan both refuse it with `message`, making no folder. */
static void refused(const char *more, const char *b, const char *message)
{
	char text[2048];
	snprintf(text, sizeof(text),
	         "{ \"output\": \"out-a\", \"repeat\": 1,\n"
	         "  \"scenes\": [ { \"name\": \"w\", \"generator\": \"soup\", \"count\": 50, "
	         "\"frames\": 2, \"deform\": \"wave\" }%s ],\n"
	         "  \"builders\": [ { \"plugin\": \"lbvh\", \"animation\": %s } ] }\n", more, b);
	const char *cfg = write_config("anim.json", text);
	CHECK_INT(run_in(tmpdir, ARGS("run", cfg)), 2);
	CHECK_CONTAINS(err_text, message);
	CHECK(!cli_exists(cli_path_in("out-a")));
	CHECK_INT(run_in(tmpdir, ARGS("plan", cfg, "--out", "plan-a")), 2);
	CHECK_CONTAINS(err_text, message);
	CHECK(!cli_exists(cli_path_in("plan-a")));
}

static void test_animcheck(void)
{
	refused("", "{ \"update\": \"nonexistent_plugin\" }",
	        "builder 'lbvh+nonexistent_plugin': animation update: plugin 'nonexistent_plugin' "
	        "not found");
	refused("", "{ \"update\": \"lbvh\" }",
	        "animation update: plugin 'lbvh' has no update function");
	refused("", "{ \"update\": \"refit\", \"refine\": [ { \"plugin\": \"reinsert\", "
	        "\"options\": { \"bogus\": 1 } } ] }",
	        "builder 'lbvh+refit+reinsert, animation refine stage 1 (reinsert)': unknown "
	        "option 'bogus'");
	refused("", "{ \"update\": \"refit\", \"refine\": [ { \"plugin\": \"lbvh\" } ] }",
	        "animation refine stage 1: plugin 'lbvh' has no refinement stage");
	refused(", { \"name\": \"still\", \"generator\": \"soup\", \"count\": 50 }",
	        "{ \"update\": \"refit\" }",
	        "scene 'still' (scenes[1]) is static (no 'frames'), where the animation would be "
	        "ignored");
}

int main(int argc, char **argv)
{
	static const struct cli_mode modes[] = {
		{"rerun", test_rerun}, {"planpaths", test_planpaths}, {"subcfg", test_subcfg},
		{"animcheck", test_animcheck}};
	return cli_main_modes(argc, argv, "test-cli-ident", modes, sizeof(modes) / sizeof(modes[0]));
}
