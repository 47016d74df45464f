/*
 * Wide trees through the bvhlab command: a sweep of lbvh, ploc and
 * sah_tasks, binary and collapsed (sah 8-wide, greedy 4-wide), records each
 * tree's width and its bytes per triangle as stored and packed (their
 * formulas checked against the run's own node, leaf and reference counts),
 * the collapse as a stage with the binary SAH before it, the columns in
 * results.csv, and report.md's wide-tree and ranking sections.
 * Usage: test-cli-wide BVHLAB_EXE all
 */
#include <math.h>

#include "cliutil.h"

static const char config[] =
	"{ \"format_version\": 1, \"output\": \"out-wide\", \"repeat\": 1, \"threads\": [1],\n"
	"  \"rays\": { \"width\": 24, \"height\": 24, \"diffuse\": 1, \"min_ms\": 1 },\n"
	"  \"scenes\": [ { \"name\": \"soup\", \"generator\": \"soup\", \"count\": 1500 } ],\n"
	"  \"builders\": [ { \"plugin\": \"lbvh\" },\n"
	"    { \"plugin\": \"lbvh\", \"name\": \"lbvh8\", \"refine\": [ { \"plugin\": \"collapse\" } ] },\n"
	"    { \"plugin\": \"ploc\", \"name\": \"ploc8\", \"refine\": [ { \"plugin\": \"collapse\" } ] },\n"
	"    { \"plugin\": \"sah_tasks\", \"name\": \"tasks8\",\n"
	"      \"refine\": [ { \"plugin\": \"collapse\" } ] },\n"
	"    { \"plugin\": \"lbvh\", \"name\": \"lbvh4g\", \"refine\": [ { \"plugin\": \"collapse\",\n"
	"      \"options\": { \"method\": \"greedy\", \"width\": 4 } } ] } ] }\n";

static double num(const cJSON *o, const char *a, const char *b)
{
	const cJSON *v = cJSON_GetObjectItem(cJSON_GetObjectItem(o, a), b);
	CHECK(cJSON_IsNumber(v));
	return cJSON_IsNumber(v) ? v->valuedouble : NAN;
}

/* Width as recorded; bytes per triangle from the run's own counts. */
static void check_tree(const cJSON *run, int width)
{
	double nodes = num(run, "tree", "nodes"), leaves = num(run, "tree", "leaves");
	double refs = num(run, "tree", "refs");
	CHECK_INT((int)num(run, "tree", "width"), width);
	CHECK(fabs(num(run, "tree", "bytes_per_triangle") - (nodes * 32 + refs * 4) / 1500) < 1e-9);
	CHECK(fabs(num(run, "tree", "packed_bytes_per_triangle") -
	           ((nodes - leaves) * width * 28 + refs * 4) / 1500) < 1e-9);
	/* the compressed 8-wide layout, for trees device_wide8 takes as built */
	const cJSON *cw = cJSON_GetObjectItem(cJSON_GetObjectItem(run, "tree"),
	                                      "cwbvh_bytes_per_triangle");
	CHECK(width > 4 ? cJSON_IsNumber(cw) && fabs(cw->valuedouble - ((nodes - leaves) * 80 +
	                                                                leaves * 8 + refs * 4) /
	                                                               1500) < 1e-9
	                : cw == NULL);
}

static void test_sweep(void)
{
	const char *cfg = write_config("wide.json", config);
	char dir[512];
	CHECK_INT(run(ARGS("run", "--quiet", cfg)), 0);
	snprintf(dir, sizeof(dir), "%s/out-wide", tmpdir);
	cJSON *doc = load_results(dir);
	const cJSON *bin = find_run(doc, "soup", "lbvh", 1), *w8 = find_run(doc, "soup", "lbvh8", 1);
	const cJSON *w4 = find_run(doc, "soup", "lbvh4g", 1);
	CHECK(bin && w8 && w4);
	if (bin && w8 && w4) {
		check_tree(bin, 2);
		check_tree(w8, 8);
		check_tree(w4, 4);
		const cJSON *stage = cJSON_GetArrayItem(cJSON_GetObjectItem(w8, "stages"), 0);
		CHECK(!strcmp(run_str(stage, "plugin"), "collapse"));
		const cJSON *before = cJSON_GetObjectItem(stage, "sah_before");
		CHECK(cJSON_IsNumber(before) && before->valuedouble == num(bin, "tree", "sah_cost"));
		CHECK(num(w8, "tree", "sah_cost") <= num(bin, "tree", "sah_cost"));
	}
	cJSON_Delete(doc);
	char *csv = read_file(dir, "results.csv");
	CHECK_CONTAINS(csv, ",tree.width,tree.bytes_per_triangle,tree.packed_bytes_per_triangle,"
	                    "tree.cwbvh_bytes_per_triangle,");
	free(csv);
	char *md = read_file(dir, "report.md");
	CHECK_CONTAINS(md, "### Wide trees");
	CHECK_CONTAINS(md, "| lbvh4g | 1 | 4 | greedy |");
	CHECK_CONTAINS(md, "### Does the collapse change the ranking? 8-wide, sah");
	CHECK_CONTAINS(md, "(3 builders; 1 the same order");
	CHECK_CONTAINS(md, "Wide trees on the front of build time");
	free(md);
}

int main(int argc, char **argv)
{
	if (!cli_begin(argc, argv))
		return 2;
	test_sweep();
	return cli_end();
}
