/* bvhlab run: an experiment from a config file. */
#include <getopt.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "cli.h"
#include "config/config.h"
#include "harness/harness.h"
#include "plan/plan.h"
#include "util/util.h"

#define MAX_THREAD_COUNTS 64

static const char usage[] =
	"usage: bvhlab run CONFIG.json [options]\n"
	"       bvhlab run PLAN.json --only ID[,ID...] --out DIR [options]\n"
	"\n"
	"Runs every scene x builder x thread count of the config: warm-up builds,\n"
	"timed builds, validation of the last tree (structure and rays against brute\n"
	"force), tree metrics, rays traced through the tree (primary and diffuse) and,\n"
	"with \"images\": true, images. Rays are traced with \"rays\": {\"threads\"}\n"
	"(default 1; 0 = one per physical core), the same for every run whatever its\n"
	"build thread count, so ray figures compare trees. A builder without the\n"
	"parallel flag (`bvhlab list`) runs once per scene, at 1 thread; its other\n"
	"thread counts are listed as not applicable. Writes results.json,\n"
	"results.csv, report.md and report.html into the output folder after every\n"
	"run, so an interrupted sweep keeps what finished. Progress goes to stderr: one\n"
	"line per run, rewritten in place when stderr is a terminal.\n"
	"\n"
	"Each run's builds happen in a child process: a plugin that crashes, hangs\n"
	"past \"timeout_s\" (default 600) or exceeds \"memory_limit_mb\" is recorded as\n"
	"crashed, timeout or failed and the sweep goes on (\"isolate\": false in the\n"
	"config runs them in this process instead, for debugging).\n"
	"\n"
	"options:\n"
	"  --out DIR        output folder (overrides the config's \"output\")\n"
	"  --resume         keep the finished runs of the output folder's results.json\n"
	"                   and run only the missing ones (a fresh start if there is none);\n"
	"                   runs made with other builder or stage options run again\n"
	"  --retry-failed   with --resume: also run again the runs that did not end ok\n"
	"  --force          start afresh in a folder that holds results: the old files\n"
	"                   are moved aside to results.json.N, ... (without --resume or\n"
	"                   --force such a folder is refused)\n"
	"  --threads LIST   build thread counts, e.g. 1,2,0 (0 = one per physical core;\n"
	"                   overrides \"threads\")\n"
	"  --repeat N       timed builds per run (overrides \"repeat\"; not with a plan)\n"
	"  --only IDS       run just these runs (ids as `bvhlab plan` lists them: the\n"
	"                   order scenes x builders x thread counts, one for a serial\n"
	"                   builder, from 0), e.g. 3,7,10-12\n"
	"  --quiet          no progress lines\n"
	"  -h, --help       this text\n"
	"\n"
	"A plan.json written by `bvhlab plan` is run like its config; its runs'\n"
	"results record the plan's hash so `bvhlab merge` can join the parts. It is\n"
	"refused when the config it was planned from has changed since.\n"
	"\n"
	"Every builder's plugin and options, and every scene file (meshes, composite\n"
	"parts, frame files: there, readable, a PLY's header parsed), are checked\n"
	"before anything runs: a config with errors is refused whole (all of them\n"
	"printed), exit 2, and no output folder is made.\n"
	"\n"
	"exit status: 0 every run ok and valid, 1 some run failed or was invalid,\n"
	"2 bad arguments or config.\n";

struct run_args {
	const char *config;
	const char *out;
	const char *only;
	uint32_t threads[MAX_THREAD_COUNTS];
	size_t thread_count;
	unsigned long repeat;
	struct harness_options opts;
};

static int parse(int argc, char **argv, struct run_args *a)
{
	static const struct option longopts[] = {
		{"out", required_argument, NULL, 'o'},   {"threads", required_argument, NULL, 't'},
		{"repeat", required_argument, NULL, 'r'}, {"quiet", no_argument, NULL, 'q'},
		{"resume", no_argument, NULL, 'R'},      {"help", no_argument, NULL, 'h'},
		{"force", no_argument, NULL, 'F'},
		{"retry-failed", no_argument, NULL, 'Y'},
		{"only", required_argument, NULL, 'O'},
		{NULL, 0, NULL, 0}};
	int c;
	while ((c = getopt_long(argc, argv, "h", longopts, NULL)) != -1) {
		if (c == 'h') {
			fputs(usage, stdout);
			exit(0);
		} else if (c == 'o') {
			a->out = optarg;
		} else if (c == 't') {
			if (cli_parse_threads(optarg, a->threads, MAX_THREAD_COUNTS, &a->thread_count))
				return -1;
		} else if (c == 'r') {
			if (cli_parse_uint("--repeat", optarg, 100000, &a->repeat) || a->repeat == 0)
				return fprintf(stderr, "bvhlab: --repeat must be at least 1\n"), -1;
		} else if (c == 'q') {
			a->opts.quiet = true;
		} else if (c == 'R') {
			a->opts.resume = true;
		} else if (c == 'F') {
			a->opts.force = true;
		} else if (c == 'Y') {
			a->opts.retry_failed = true;
		} else if (c == 'O') {
			a->only = optarg;
		} else {
			return -1;
		}
	}
	if (optind != argc - 1) {
		fprintf(stderr, "bvhlab run: expected one config file\n\n%s", usage);
		return -1;
	}
	if (a->opts.resume && a->opts.force) {
		fprintf(stderr, "bvhlab run: --resume keeps the old results, --force moves them "
		        "aside: give one of them\n");
		return -1;
	}
	if (a->opts.retry_failed && !a->opts.resume) {
		fprintf(stderr, "bvhlab run: --retry-failed goes with --resume\n");
		return -1;
	}
	a->config = argv[optind];
	return 0;
}

/* Command-line overrides; --out is taken as given (relative to the cwd).
 * Thread counts stay as given: the run list resolves them (plan_runs.c). */
static int apply_overrides(struct config *cfg, const struct run_args *a, bvhlab_error *err)
{
	if (a->out) {
		char *out = strdup(a->out);
		if (!out)
			return error_set(err, "out of memory"), -1;
		free(cfg->output);
		cfg->output = out;
	}
	if (a->thread_count && config_set_threads(cfg, a->threads, a->thread_count) < 0)
		return error_set(err, "out of memory"), -1;
	if (a->repeat)
		cfg->repeat = (uint32_t)a->repeat;
	return 0;
}

/* The config, or a plan's (checked, its hash kept for the results). */
static int load(struct config *cfg, struct plan_file *plan, const struct run_args *a,
                bvhlab_error *err)
{
	if (plan_file_detect(a->config))
		return plan_file_load(plan, a->config, cfg, err);
	return config_load(cfg, a->config, err);
}

/* --only goes to the harness, which checks it against its run list. */
static int select_runs(struct run_args *a, bvhlab_error *err)
{
	if (a->thread_count && (a->only || a->opts.plan)) {
		/* Thread counts are part of a run's identity: other ones renumber the runs. */
		error_set(err, "--threads cannot be combined with --only or a plan: it changes the "
		          "runs and their ids (edit the config and plan again)");
		return -1;
	}
	if (a->repeat && a->opts.plan) {
		/* Every part of a plan measures alike, or the merge mixes sample counts. */
		error_set(err, "--repeat cannot be combined with a plan: its parts would measure "
		          "with other repeat counts than the plan's (edit the config and plan again)");
		return -1;
	}
	a->opts.only = a->only;
	return 0;
}

/* The sweep's last line: where the results are and what went wrong, by kind. */
static void print_outcome(const char *dir, int r, const struct harness_tally *t)
{
	fprintf(stderr, "bvhlab: results in %s/ (results.json, results.csv, report.md, "
	        "report.html)", dir);
	if (t->unsaved)
		fprintf(stderr, "; %zu finished run%s could not be saved (see above)", t->unsaved,
		        t->unsaved == 1 ? "" : "s");
	if (t->images_lost)
		fprintf(stderr, "; %zu image%s could not be written (see above)", t->images_lost,
		        t->images_lost == 1 ? "" : "s");
	if (t->untraced)
		fprintf(stderr, "; %zu run%s traced no rays (see their rays.error)", t->untraced,
		        t->untraced == 1 ? "" : "s");
	if (t->not_ok || (r && !t->unsaved && !t->untraced && !t->images_lost))
		fprintf(stderr, "; some runs failed or were invalid");
	fprintf(stderr, "\n");
}

int cmd_run(int argc, char **argv)
{
	struct run_args a = {0};
	struct config cfg = {0};
	struct plan_file plan = {0};
	bvhlab_error err = {{0}};
	if (parse(argc, argv, &a) < 0)
		return EXIT_USAGE;
	int status = EXIT_USAGE;
	int r = load(&cfg, &plan, &a, &err);
	a.opts.plan = r == 0 && plan.doc ? &plan : NULL;
	if (r < 0 || select_runs(&a, &err) < 0) {
		fprintf(stderr, "bvhlab: %s\n", err.message);
		goto out;
	}
	if (apply_overrides(&cfg, &a, &err) < 0) {
		fprintf(stderr, "bvhlab: %s\n", err.message);
		goto out;
	}
	struct harness_tally tally = {0};
	a.opts.tally = &tally;
	r = harness_run(&cfg, &a.opts, &err);
	if (r < 0) {
		fprintf(stderr, "bvhlab: %s\n", err.message);
		goto out;
	}
	if (!a.opts.quiet)
		print_outcome(cfg.output, r, &tally);
	status = r ? EXIT_RUNS_FAILED : 0;
out:
	plan_file_finish(&plan);
	config_finish(&cfg);
	return status;
}
