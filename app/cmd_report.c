/* bvhlab report: results.csv, report.md and report.html again from a saved results.json. */
#include <getopt.h>
#include <stdio.h>
#include <string.h>

#include "cli.h"
#include "output/results.h"

static const char report_usage[] =
	"usage: bvhlab report RESULTS.json [--out DIR]\n"
	"\n"
	"Regenerates results.csv, report.md and report.html from a saved results.json,\n"
	"into DIR (default: the folder of RESULTS.json). Images are referenced as\n"
	"images/... relative to the report, as `bvhlab run` wrote them.\n";

int cmd_report(int argc, char **argv)
{
	static const struct option longopts[] = {
		{"out", required_argument, NULL, 'o'}, {"help", no_argument, NULL, 'h'},
		{NULL, 0, NULL, 0}};
	const char *out = NULL;
	int c;
	while ((c = getopt_long(argc, argv, "h", longopts, NULL)) != -1) {
		if (c == 'h')
			return fputs(report_usage, stdout), 0;
		if (c != 'o')
			return EXIT_USAGE;
		out = optarg;
	}
	if (optind != argc - 1) {
		fprintf(stderr, "bvhlab report: expected one results.json\n\n%s", report_usage);
		return EXIT_USAGE;
	}
	char dir[4096];
	const char *json = argv[optind], *slash = strrchr(json, '/');
	snprintf(dir, sizeof(dir), "%.*s", slash ? (int)(slash - json) : 1, slash ? json : ".");
	bvhlab_error err = {{0}};
	if (results_render_saved(json, out ? out : dir, &err) < 0) {
		fprintf(stderr, "bvhlab: %s\n", err.message);
		return EXIT_USAGE;
	}
	return 0;
}
