/*
 * `bvhlab report DIR --reference NAME` (and --scene, --threads): a
 * finished sweep re-based without touching its results.json. A re-based
 * report is the report of a sweep run with that reference: the same
 * results.json with config.report.reference naming it renders the very
 * same report.md and report.html. (Two real sweeps would differ in every
 * timed figure, so the figures are held fixed and only the reference
 * differs.)
 */
#include <sys/stat.h>

#include "cliutil.h"

static const char config[] =
	"{ \"output\": \"out\", \"repeat\": 1, \"threads\": [1, 2],\n"
	"  \"report\": { \"reference\": \"seq\" },\n"
	"  \"rays\": { \"width\": 16, \"height\": 16, \"min_ms\": 1, \"rounds\": 1 },\n"
	"  \"scenes\": [ { \"name\": \"ico\", \"generator\": \"icosphere\", \"frequency\": 6 },\n"
	"              { \"name\": \"terrain\", \"generator\": \"terrain\", \"size\": 8 } ],\n"
	"  \"builders\": [ { \"plugin\": \"sah_seq\", \"name\": \"seq\" },\n"
	"                { \"plugin\": \"sah_tasks\", \"name\": \"tasks\" } ] }\n";

/* dir/results.json with config.report.reference set to ref, into a new
 * folder `to` of tmpdir. */
static void write_rebased(const char *dir, const char *ref, const char *to)
{
	char *text = read_file(dir, "results.json"), path[600];
	cJSON *doc = cJSON_Parse(text);
	cJSON *report = cJSON_GetObjectItem(cJSON_GetObjectItem(doc, "config"), "report");
	cJSON_ReplaceItemInObject(report, "reference", cJSON_CreateString(ref));
	char *out = cJSON_Print(doc);
	snprintf(path, sizeof(path), "%s/%s", tmpdir, to);
	CHECK(mkdir(path, 0755) == 0);
	snprintf(path, sizeof(path), "%s/%s/results.json", tmpdir, to);
	FILE *f = fopen(path, "w");
	CHECK(f && fputs(out, f) >= 0 && fclose(f) == 0);
	free(out);
	free(text);
	cJSON_Delete(doc);
}

static void same_file(const char *a, const char *b, const char *name)
{
	char *x = read_file(a, name), *y = read_file(b, name);
	CHECK(x && y);
	if (x && y && strcmp(x, y) != 0)
		fprintf(stderr, "%s differs between %s and %s\n", name, a, b);
	CHECK(x && y && strcmp(x, y) == 0);
	free(x);
	free(y);
}

static void test_reference(void)
{
	char dir[600], r1[600], r2[600], json[700];
	const char *cfg = write_config("report.json", config);
	CHECK_INT(run(ARGS("run", "--quiet", cfg)), 0);
	snprintf(dir, sizeof(dir), "%s/out", tmpdir);
	snprintf(r1, sizeof(r1), "%s/rebased", tmpdir);
	snprintf(r2, sizeof(r2), "%s/asked", tmpdir);
	cJSON *doc = load_results(dir);
	CHECK_INT(count_runs(doc, "tasks", "ok"), 4); /* 2 scenes, 1 and 2 threads */
	CHECK_INT(count_runs(doc, "seq", "ok"), 2);   /* not PARALLEL: 1 thread */
	cJSON_Delete(doc);
	char *before = read_file(dir, "results.json");
	CHECK_INT(run(ARGS("report", dir, "--reference", "tasks", "--out", r1)), 0);
	write_rebased(dir, "tasks", "asked");
	snprintf(json, sizeof(json), "%s/results.json", r2);
	CHECK_INT(run(ARGS("report", json)), 0);
	same_file(r1, r2, "report.md");
	same_file(r1, r2, "report.html");
	char *md = read_file(r1, "report.md");
	CHECK_CONTAINS(md, "reference builder **tasks**");
	CHECK(!strstr(md, "Parallel builders against")); /* tasks ran on 2 threads */
	CHECK_CONTAINS(md, "**Cheapest for a ray budget**");
	free(md);
	/* Into the sweep's own folder too: its results.json is only read. */
	CHECK_INT(run(ARGS("report", dir, "--reference", "tasks")), 0);
	same_file(dir, r1, "report.md");
	char *after = read_file(dir, "results.json");
	CHECK(before && after && strcmp(before, after) == 0);
	free(before);
	free(after);
}

static void test_filters(void)
{
	char dir[600], out[600];
	snprintf(dir, sizeof(dir), "%s/out", tmpdir);
	snprintf(out, sizeof(out), "%s/filtered", tmpdir);
	CHECK_INT(run(ARGS("report", dir, "--scene", "ico", "--threads", "2", "--out", out)), 0);
	char *md = read_file(out, "report.md");
	CHECK_CONTAINS(md, "**Filtered by bvhlab report: scenes: ico; threads: 2;");
	CHECK_CONTAINS(md, "## ico");
	CHECK(!strstr(md, "## terrain") && !strstr(md, "| seq | 1 |"));
	CHECK_CONTAINS(md, "| tasks | 2 | ok |");
	free(md);
	/* Bad views: exit 2, the file and what it lacks named, nothing written. */
	snprintf(out, sizeof(out), "%s/bad", tmpdir);
	CHECK_INT(run(ARGS("report", dir, "--reference", "nope", "--out", out)), 2);
	CHECK_CONTAINS(err_text, "no ok run of a builder or plugin named 'nope' (--reference)");
	CHECK_INT(run(ARGS("report", dir, "--scene", "nope", "--out", out)), 2);
	CHECK_CONTAINS(err_text, "has no run of scene 'nope' (--scene)");
	CHECK_INT(run(ARGS("report", dir, "--threads", "3", "--out", out)), 2);
	CHECK_CONTAINS(err_text, "has no run with 3 threads (--threads)");
	CHECK_INT(run(ARGS("report", dir, "--threads", "x", "--out", out)), 2);
	CHECK_CONTAINS(err_text, "--threads 'x': not a thread count");
	/* The reference must have an ok run among the runs kept: seq ran on 1
	 * thread only. */
	CHECK_INT(run(ARGS("report", dir, "--threads", "2", "--reference", "seq", "--out", out)), 2);
	CHECK_CONTAINS(err_text, "among the scenes and threads kept");
	struct stat st;
	CHECK(stat(out, &st) != 0);
}

int main(int argc, char **argv)
{
	if (!cli_begin(argc, argv))
		return 2;
	test_reference();
	test_filters();
	return cli_end();
}
