/*
 * Two-level scenes through `bvhlab run` (#42): a scene of meshes and
 * instances built flat and in two levels, each run valid with its rays
 * through both levels checked against brute force, the scene's counts and
 * the levels' figures in results.json, CSV and report; a two-level config
 * that cannot run (a top that cannot build over boxes, an unknown mesh)
 * is exit 2 before any output folder.
 */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>


#include "cliutil.h"

#define SCENE \
	"  \"scenes\": [ { \"name\": \"grove\",\n" \
	"    \"meshes\": [ { \"name\": \"ball\", \"generator\": \"icosphere\", \"frequency\": 3 },\n" \
	"                  { \"name\": \"rock\", \"generator\": \"soup\", \"count\": 40 } ],\n" \
	"    \"instances\": [ { \"mesh\": \"%s\", \"translate\": [0, 0, 0] },\n" \
	"      { \"scatter\": { \"mesh\": \"ball\", \"count\": 30,\n" \
	"                       \"bounds\": [[-5, 0, -5], [5, 1, 5]],\n" \
	"                       \"scale\": [0.5, 1.5], \"rotate\": \"random-y\" } } ] } ],\n"

static double num_at(const cJSON *o, const char *a, const char *b, const char *c)
{
	const cJSON *v = cJSON_GetObjectItem(o, a);
	v = b ? cJSON_GetObjectItem(v, b) : v;
	v = c ? cJSON_GetObjectItem(v, c) : v;
	return cJSON_IsNumber(v) ? v->valuedouble : -1;
}

static void sweep(void)
{
	char text[2048];
	snprintf(text, sizeof(text),
	         "{ \"output\": \"out\", \"repeat\": 2, \"warmup\": 0, \"threads\": [2],\n"
	         "  \"validate_rays\": 64, \"rays\": { \"width\": 16, \"height\": 16,\n"
	         "    \"traversal\": [\"stack\", \"stackless\", \"wide\"] },\n" SCENE
	         "  \"builders\": [ { \"plugin\": \"sah_seq\" },\n"
	         "    { \"bottom\": \"sah_seq\", \"top\": \"sah_tasks\",\n"
	         "      \"top_options\": { \"method\": \"sweep\" } } ] }\n", "rock");
	CHECK_INT(run_in(tmpdir, ARGS("run", "--quiet", write_config("grove.json", text))), 0);
	cJSON *doc = load_results(cli_path_in("out"));
	const cJSON *scene = cJSON_GetArrayItem(cJSON_GetObjectItem(doc, "scenes"), 0);
	CHECK(num_at(scene, "instances", "meshes", NULL) == 2);
	CHECK(num_at(scene, "instances", "instances", NULL) == 31);
	CHECK(num_at(scene, "instances", "unique_triangles", NULL) == 180 + 40);
	CHECK(num_at(scene, "instances", "instanced_triangles", NULL) == 30 * 180 + 40);
	CHECK(num_at(scene, "triangles", NULL, NULL) == 30 * 180 + 40);
	const cJSON *flat = find_run(doc, "grove", "sah_seq", 2);
	const cJSON *two = find_run(doc, "grove", "two-level[top=sah_tasks,bottom=sah_seq]", 2);
	CHECK(flat && two && !strcmp(run_str(flat, "status"), "ok"));
	CHECK(two && !strcmp(run_str(two, "status"), "ok"));
	/* 64 rays per mesh's bottom tree, 64 through both levels */
	CHECK(num_at(two, "validation", "rays_checked", NULL) == 3 * 64);
	CHECK(num_at(two, "validation", "mismatches", NULL) == 0);
	CHECK(num_at(two, "two_level", "bottom", "trees") == 2);
	CHECK(num_at(two, "two_level", "top", "trees") == 1);
	const cJSON *top = cJSON_GetObjectItem(cJSON_GetObjectItem(two, "two_level"), "top");
	CHECK(!strcmp(run_str(top, "plugin"), "sah_tasks"));
	double b = num_at(two, "two_level", "bottom", "build_ms");
	double t = num_at(two, "two_level", "top", "build_ms");
	CHECK(b > 0 && t > 0 && fabs(num_at(two, "two_level", "build_ms", NULL) - (b + t)) < 1e-9);
	CHECK(num_at(two, "tree", "sah_cost", NULL) == num_at(two, "two_level", "sah_cost", NULL));
	CHECK(num_at(two, "tree", "nodes", NULL) == num_at(two, "two_level", "bottom", "nodes") +
	                                            num_at(two, "two_level", "top", "nodes"));
	/* its primary rays through both levels, each CPU traversal, the same hits */
	const cJSON *rays = cJSON_GetObjectItem(two, "rays");
	CHECK(num_at(rays, "primary", "rays", NULL) == 256);
	CHECK(num_at(rays, "primary", "mrays_per_s", NULL) > 0);
	CHECK(num_at(rays, "stackless", "primary", "mrays_per_s") > 0);
	CHECK(num_at(rays, "wide", "primary", "mrays_per_s") > 0);
	CHECK(num_at(rays, "traversal_disagreements", NULL, NULL) == 0);
	cJSON_Delete(doc);
	char *csv = read_file(cli_path_in("out"), "results.csv");
	CHECK(csv && strstr(csv, ",two_level.bottom.build_ms,two_level.top.build_ms,"));
	free(csv);
	char *md = read_file(cli_path_in("out"), "report.md");
	CHECK(md && strstr(md, "31 instances of 2 meshes (220 unique triangles, 5440 instanced)"));
	CHECK(md && strstr(md, "| two-level[top=sah_tasks,bottom=sah_seq] | 2 | sah_seq | sah_tasks |"));
	CHECK(md && strstr(md, "| two-level[top=sah_tasks,bottom=sah_seq] | sah_seq | 2 |"));
	free(md);
	char *html = read_file(cli_path_in("out"), "report.html");
	CHECK(html && strstr(html, "<tr><td>two-level[top=sah_tasks,bottom=sah_seq]</td><td>2</td>"
	                           "<td>sah_seq</td><td>sah_tasks</td>"));
	CHECK(html && strstr(html, "<tr><td>two-level[top=sah_tasks,bottom=sah_seq]</td>"
	                           "<td>sah_seq</td><td>2</td>"));
	free(html);
}

static void refused(void)
{
	char text[2048];
	snprintf(text, sizeof(text), "{ \"output\": \"out-bad\",\n" SCENE
	         "  \"builders\": [ { \"bottom\": \"sah_seq\", \"top\": \"fake_good\" } ] }\n",
	         "rock");
	cli_refused("top.json", text, "builder 'two-level[top=fake_good,bottom=sah_seq]': top: "
	            "plugin 'fake_good' cannot build over boxes");
	snprintf(text, sizeof(text), "{ \"output\": \"out-bad\",\n" SCENE
	         "  \"builders\": [ { \"plugin\": \"sah_seq\" } ] }\n", "rok");
	cli_refused("mesh.json", text, "scene 'grove' has no mesh 'rok' (did you mean 'rock'?)");
	CHECK(!cli_exists(cli_path_in("out-bad")));
}

/* A scene no flat tree can hold (100,820-triangle spheres placed 50,000
 * times: 5,041,000,000 triangles): the one-level run fails naming the
 * scene and its triangles, the two-level one runs without the flat scene. */
static void unflattenable(void)
{
	const char *text =
		"{ \"output\": \"out-big\", \"repeat\": 1, \"warmup\": 0, \"threads\": [2],\n"
		"  \"validate_rays\": 8, \"rays\": { \"width\": 4, \"height\": 4, \"min_ms\": 1 },\n"
		"  \"scenes\": [ { \"name\": \"big\",\n"
		"    \"meshes\": [ { \"name\": \"ball\", \"generator\": \"icosphere\",\n"
		"                    \"frequency\": 71 } ],\n"
		"    \"instances\": [ { \"scatter\": { \"mesh\": \"ball\", \"count\": 50000,\n"
		"      \"bounds\": [[-2000, 0, -2000], [2000, 0, 2000]] } } ] } ],\n"
		"  \"builders\": [ { \"plugin\": \"lbvh\" }, { \"bottom\": \"lbvh\", \"top\": \"lbvh\" } ] }\n";
	CHECK_INT(run_in(tmpdir, ARGS("run", "--quiet", write_config("big.json", text))), 1);
	cJSON *doc = load_results(cli_path_in("out-big"));
	const cJSON *scene = cJSON_GetArrayItem(cJSON_GetObjectItem(doc, "scenes"), 0);
	CHECK(num_at(scene, "instances", "instanced_triangles", NULL) == 5041000000.0);
	CHECK(scene && !strcmp(run_str(scene, "source"), "two-level scene"));
	const cJSON *flat = find_run(doc, "big", "lbvh", 2);
	const cJSON *two = find_run(doc, "big", "two-level[top=lbvh,bottom=lbvh]", 2);
	CHECK(flat && !strcmp(run_str(flat, "status"), "failed"));
	CHECK(flat && strstr(run_str(flat, "error"), "big") &&
	      strstr(run_str(flat, "error"), "flattened") &&
	      strstr(run_str(flat, "error"), "5041000000"));
	CHECK(two && !strcmp(run_str(two, "status"), "ok"));
	CHECK(num_at(two, "validation", "mismatches", NULL) == 0);
	CHECK(num_at(cJSON_GetObjectItem(two, "rays"), "primary", "rays", NULL) == 16);
	cJSON_Delete(doc);
}

static void all(void)
{
	sweep();
	unflattenable();
	refused();
}

int main(int argc, char **argv)
{
	static const struct cli_mode modes[] = {{"all", all}};
	return cli_main_modes(argc, argv, "test-cli-inst", modes, 1);
}
