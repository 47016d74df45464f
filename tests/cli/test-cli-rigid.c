/*
 * Rigid motion of instances through `bvhlab run` (#42 item 4): an animated
 * two-level scene swept by flat strategies (rebuild, refit) and two-level
 * ones (the top rebuilt, the top refitted), every frame of every run valid
 * in results.json and frames.csv, the two-level strategies beside the flat
 * ones in the reports' animation section; an animated two-level config
 * that cannot run is exit 2, naming the key, before any output folder.
 */
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "cliutil.h"

#define SCENE \
	"  \"scenes\": [ { \"name\": \"grove\", \"frames\": 3,\n" \
	"    \"meshes\": [ { \"name\": \"ball\", \"generator\": \"icosphere\", \"frequency\": 2 },\n" \
	"                  { \"name\": \"rock\", \"generator\": \"soup\", \"count\": 20 } ],\n" \
	"    \"instances\": [ { \"mesh\": \"rock\", %s },\n" \
	"      { \"scatter\": { \"mesh\": \"ball\", \"count\": 12,\n" \
	"                       \"bounds\": [[-5, 0, -5], [5, 1, 5]], \"rotate\": \"random-y\",\n" \
	"                       \"animate\": { \"rotate\": [0, 90, 0], \"translate\": [0, 3, 0] } } }" \
	" ] } ],\n"

static const char *const two = "two-level[top=lbvh,bottom=sah_seq]";
static const char *const two_refit = "two-level[top=lbvh,bottom=sah_seq]+refit";

/* Every frame of the run there and valid; rebuilt only at frame 0 when it
 * refits. */
static void check_frames(const cJSON *doc, const char *builder, bool refits)
{
	const cJSON *run = find_run(doc, "grove", builder, 2), *f;
	CHECK(run && !strcmp(run_str(run, "status"), "ok"));
	const cJSON *frames = run ? cJSON_GetObjectItem(run, "frames") : NULL;
	CHECK(cJSON_GetArraySize(frames) == 3);
	int k = 0;
	cJSON_ArrayForEach(f, frames) {
		CHECK(cJSON_IsTrue(cJSON_GetObjectItem(f, "valid")));
		CHECK(cJSON_IsNumber(cJSON_GetObjectItem(f, "sah")));
		CHECK(cJSON_IsTrue(cJSON_GetObjectItem(f, "rebuilt")) == (!refits || k == 0));
		CHECK(cJSON_IsTrue(cJSON_GetObjectItem(f, "rays_checked")));
		k++;
	}
}

static void refused(void);

/* The sweep, then the configs refused. */
static void all(void)
{
	char text[4096];
	snprintf(text, sizeof(text),
	         "{ \"output\": \"out\", \"repeat\": 1, \"warmup\": 0, \"threads\": [2],\n"
	         "  \"validate_rays\": 32, \"rays\": { \"width\": 8, \"height\": 8 },\n" SCENE
	         "  \"builders\": [ { \"plugin\": \"lbvh\" },\n"
	         "    { \"plugin\": \"lbvh\", \"animation\": { \"update\": \"refit\" } },\n"
	         "    { \"bottom\": \"sah_seq\", \"top\": \"lbvh\" },\n"
	         "    { \"bottom\": \"sah_seq\", \"top\": \"lbvh\",\n"
	         "      \"animation\": { \"update\": \"refit\" } } ] }\n",
	         "\"animate\": { \"translate\": [2, 0, 0] }");
	CHECK_INT(run_in(tmpdir, ARGS("run", "--quiet", write_config("grove.json", text))), 0);
	cJSON *doc = load_results(cli_path_in("out"));
	check_frames(doc, "lbvh", false);
	check_frames(doc, "lbvh+refit", true);
	check_frames(doc, two, false);
	check_frames(doc, two_refit, true);
	/* Frame 0 is the series' tree: the same two-level SAH. */
	const cJSON *run = find_run(doc, "grove", two_refit, 2);
	const cJSON *sah = cJSON_GetObjectItem(cJSON_GetObjectItem(run, "two_level"), "sah_cost");
	const cJSON *first = cJSON_GetArrayItem(cJSON_GetObjectItem(run, "frames"), 0);
	CHECK(cJSON_IsNumber(sah) && sah->valuedouble ==
	      cJSON_GetObjectItem(first, "sah")->valuedouble);
	cJSON_Delete(doc);
	char *csv = read_file(cli_path_in("out"), "frames.csv");
	CHECK(csv && strstr(csv, "grove,\"two-level[top=lbvh,bottom=sah_seq]+refit\",sah_seq,2,2,"
	                         "false,true,"));
	free(csv);
	char *md = read_file(cli_path_in("out"), "report.md");
	CHECK(md && strstr(md, "| two-level[top=lbvh,bottom=sah_seq]+refit | 2 | 3 | yes |"));
	CHECK(md && strstr(md, "| lbvh+refit | 2 | 3 | yes |"));
	free(md);
	char *html = read_file(cli_path_in("out"), "report.html");
	CHECK(html && strstr(html, "two-level[top=lbvh,bottom=sah_seq]+refit"));
	free(html);
	refused();
	CHECK(!cli_exists(cli_path_in("out-bad")));
}

static void refused(void)
{
	char text[4096];
	const char *const builders = "  \"builders\": [ { \"plugin\": \"lbvh\" } ] }\n";
	snprintf(text, sizeof(text), "{ \"output\": \"out-bad\",\n" SCENE "%s",
	         "\"animate\": { \"turn\": [0, 1, 0] }", builders);
	cli_refused("key.json", text, "unknown key 'turn' in scenes[0].instances[0].animate");
	snprintf(text, sizeof(text), "{ \"output\": \"out-bad\",\n" SCENE
	         "  \"builders\": [ { \"bottom\": \"sah_seq\", \"top\": \"lbvh\", \"animation\": "
	         "{ \"update\": \"refit\", \"refine\": [ { \"plugin\": \"reinsert\" } ] } } ] }\n",
	         "\"translate\": [0, 0, 0]");
	cli_refused("refine.json", text, "'builders[0].animation.refine': a two-level builder's "
	            "top is rebuilt or updated without refinement stages");
	snprintf(text, sizeof(text), "{ \"output\": \"out-bad\",\n" SCENE "%s",
	         "\"translate\": [0, 0, 0]", builders);
	char *frames = strstr(text, "\"frames\": 3,");
	memset(frames, ' ', strlen("\"frames\": 3,")); /* the same scene, static */
	cli_refused("static.json", text, "'scenes[0].instances[1].scatter.animate': the scene has "
	            "no 'frames' for its instances to move in");
	snprintf(text, sizeof(text), "{ \"output\": \"out-bad\",\n" SCENE
	         "  \"builders\": [ { \"bottom\": \"sah_seq\", \"top\": \"lbvh\", \"animation\": "
	         "{ \"update\": \"lbvh\" } } ] }\n", "\"translate\": [0, 0, 0]");
	cli_refused("update.json", text, "'lbvh' has no update function");
}

int main(int argc, char **argv)
{
	static const struct cli_mode modes[] = {{"all", all}};
	return cli_main_modes(argc, argv, "test-cli-rigid", modes, 1);
}
