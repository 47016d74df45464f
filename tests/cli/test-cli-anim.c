/*
 * Animated scenes through the bvhlab command (docs/animation.md), one
 * mode per test:
 *   sweep   a composite with a moving and a waving part and an exploding
 *           mesh, four strategies (rebuild, refit, refit + reinsert, refit
 *           with a rebuild every 2 frames): every frame valid, the frames'
 *           rebuilt flags as the strategy says, brute-force rays on the
 *           first, middle and last frames, a rebuild's SAH the rebuild
 *           run's, refit's SAH rising on the explosion, cost_ms as modelled,
 *           the same figures for 1 and 2 refit threads, frames.csv and the
 *           reports' animation sections;
 *   files   frames from OBJ files: a good sequence, and a frame whose
 *           triangles differ, an error naming that file;
 *   errors  config mistakes named at their key; an update plugin without
 *           an update function;
 *   kill    an animated sweep killed with SIGKILL mid-way, then --resume:
 *           no finished run lost, none run again.
 */
#include <math.h>

#include "cliutil.h"

static const cJSON *frame(const cJSON *run, int f)
{
	return cJSON_GetArrayItem(cJSON_GetObjectItem(run, "frames"), f);
}

static double fnum(const cJSON *run, int f, const char *key)
{
	const cJSON *v = cJSON_GetObjectItem(frame(run, f), key);
	return cJSON_IsNumber(v) ? v->valuedouble : NAN;
}

static bool fflag(const cJSON *run, int f, const char *key)
{
	return cJSON_IsTrue(cJSON_GetObjectItem(frame(run, f), key));
}

/* Every frame valid, ok, cost as modelled for `rays` rays per frame,
 * rebuilt where `rebuilt` has '1'. */
static void check_frames_for(const cJSON *run, const char *rebuilt, double rays)
{
	int n = (int)strlen(rebuilt);
	CHECK(run != NULL);
	if (!run)
		return;
	CHECK(!strcmp(run_str(run, "status"), "ok"));
	CHECK_INT(cJSON_GetArraySize(cJSON_GetObjectItem(run, "frames")), (int)strlen(rebuilt));
	for (int f = 0; rebuilt[f]; f++) {
		double mrays = fnum(run, f, "mrays_per_s"), update = fnum(run, f, "update_ms");
		CHECK_INT(fnum(run, f, "frame"), f);
		CHECK(fflag(run, f, "valid"));
		CHECK_INT(fflag(run, f, "rebuilt"), rebuilt[f] == '1');
		/* Brute-force rays on the first, middle and last frames. */
		CHECK_INT(fflag(run, f, "rays_checked"), f == 0 || f == (n - 1) / 2 || f == n - 1);
		CHECK(fnum(run, f, "sah") >= 1 && fnum(run, f, "nodes_per_ray") > 0 && mrays > 0);
		CHECK(fabs(fnum(run, f, "cost_ms") - (update + rays / (mrays * 1e3))) <
		      1e-6 * (1 + fnum(run, f, "cost_ms")));
	}
}

/* The same with the default rays_per_frame. */
static void check_frames(const cJSON *run, const char *rebuilt)
{
	check_frames_for(run, rebuilt, 1e6);
}

static const char sweep_config[] =
	"{ \"output\": \"out-anim\", \"repeat\": 1, \"warmup\": 0, \"threads\": [1],\n"
	"  \"rays\": { \"width\": 16, \"height\": 16, \"min_ms\": 1, \"rounds\": 1 },\n"
	"  \"rays_per_frame\": 1000,\n"
	"  \"scenes\": [ { \"name\": \"yard\", \"frames\": 4, \"parts\": [\n"
	"      { \"generator\": \"terrain\", \"size\": 8 },\n"
	"      { \"generator\": \"icosphere\", \"frequency\": 3, \"scale\": 0.2,\n"
	"        \"translate\": [0, 0.5, 0],\n"
	"        \"animate\": { \"translate\": [0.6, 0, 0], \"rotate\": [0, 90, 0], \"scale\": 1.5 } },\n"
	"      { \"generator\": \"icosphere\", \"frequency\": 3, \"scale\": 0.3,\n"
	"        \"deform\": \"wave\", \"amplitude\": 0.1 } ] },\n"
	"    { \"name\": \"boom\", \"generator\": \"icosphere\", \"frequency\": 6, \"frames\": 4,\n"
	"      \"deform\": \"explode\" } ],\n"
	"  \"builders\": [ { \"plugin\": \"lbvh\" },\n"
	"    { \"plugin\": \"lbvh\", \"threads\": [1, 2], \"animation\": { \"update\": \"refit\" } },\n"
	"    { \"plugin\": \"lbvh\", \"animation\": { \"update\": \"refit\",\n"
	"        \"refine\": [ { \"plugin\": \"reinsert\" } ] } },\n"
	"    { \"plugin\": \"lbvh\",\n"
	"      \"animation\": { \"update\": \"refit\", \"rebuild_every\": 2 } } ] }\n";

static void check_scene(const cJSON *doc, const char *scene)
{
	const cJSON *lbvh = find_run(doc, scene, "lbvh", 1);
	const cJSON *refit = find_run(doc, scene, "lbvh+refit", 1);
	const cJSON *refit2 = find_run(doc, scene, "lbvh+refit", 2);
	const cJSON *every = find_run(doc, scene, "lbvh+refit[rebuild_every=2]", 1);
	check_frames_for(lbvh, "1111", 1000);
	check_frames_for(refit, "1000", 1000);
	check_frames_for(refit2, "1000", 1000);
	check_frames_for(find_run(doc, scene, "lbvh+refit+reinsert", 1), "1000", 1000);
	check_frames_for(every, "1010", 1000);
	if (!lbvh || !refit || !refit2 || !every)
		return;
	/* Frame 0 is everyone's build; a rebuild is lbvh's tree; refit is
	 * deterministic: its threads change no figure of the trees. */
	CHECK(fnum(refit, 0, "sah") == fnum(lbvh, 0, "sah"));
	CHECK(fnum(every, 2, "sah") == fnum(lbvh, 2, "sah"));
	for (int f = 0; f < 4; f++) {
		CHECK(fnum(refit, f, "sah") == fnum(refit2, f, "sah"));
		CHECK(fnum(refit, f, "nodes_per_ray") == fnum(refit2, f, "nodes_per_ray"));
	}
}

static void test_sweep(void)
{
	char dir[512];
	snprintf(dir, sizeof(dir), "%s/out-anim", tmpdir);
	CHECK_INT(run(ARGS("run", "--quiet", write_config("anim.json", sweep_config))), 0);
	cJSON *doc = load_results(dir);
	if (!doc)
		return;
	CHECK_INT(cJSON_GetArraySize(cJSON_GetObjectItem(doc, "runs")), 10);
	check_scene(doc, "yard");
	check_scene(doc, "boom");
	/* Triangles flying apart: refit's boxes grow, a rebuild's do not. */
	const cJSON *lbvh = find_run(doc, "boom", "lbvh", 1);
	const cJSON *refit = find_run(doc, "boom", "lbvh+refit", 1);
	CHECK(fnum(refit, 3, "sah") > 2 * fnum(refit, 0, "sah"));
	CHECK(fnum(refit, 3, "sah") > 2 * fnum(lbvh, 3, "sah"));
	cJSON_Delete(doc);
	char *csv = read_file(dir, "frames.csv"), *md = read_file(dir, "report.md");
	char *html = read_file(dir, "report.html");
	int lines = 0;
	for (const char *p = csv; p && *p; p++)
		lines += *p == '\n';
	CHECK_INT(lines, 1 + 10 * 4);
	CHECK_CONTAINS(csv, "scene,builder,plugin,threads,frame,rebuilt,valid,update_ms,sah,");
	CHECK_CONTAINS(csv, "\nboom,lbvh+refit[rebuild_every=2],lbvh,1,2,true,true,");
	CHECK_CONTAINS(md, "### Animation");
	CHECK_CONTAINS(md, "**Cheapest over the animation: ");
	CHECK_CONTAINS(html, "SAH over the frames, 2 threads");
	CHECK_CONTAINS(html, "Cumulative modelled cost, 1 thread");
	free(csv);
	free(md);
	free(html);
}

/* A quad of two triangles at height z; `swap` joins its corners otherwise. */
static void write_frame(const char *name, double z, bool swap)
{
	char path[600];
	snprintf(path, sizeof(path), "%s/%s", tmpdir, name);
	FILE *f = fopen(path, "w");
	CHECK(f != NULL);
	if (!f)
		return;
	fprintf(f, "v 0 0 %g\nv 1 0 %g\nv 1 1 %g\nv 0 1 %g\n", z, z, 2 * z, z);
	fprintf(f, swap ? "f 1 2 4\nf 2 3 4\n" : "f 1 2 3\nf 1 3 4\n");
	fclose(f);
}

static void test_files(void)
{
	static const char text[] =
		"{ \"output\": \"out-files\", \"repeat\": 1, \"warmup\": 0,\n"
		"  \"rays\": { \"width\": 8, \"height\": 8, \"min_ms\": 1, \"rounds\": 1 },\n"
		"  \"scenes\": [ { \"name\": \"quad\", \"frames\": { \"pattern\": \"f%%03d.obj\", "
		"\"count\": %d } } ],\n"
		"  \"builders\": [ { \"plugin\": \"lbvh\", \"animation\": { \"update\": \"refit\" } } ] }\n";
	char cfg[1024], dir[512];
	snprintf(dir, sizeof(dir), "%s/out-files", tmpdir);
	for (int k = 0; k < 4; k++) {
		char name[32];
		snprintf(name, sizeof(name), "f%03d.obj", k);
		write_frame(name, 0.25 * k, k == 3);
	}
	snprintf(cfg, sizeof(cfg), text, 3);
	CHECK_INT(run(ARGS("run", "--quiet", write_config("files.json", cfg))), 0);
	cJSON *doc = load_results(dir);
	if (doc)
		check_frames(find_run(doc, "quad", "lbvh+refit", 1), "100");
	cJSON_Delete(doc);
	/* Frame 3 joins the same corners into other triangles. */
	snprintf(cfg, sizeof(cfg), text, 4);
	CHECK_INT(run(ARGS("run", "--quiet", "--force", write_config("files.json", cfg))), 1);
	doc = load_results(dir);
	const cJSON *r = doc ? find_run(doc, "quad", "lbvh+refit", 1) : NULL;
	CHECK(r && !strcmp(run_str(r, "status"), "failed"));
	CHECK_CONTAINS(run_str(r, "error"), "f003.obj: frame 3 of scene 'quad' has other triangles");
	CHECK_CONTAINS(run_str(r, "error"), "keep their topology");
	cJSON_Delete(doc);
}

static void config_error(const char *scene, const char *builder, const char *message)
{
	char text[1024];
	snprintf(text, sizeof(text), "{ \"output\": \"out-err\", \"scenes\": [ %s ],\n"
	         "  \"builders\": [ %s ] }\n", scene, builder);
	CHECK_INT(run(ARGS("run", write_config("err.json", text))), 2);
	CHECK_CONTAINS(err_text, message);
}

static void test_errors(void)
{
	const char *ico = "{ \"generator\": \"icosphere\", \"frames\": 3 }";
	const char *lbvh = "{ \"plugin\": \"lbvh\" }";
	config_error("{ \"generator\": \"icosphere\", \"frames\": 3, \"deform\": \"melt\" }", lbvh,
	             "err.json:1:87: 'scenes[0].deform' must be \"wave\" or \"explode\", not \"melt\"");
	config_error("{ \"generator\": \"icosphere\", \"deform\": \"wave\" }", lbvh,
	             "'scenes[0]' moves ('animate' or 'deform') but has no 'frames'");
	config_error("{ \"generator\": \"icosphere\", \"frames\": 0 }", lbvh,
	             "'scenes[0].frames' must be a whole number of frames from 1 to 100000");
	config_error("{ \"frames\": { \"pattern\": \"f.obj\", \"count\": 2 } }", lbvh,
	             "'scenes[0].frames.pattern' must hold exactly one %d");
	config_error("{ \"generator\": \"icosphere\", \"frames\": 2, \"amplitude\": 0.1 }", lbvh,
	             "'scenes[0].amplitude' applies to a 'deform' only");
	config_error("{ \"parts\": [ { \"generator\": \"icosphere\", \"animate\": "
	             "{ \"spin\": 1 } } ], \"frames\": 2 }", lbvh,
	             "unknown key 'spin' in scenes[0].parts[0].animate");
	config_error(ico, "{ \"plugin\": \"lbvh\", \"animation\": { \"rebuild_every\": 2 } }",
	             "'builders[0].animation' needs an 'update'");
	/* A plugin without an update function is a config error, before any run. */
	char text[1024];
	snprintf(text, sizeof(text), "{ \"output\": \"out-noupd\", \"repeat\": 1, \"warmup\": 0,\n"
	         "  \"rays\": { \"width\": 8, \"height\": 8, \"min_ms\": 1, \"rounds\": 1 },\n"
	         "  \"scenes\": [ %s ],\n"
	         "  \"builders\": [ { \"plugin\": \"sah_seq\", \"animation\": { \"update\": "
	         "\"lbvh\" } } ] }\n", ico);
	CHECK_INT(run(ARGS("run", write_config("noupd.json", text))), 2);
	CHECK_CONTAINS(err_text, "animation update: plugin 'lbvh' has no update function (ABI 1.4)");
	snprintf(text, sizeof(text), "%s/out-noupd", tmpdir);
	CHECK(access(text, F_OK) != 0);
}

/* Two animated scenes, the "gated" builder on both (struct kill_sweep). */
static const char kill_config[] =
	"{ \"output\": \"out-kill\", \"repeat\": 1, \"warmup\": 0, \"threads\": [1],\n"
	"  \"rays\": { \"min_ms\": 1, \"width\": 8, \"height\": 8, \"rounds\": 1 },\n"
	"  \"scenes\": [ { \"name\": \"a\", \"generator\": \"soup\", \"count\": 200,\n"
	"      \"frames\": 3, \"deform\": \"explode\" },\n"
	"    { \"name\": \"b\", \"generator\": \"icosphere\", \"frequency\": 4,\n"
	"      \"frames\": 2, \"deform\": \"wave\" } ],\n"
	"  \"builders\": [ { \"plugin\": \"sah_seq\", \"threads\": [1],\n"
	"      \"animation\": { \"update\": \"refit\" } },\n"
	"    { \"plugin\": \"fake_good\", \"name\": \"gated\",\n"
	"      \"options\": { \"wait_for\": \"%s\" } } ] }\n";

static void test_kill(void)
{
	struct kill_sweep k;
	CHECK_INT(kill_sweep_start(&k, kill_config), 1);
	cJSON *doc = load_results(k.dir);
	const cJSON *first = doc ? find_run(doc, "a", "sah_seq+refit", 1) : NULL;
	check_frames(first, "100");
	char *frames = run_item_text(first, "frames");
	cJSON_Delete(doc);
	CHECK_INT(kill_sweep_resume(&k), 0);
	CHECK_CONTAINS(err_text, "1 finished run kept");
	doc = load_results(k.dir);
	if (doc) {
		CHECK_INT(cJSON_GetArraySize(cJSON_GetObjectItem(doc, "runs")), 4);
		first = find_run(doc, "a", "sah_seq+refit", 1);
		char *again = run_item_text(first, "frames");
		CHECK(frames && again && !strcmp(frames, again)); /* kept, not run again */
		CHECK_INT(count_runs(doc, "gated", "ok"), 2);
		check_frames(find_run(doc, "b", "gated", 1), "11");
		free(again);
		cJSON_Delete(doc);
	}
	free(frames);
}

int main(int argc, char **argv)
{
	if (!cli_begin(argc, argv))
		return 2;
	const char *mode = argv[2];
	if (!strcmp(mode, "sweep"))
		test_sweep();
	else if (!strcmp(mode, "files"))
		test_files();
	else if (!strcmp(mode, "errors"))
		test_errors();
	else if (!strcmp(mode, "kill"))
		test_kill();
	else
		return 2;
	return cli_end();
}
