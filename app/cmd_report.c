/* bvhlab report: results.csv, report.md and report.html again from a saved
 * results.json, optionally re-based on another reference or narrowed to
 * some scenes and thread counts. */
#include <errno.h>
#include <getopt.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>

#include "cli.h"
#include "output/results.h"

static const char report_usage[] =
	"usage: bvhlab report DIR|RESULTS.json [--out DIR] [--reference NAME]\n"
	"                     [--scene NAME]... [--threads N]...\n"
	"\n"
	"Regenerates results.csv, report.md and report.html from a saved results.json\n"
	"(or DIR/results.json), into DIR (default: the folder of RESULTS.json). Images\n"
	"are referenced as images/... relative to the report, as `bvhlab run` wrote them.\n"
	"results.json itself is only read.\n"
	"\n"
	"  --reference NAME  the reference builder (a label, or a plugin's first builder)\n"
	"                    as if the config's report.reference had named it\n"
	"  --scene NAME      only this scene's runs (repeat for more)\n"
	"  --threads N       only the runs with N threads (repeat for more)\n";

#define MAX_FILTERS 64

struct report_args {
	struct results_view view;
	const char *scenes[MAX_FILTERS];
	double threads[MAX_FILTERS];
	const char *out;
};

/* One --threads value: a whole count from 1 up. */
static int add_threads(struct report_args *a, const char *text)
{
	char *end;
	long n = strtol(text, &end, 10);
	if (*end || n < 1 || n > 4096) {
		fprintf(stderr, "bvhlab report: --threads '%s': not a thread count\n", text);
		return -EINVAL;
	}
	a->threads[a->view.threads_count++] = (double)n;
	return 0;
}

static int parse(int argc, char **argv, struct report_args *a)
{
	static const struct option longopts[] = {
		{"out", required_argument, NULL, 'o'}, {"reference", required_argument, NULL, 'r'},
		{"scene", required_argument, NULL, 's'}, {"threads", required_argument, NULL, 't'},
		{"help", no_argument, NULL, 'h'}, {NULL, 0, NULL, 0}};
	int c;
	while ((c = getopt_long(argc, argv, "h", longopts, NULL)) != -1) {
		if (c == 'h')
			return fputs(report_usage, stdout), 1;
		if ((c == 's' && a->view.scene_count == MAX_FILTERS) ||
		    (c == 't' && a->view.threads_count == MAX_FILTERS)) {
			fprintf(stderr, "bvhlab report: at most %d --scene and --threads each\n",
			        MAX_FILTERS);
			return -EINVAL;
		}
		if (c == 'o')
			a->out = optarg;
		else if (c == 'r')
			a->view.reference = optarg;
		else if (c == 's')
			a->scenes[a->view.scene_count++] = optarg;
		else if (c != 't' || add_threads(a, optarg) < 0)
			return -EINVAL;
	}
	a->view.scenes = a->scenes;
	a->view.threads = a->threads;
	if (optind != argc - 1) {
		fprintf(stderr, "bvhlab report: expected one results.json or folder\n\n%s",
		        report_usage);
		return -EINVAL;
	}
	return 0;
}

int cmd_report(int argc, char **argv)
{
	struct report_args a = {0};
	int r = parse(argc, argv, &a);
	if (r != 0)
		return r > 0 ? 0 : EXIT_USAGE;
	char json[4096], dir[4096];
	struct stat st;
	const char *arg = argv[optind];
	if (stat(arg, &st) == 0 && S_ISDIR(st.st_mode)) { /* a sweep's folder */
		snprintf(json, sizeof(json), "%s/results.json", arg);
		snprintf(dir, sizeof(dir), "%s", arg);
	} else {
		const char *slash = strrchr(arg, '/');
		snprintf(json, sizeof(json), "%s", arg);
		snprintf(dir, sizeof(dir), "%.*s", slash ? (int)(slash - arg) : 1, slash ? arg : ".");
	}
	bvhlab_error err = {{0}};
	if (results_render_saved(json, a.out ? a.out : dir, &a.view, &err) < 0) {
		fprintf(stderr, "bvhlab: %s\n", err.message);
		return EXIT_USAGE;
	}
	return 0;
}
