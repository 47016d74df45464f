/* bvhlab merge: the results folders of a plan's parts joined into one. */
#include <getopt.h>
#include <limits.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include <cJSON.h>

#include "cli.h"
#include "plan/plan.h"

static const char usage[] =
	"usage: bvhlab merge PART... --out DIR [--plan PLAN.json] [--allow-mixed-versions]\n"
	"\n"
	"Joins results folders written by the commands of `bvhlab plan` (usually\n"
	"DIR/parts/*) into DIR: results.json with every run in the plan's order,\n"
	"results.csv, report.md, report.html and the images. Each run keeps the\n"
	"machine record (hostname, CPU, cores) of the part that measured it; the\n"
	"reports list the machines when there are several, since times from\n"
	"different machines do not compare.\n"
	"\n"
	"Checks that every part comes from the plan (its hash) and the same bvhlab\n"
	"build (its bvhlab_version), that no run is claimed by two parts and that\n"
	"the plan's config has not changed. A partial\n"
	"set merges fine and names the runs still missing (`bvhlab plan --missing\n"
	"DIR` prints their commands); merging again later replaces an earlier merge\n"
	"of the same plan, and nothing else.\n"
	"\n"
	"options:\n"
	"  --out DIR        where the merged results go (default plan: DIR/plan.json)\n"
	"  --plan FILE      the plan the parts come from\n"
	"  --allow-mixed-versions\n"
	"                   merge parts run by different bvhlab builds (refused\n"
	"                   otherwise: figures of other builds may not compare); each\n"
	"                   run keeps its part's bvhlab_version\n"
	"\n"
	"exit status: 0 every run present and ok, 1 runs missing, failed or invalid,\n"
	"2 bad arguments or parts (another plan, no results.json, a run twice).\n";

/* The plan's description of run id: "3 (ico, sah_seq, 2 threads)". */
static void describe(const struct plan_file *plan, uint32_t id, char *buf, size_t size)
{
	const cJSON *run = cJSON_GetArrayItem(cJSON_GetObjectItem(plan->doc, "runs"), (int)id);
	const cJSON *s = cJSON_GetObjectItem(run, "scene"), *b = cJSON_GetObjectItem(run, "builder");
	const cJSON *t = cJSON_GetObjectItem(run, "threads_configured");
	snprintf(buf, size, "%u (%s, %s, %g threads)", id, cJSON_IsString(s) ? s->valuestring : "?",
	         cJSON_IsString(b) ? b->valuestring : "?", cJSON_IsNumber(t) ? t->valuedouble : 0);
}

static void list_runs(const struct plan_file *plan, const char *what, const uint32_t *ids,
                      size_t n)
{
	char buf[512];
	for (size_t k = 0; k < n; k++) {
		describe(plan, ids[k], buf, sizeof(buf));
		fprintf(stderr, "bvhlab: %s: run %s\n", what, buf);
	}
}

static int report(const struct plan_file *plan, const struct merge_summary *sum,
                  const char *dir)
{
	fprintf(stderr, "bvhlab: merged %zu of the plan's %zu runs into %s/ (results.json, "
	                "results.csv, report.md, report.html)\n", sum->present, sum->runs, dir);
	list_runs(plan, "missing", sum->missing, sum->missing_count);
	list_runs(plan, "not ok", sum->not_ok, sum->not_ok_count);
	if (sum->missing_count)
		fprintf(stderr, "bvhlab: %zu runs missing; `bvhlab plan --missing %s` prints their "
		                "commands\n", sum->missing_count, dir);
	if (sum->machines > 1)
		fprintf(stderr, "bvhlab: the runs were measured on %zu different machines: compare "
		                "times only within one (the reports group them)\n", sum->machines);
	return sum->missing_count || sum->not_ok_count ? EXIT_RUNS_FAILED : 0;
}

int cmd_merge(int argc, char **argv)
{
	static const struct option longopts[] = {
		{"out", required_argument, NULL, 'o'}, {"plan", required_argument, NULL, 'p'},
		{"help", no_argument, NULL, 'h'},
		{"allow-mixed-versions", no_argument, NULL, 'm'}, {NULL, 0, NULL, 0}};
	const char *out = NULL, *plan_path = NULL;
	bool mixed = false;
	char buf[PATH_MAX + 16];
	int c;
	while ((c = getopt_long(argc, argv, "h", longopts, NULL)) != -1) {
		if (c == 'h')
			return fputs(usage, stdout), 0;
		if (c == 'm') {
			mixed = true;
			continue;
		}
		if (c != 'o' && c != 'p')
			return EXIT_USAGE;
		*(c == 'o' ? &out : &plan_path) = optarg;
	}
	if (!out || optind == argc) {
		fprintf(stderr, "bvhlab merge: expected PART... --out DIR\n\n%s", usage);
		return EXIT_USAGE;
	}
	if (!plan_path && (size_t)snprintf(buf, sizeof(buf), "%s/plan.json", out) < sizeof(buf))
		plan_path = buf;
	struct plan_file plan = {0};
	struct merge_summary sum = {0};
	bvhlab_error err = {{0}};
	int status = EXIT_USAGE;
	if (plan_file_load(&plan, plan_path, NULL, &err) == 0 &&
	    plan_merge(&plan, (const char *const *)argv + optind, (size_t)(argc - optind), out, mixed, &sum,
	               &err) == 0)
		status = report(&plan, &sum, out);
	else
		fprintf(stderr, "bvhlab: %s\n", err.message);
	merge_summary_finish(&sum);
	plan_file_finish(&plan);
	return status;
}
