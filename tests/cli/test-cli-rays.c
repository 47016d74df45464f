/*
 * Rays, images and reports through the bvhlab command: a run with images
 * writes report.html naming every run, with charts and PNGs of the asked
 * size that are not blank; `bvhlab report` regenerates it; `bvhlab render`
 * writes one image; a bad camera is an error with its position; ray
 * timings come from the interleaved rounds (rays.rounds), isolated or not,
 * and leave no tree file behind.
 * Usage: test-cli-rays BVHLAB_EXE all
 */
#include <dirent.h>
#include <stdint.h>
#include <sys/stat.h>

#include "cliutil.h"
#include "output/image.h"

static const char config[] =
	"{ \"format_version\": 1, \"output\": \"out-rays\", \"repeat\": 1, \"threads\": [1, 2],\n"
	"  \"images\": true, \"rays\": { \"width\": 40, \"height\": 30, \"diffuse\": 2,\n"
	"    \"min_ms\": 1, \"traversal\": [\"wide\", \"stack\", \"stackless\"],\n"
	"    \"kinds\": [\"primary\", \"diffuse\", \"shadow\", \"ao\"], \"ao_length\": 0.1 },\n"
	"  \"scenes\": [ { \"name\": \"ico<1>\", \"generator\": \"icosphere\", \"frequency\": 10 },\n"
	"              { \"name\": \"terrain\", \"generator\": \"terrain\", \"size\": 16 } ],\n"
	"  \"builders\": [ { \"plugin\": \"sah_seq\", \"name\": \"sweep\" },\n"
	"                { \"plugin\": \"sah_seq\", \"name\": \"binned\",\n"
	"                  \"options\": { \"method\": \"binned\" } } ] }\n";

/* PNG header: width and height at bytes 16..23, big-endian. */
static bool png_size(const char *dir, const char *name, uint32_t *w, uint32_t *h)
{
	char path[600];
	unsigned char b[24];
	snprintf(path, sizeof(path), "%s/%s", dir, name);
	FILE *f = fopen(path, "rb");
	bool ok = f && fread(b, 1, 24, f) == 24 && !memcmp(b + 1, "PNG", 3);
	if (f)
		fclose(f);
	if (ok) {
		*w = (uint32_t)b[16] << 24 | (uint32_t)b[17] << 16 | (uint32_t)b[18] << 8 | b[19];
		*h = (uint32_t)b[20] << 24 | (uint32_t)b[21] << 16 | (uint32_t)b[22] << 8 | b[23];
	}
	return ok;
}

/* Not blank: decoded through OpenImageIO, more than 1% of the pixels differ
 * from the first one (a render shows geometry on a background, a heat map
 * and a legend show a range of colours). */
static void check_not_blank(const char *dir, const char *name)
{
	char path[600];
	int w = 0, h = 0;
	uint8_t *rgb = NULL;
	bvhlab_error err = {{0}};
	snprintf(path, sizeof(path), "%s/%s", dir, name);
	CHECK_INT(image_read_rgb8(path, &w, &h, &rgb, &err), 0);
	size_t differ = 0, n = (size_t)w * (size_t)h;
	for (size_t k = 1; rgb && k < n; k++)
		differ += memcmp(rgb + 3 * k, rgb, 3) != 0;
	if (differ * 100 <= n)
		fprintf(stderr, "%s: only %zu of %zu pixels differ from the first\n", path, differ, n);
	CHECK(differ * 100 > n);
	free(rgb);
}

static void check_image(const char *dir, const char *name, uint32_t w, uint32_t h)
{
	uint32_t gw = 0, gh = 0;
	if (!png_size(dir, name, &gw, &gh))
		fprintf(stderr, "missing or not a PNG: %s/%s\n", dir, name);
	CHECK_INT(gw, w);
	CHECK_INT(gh, h);
	check_not_blank(dir, name);
}

static void check_html(const char *dir)
{
	char *html = read_file(dir, "report.html");
	CHECK_CONTAINS(html, "<svg");
	CHECK_CONTAINS(html, "ico&lt;1&gt;");
	CHECK_CONTAINS(html, "terrain");
	CHECK_CONTAINS(html, ">sweep</td>");
	CHECK_CONTAINS(html, ">binned</td>");
	/* "ico<1>" had to change, so its images carry the hash of the name. */
	CHECK_CONTAINS(html, "images/ico_1_-382d5051--sweep--heat.png");
	CHECK(html && !strstr(html, "ico<1>"));
	free(html);
}

/* Every run: the three traversals with the same hits, the same node counts
 * for wide (main) and stack, repeated passes, EPO and peak memory. */
/* A batch's 10 passes, or fewer that took 10 x min_ms (1 ms here) between
 * them: min_repeats gives way to slow passes (trace_measure.c), as they
 * are under ASan on a busy machine. */
static bool ten_passes(const cJSON *batch)
{
	return cJSON_GetObjectItem(batch, "repeats")->valueint >= 10 ||
	       cJSON_GetObjectItem(batch, "seconds")->valuedouble >= 10 * 1e-3;
}

static void check_measures(const cJSON *doc)
{
	const cJSON *run;
	cJSON_ArrayForEach(run, cJSON_GetObjectItem(doc, "runs")) {
		const cJSON *rays = cJSON_GetObjectItem(run, "rays");
		const cJSON *sl = cJSON_GetObjectItem(cJSON_GetObjectItem(rays, "stackless"), "primary");
		const cJSON *st = cJSON_GetObjectItem(rays, "primary");
		const cJSON *sk = cJSON_GetObjectItem(cJSON_GetObjectItem(rays, "stack"), "primary");
		CHECK(!strcmp(cJSON_GetObjectItem(rays, "traversal")->valuestring, "wide"));
		CHECK(sk && cJSON_GetObjectItem(sk, "nodes_per_ray")->valuedouble ==
		                    cJSON_GetObjectItem(st, "nodes_per_ray")->valuedouble);
		CHECK(cJSON_IsNumber(cJSON_GetObjectItem(rays, "traversal_disagreements")) &&
		      cJSON_GetObjectItem(rays, "traversal_disagreements")->valuedouble == 0);
		CHECK(sl && cJSON_GetObjectItem(sl, "rays")->valueint == 40 * 30);
		/* Shadow and AO rays, from every primary hit, by every traversal
		 * (traversal_disagreements above covers their hits), timed in
		 * the rounds like the others. */
		for (int k = 0; k < 3; k++) {
			const cJSON *by = k ? cJSON_GetObjectItem(rays, k == 1 ? "stack" : "stackless")
			                    : rays;
			const cJSON *sh = cJSON_GetObjectItem(by, "shadow");
			const cJSON *ao = cJSON_GetObjectItem(by, "ao");
			CHECK(sh && cJSON_GetObjectItem(sh, "rays")->valueint > 0 && ten_passes(sh));
			CHECK(ao && cJSON_GetObjectItem(ao, "rays")->valueint > 0 && ten_passes(ao));
			CHECK(cJSON_GetObjectItem(sh, "rays")->valueint ==
			      cJSON_GetObjectItem(cJSON_GetObjectItem(rays, "shadow"), "rays")->valueint);
		}
		/* The default 8 rounds, slices of 2 passes until the batch has
		 * its 10: more than the run's own provisional timing (one pass
		 * of min_ms / 8) makes. */
		CHECK_INT(cJSON_GetObjectItem(rays, "rounds")->valueint, 8);
		CHECK(ten_passes(st));
		CHECK(ten_passes(sl));
		CHECK(cJSON_GetObjectItem(st, "mrays_min")->valuedouble <=
		      cJSON_GetObjectItem(st, "mrays_max")->valuedouble);
		CHECK(cJSON_IsNumber(cJSON_GetObjectItem(cJSON_GetObjectItem(run, "tree"), "epo")));
		const cJSON *mem = cJSON_GetObjectItem(run, "memory");
		CHECK(cJSON_IsNumber(cJSON_GetObjectItem(mem, "peak_bytes")));
		CHECK(cJSON_GetObjectItem(mem, "peak_rss_bytes")->valuedouble > 0);
		CHECK(cJSON_GetObjectItem(mem, "output_bytes")->valuedouble > 0);
	}
}

/* No ".tree-" file of the rounds is left in the output folder. */
static void check_no_trees(const char *dir)
{
	DIR *d = opendir(dir);
	struct dirent *e;
	CHECK(d != NULL);
	while (d && (e = readdir(d)) != NULL) {
		if (!strncmp(e->d_name, ".tree-", 6))
			fprintf(stderr, "left behind: %s/%s\n", dir, e->d_name);
		CHECK(strncmp(e->d_name, ".tree-", 6) != 0);
	}
	if (d)
		closedir(d);
}

static void test_run(void)
{
	const char *cfg = write_config("rays.json", config);
	char dir[512], regen[600], json[600];
	CHECK_INT(run(ARGS("run", "--quiet", cfg)), 0);
	snprintf(dir, sizeof(dir), "%s/out-rays", tmpdir);
	cJSON *doc = load_results(dir);
	const cJSON *run0 = cJSON_GetArrayItem(cJSON_GetObjectItem(doc, "runs"), 0);
	const cJSON *rays = cJSON_GetObjectItem(run0, "rays");
	const cJSON *prim = cJSON_GetObjectItem(rays, "primary");
	CHECK(cJSON_GetObjectItem(prim, "mrays_per_s")->valuedouble > 0);
	CHECK(cJSON_GetObjectItem(prim, "nodes_per_ray")->valuedouble >= 1);
	CHECK_INT(cJSON_GetObjectItem(prim, "rays")->valueint, 40 * 30);
	CHECK(cJSON_GetObjectItem(cJSON_GetObjectItem(rays, "diffuse"), "rays")->valueint > 0);
	CHECK_INT(count_runs(doc, "sweep", "ok"), 2); /* not PARALLEL: 1 thread only */
	check_measures(doc);
	cJSON_Delete(doc);
	check_image(dir, "images/ico_1_-382d5051.png", 40, 30);
	check_image(dir, "images/ico_1_-382d5051--sweep--heat.png", 40, 30);
	check_image(dir, "images/terrain--binned--heat.png", 40, 30);
	check_image(dir, "images/terrain--legend.png", 256, 16);
	check_html(dir);
	check_no_trees(dir);
	char *csv = read_file(dir, "results.csv");
	CHECK_CONTAINS(csv, "rays.primary.mrays_per_s");
	CHECK_CONTAINS(csv, "rays.shadow.mrays_per_s");
	CHECK_CONTAINS(csv, "rays.ao.nodes_per_ray");
	free(csv);
	snprintf(regen, sizeof(regen), "%s/regen", tmpdir);
	snprintf(json, sizeof(json), "%s/results.json", dir);
	CHECK_INT(run(ARGS("report", json, "--out", regen)), 0);
	check_html(regen);
	char *md = read_file(regen, "report.md");
	CHECK_CONTAINS(md, "primary Mrays/s");
	CHECK_CONTAINS(md, "**Rays by kind.**");
	CHECK_CONTAINS(md, "| shadow Mrays/s | shadow nodes/ray | ao Mrays/s |");
	/* No sah_seq-labelled builder: the reference falls back to the plugin's
	 * first builder, sweep, which is 1.00x itself on every scene. */
	CHECK_CONTAINS(md, "## Summary");
	CHECK_CONTAINS(md, "reference builder **sweep**");
	CHECK_CONTAINS(md, "| sweep | 1 | 2 | 1.00× | 1.00× |");
	free(md);
	char *html = read_file(regen, "report.html");
	CHECK_CONTAINS(html, "<h2 id=\"summary\">Summary</h2>");
	CHECK_CONTAINS(html, "stackless primary Mrays/s");
	CHECK_CONTAINS(html, "stack primary Mrays/s");
	CHECK_CONTAINS(html, "<h3>Rays by kind</h3>");
	free(html);
	CHECK_INT(run(ARGS("report", "/nonexistent/results.json")), 2);
}

/* Every run's primary timing: `rounds` rounds of at least `passes` passes
 * in all; in process (isolate false) the same as in children. */
static void check_rounds(const char *name, const char *isolate, int rounds, int passes)
{
	char text[1024], dir[600];
	snprintf(text, sizeof(text),
	         "{ \"output\": \"out-%s\", \"repeat\": 1, \"isolate\": %s,\n"
	         "  \"rays\": { \"width\": 16, \"height\": 16, \"min_ms\": 1, \"rounds\": %d },\n"
	         "  \"scenes\": [ { \"generator\": \"icosphere\", \"frequency\": 6 } ],\n"
	         "  \"builders\": [ { \"plugin\": \"sah_seq\" }, { \"plugin\": \"lbvh\" } ] }\n",
	         name, isolate, rounds);
	const char *cfg = write_config(name, text);
	/* A tree file an interrupted sweep left behind goes too. */
	snprintf(dir, sizeof(dir), "%s/out-%s", tmpdir, name);
	CHECK(mkdir(dir, 0755) == 0);
	char stale[700];
	snprintf(stale, sizeof(stale), "%s/.tree-0-7.raw", dir);
	FILE *f = fopen(stale, "w");
	CHECK(f && fputs("left by a killed run", f) >= 0 && fclose(f) == 0);
	CHECK_INT(run(ARGS("run", "--quiet", cfg)), 0);
	cJSON *doc = load_results(dir);
	const cJSON *r;
	CHECK_INT(cJSON_GetArraySize(cJSON_GetObjectItem(doc, "runs")), 2);
	cJSON_ArrayForEach(r, cJSON_GetObjectItem(doc, "runs")) {
		const cJSON *rays = cJSON_GetObjectItem(r, "rays");
		const cJSON *prim = cJSON_GetObjectItem(rays, "primary");
		CHECK_INT(cJSON_GetObjectItem(rays, "rounds")->valueint, rounds);
		CHECK(cJSON_GetObjectItem(prim, "repeats")->valueint >= passes);
		CHECK(cJSON_GetObjectItem(prim, "mrays_per_s")->valuedouble > 0);
		CHECK_INT(cJSON_GetObjectItem(prim, "rays")->valueint, 16 * 16);
	}
	cJSON_Delete(doc);
	check_no_trees(dir);
}

/* A run whose tree cannot be kept for the rounds (here a folder in the
 * way of its file) times all of min_ms itself, with its 10 passes, not
 * one provisional slice (a pass of 4096 rays takes a good part of that
 * slice's millisecond), and says rounds 1; the other run still gets the
 * rounds. */
static void check_tree_refused(void)
{
	char dir[600], blocker[700];
	const char *cfg = write_config("refused.json",
		"{ \"output\": \"out-refused\", \"repeat\": 1,\n"
		"  \"rays\": { \"width\": 64, \"height\": 64, \"min_ms\": 5, \"rounds\": 5 },\n"
		"  \"scenes\": [ { \"generator\": \"icosphere\", \"frequency\": 6 } ],\n"
		"  \"builders\": [ { \"plugin\": \"sah_seq\" }, { \"plugin\": \"lbvh\" } ] }\n");
	snprintf(dir, sizeof(dir), "%s/out-refused", tmpdir);
	snprintf(blocker, sizeof(blocker), "%s/.tree-0-0.raw", dir);
	CHECK(mkdir(dir, 0755) == 0 && mkdir(blocker, 0755) == 0);
	CHECK_INT(run(ARGS("run", "--quiet", cfg)), 0);
	cJSON *doc = load_results(dir);
	const cJSON *runs = cJSON_GetObjectItem(doc, "runs");
	for (int k = 0; k < 2; k++) {
		const cJSON *rays = cJSON_GetObjectItem(cJSON_GetArrayItem(runs, k), "rays");
		CHECK_INT(cJSON_GetObjectItem(rays, "rounds")->valueint, k == 0 ? 1 : 5);
		CHECK(cJSON_GetObjectItem(cJSON_GetObjectItem(rays, "primary"), "repeats")->valueint >=
		      10);
	}
	cJSON_Delete(doc);
	CHECK(rmdir(blocker) == 0);
	check_no_trees(dir);
}

static void test_rounds(void)
{
	check_rounds("rounds3.json", "true", 3, 10);
	check_rounds("rounds3-here.json", "false", 3, 10);
	check_rounds("rounds1.json", "true", 1, 10);
	check_tree_refused();
}

static void test_render(void)
{
	char out[600];
	snprintf(out, sizeof(out), "%s/one.png", tmpdir);
	CHECK_INT(run(ARGS("render", "sah_seq", "icosphere:frequency=6", "-o", out, "--width", "33",
	                   "--height", "21", "--heat")), 0);
	check_image(tmpdir, "one.png", 33, 21);
	CHECK_INT(run(ARGS("render", "--help")), 0);
	CHECK_CONTAINS(out_text, "usage: bvhlab render");
	CHECK_INT(run(ARGS("render", "sah_seq")), 2);
}

static void test_bad_camera(void)
{
	static const char format[] =
		"{ \"rays\": { \"camera\": %s },\n"
		"  \"scenes\": [ { \"generator\": \"icosphere\" } ],\n"
		"  \"builders\": [ { \"plugin\": \"sah_seq\" } ] }\n";
	cli_refused_with("cam.json", format, "{ \"position\": [0, 0, 1], \"target\": [0, 0, 1] }",
	                 "position and target must differ");
	CHECK_CONTAINS(err_text, "cam.json:1:");
	cli_refused_with("cam2.json", format, "{ \"position\": [0, 0, \"x\"] }",
	                 "'rays.camera.position' must be an array of 3 finite numbers");
}

int main(int argc, char **argv)
{
	if (!cli_begin(argc, argv))
		return 2;
	test_run();
	test_rounds();
	test_render();
	test_bad_camera();
	return cli_end();
}
