/* bvhlab run: an experiment from a config file. */
#include <getopt.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "cli.h"
#include "config/config.h"
#include "harness/harness.h"

#define MAX_THREAD_COUNTS 64

static const char usage[] =
	"usage: bvhlab run CONFIG.json [options]\n"
	"\n"
	"Runs every scene x builder x thread count of the config: warm-up builds,\n"
	"timed builds, validation of the last tree (structure and rays against brute\n"
	"force), tree metrics, rays traced through the tree (primary and diffuse, with\n"
	"every hardware thread) and, with \"images\": true, images. Writes results.json,\n"
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
	"                   and run only the missing ones (a fresh start if there is none)\n"
	"  --threads LIST   thread counts, e.g. 1,2,0 (0 = all cores; overrides \"threads\")\n"
	"  --repeat N       timed builds per run (overrides \"repeat\")\n"
	"  --quiet          no progress lines\n"
	"  -h, --help       this text\n"
	"\n"
	"exit status: 0 every run ok and valid, 1 some run failed or was invalid,\n"
	"2 bad arguments or config.\n";

struct run_args {
	const char *config;
	const char *out;
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
		} else {
			return -1;
		}
	}
	if (optind != argc - 1) {
		fprintf(stderr, "bvhlab run: expected one config file\n\n%s", usage);
		return -1;
	}
	a->config = argv[optind];
	return 0;
}

/* Command-line overrides; --out is taken as given (relative to the cwd). */
static int apply_overrides(struct config *cfg, const struct run_args *a)
{
	if (a->out) {
		char *out = strdup(a->out);
		if (!out)
			return -1;
		free(cfg->output);
		cfg->output = out;
	}
	if (a->thread_count && config_set_threads(cfg, a->threads, a->thread_count) < 0)
		return -1;
	if (a->repeat)
		cfg->repeat = (uint32_t)a->repeat;
	return 0;
}

int cmd_run(int argc, char **argv)
{
	struct run_args a = {0};
	struct config cfg = {0};
	bvhlab_error err = {{0}};
	if (parse(argc, argv, &a) < 0)
		return EXIT_USAGE;
	if (config_load(&cfg, a.config, &err) < 0) {
		fprintf(stderr, "bvhlab: %s\n", err.message);
		config_finish(&cfg);
		return EXIT_USAGE;
	}
	int status = EXIT_USAGE;
	if (apply_overrides(&cfg, &a) < 0) {
		fprintf(stderr, "bvhlab: out of memory\n");
		goto out;
	}
	int r = harness_run(&cfg, &a.opts, &err);
	if (r < 0) {
		fprintf(stderr, "bvhlab: %s\n", err.message);
		goto out;
	}
	if (!a.opts.quiet)
		fprintf(stderr, "bvhlab: results in %s/ (results.json, results.csv, report.md, report.html)%s\n",
		        cfg.output, r ? "; some runs failed or were invalid" : "");
	status = r ? EXIT_RUNS_FAILED : 0;
out:
	config_finish(&cfg);
	return status;
}
