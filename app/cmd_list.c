/* bvhlab list: the plugins on the search path and their options. */
#include <stdbool.h>
#include <stdio.h>
#include <string.h>

#include "cli.h"
#include "harness/harness_builders.h"

static const char usage[] =
	"usage: bvhlab list [PLUGIN...]\n"
	"       bvhlab list --names\n"
	"\n"
	"Lists the builder plugins on the search path (or the named ones, by name or\n"
	"path) with their summary, flags and options (type, default, range, help).\n"
	"A plugin that cannot be loaded is listed with the reason; each is loaded\n"
	"first in a forked probe, so one that crashes or hangs (30 s) costs its line.\n"
	"--names prints only the names found on the search path, one a line,\n"
	"loading none.\n"	"\n"
	"search path: $BVHLAB_PLUGIN_PATH, then the build tree, then the install folder.\n";

static void print_flags(uint32_t flags)
{
	static const char *names[] = {"parallel", "deterministic", "spatial-splits", "UNFINISHED",
	                              "boxes", "device"};
	const char *sep = "";
	printf("  flags:");
	for (size_t k = 0; k < sizeof(names) / sizeof(names[0]); k++)
		if (flags & (1u << k)) {
			printf("%s %s", sep, names[k]);
			sep = ",";
		}
	printf("%s\n", *sep ? "" : " none");
}

/* A bound as the user writes it: 1073741824, not 1.07374e+09; 0.05. */
static void print_bound(double v, bool integer)
{
	char buf[64];
	bvhlab_option_value value = {.type = BVHLAB_OPTION_FLOAT, .f = v};
	if (integer && v >= -9.2e18 && v <= 9.2e18)
		value = (bvhlab_option_value){.type = BVHLAB_OPTION_INT, .i = (int64_t)v};
	bvhlab_option_format(&value, buf, sizeof(buf));
	printf("%s", buf);
}

static void print_range(const bvhlab_option_decl *d)
{
	bool integer = d->type == BVHLAB_OPTION_INT;
	printf(", range [");
	print_bound(d->min, integer);
	printf(", ");
	print_bound(d->max, integer);
	printf("]");
}

static void print_option(const bvhlab_option_decl *d)
{
	static const char *types[] = {"?", "bool", "int", "float", "string"};
	bvhlab_option_value v = {.type = d->type, .b = d->def_bool, .i = d->def_int,
	                         .f = d->def_float, .s = (char *)d->def_string};
	char def[128];
	bvhlab_option_format(&v, def, sizeof(def));
	printf("    %-12s %-6s default %s", d->name, types[d->type <= 4 ? d->type : 0], def);
	if (d->choices)
		printf(", one of %s", d->choices);
	else if (d->min <= d->max && (d->type == BVHLAB_OPTION_INT || d->type == BVHLAB_OPTION_FLOAT))
		/* Ranges mean something for numbers only; a bool's zeroed
		 * min and max would print as [0, 0]. */
		print_range(d);
	printf("\n      %s\n", d->help ? d->help : "");
}

/* Loading runs the plugin's code: a constructor that crashes or hangs
 * costs its own line of the list, not the listing. */
#define PROBE_TIMEOUT_S 30

static int list_one(const char *name)
{
	bvhlab_plugin *p = NULL;
	bvhlab_error err = {{0}};
	const char *status;
	if (harness_probe_plugin(name, PROBE_TIMEOUT_S, &status, &err) < 0 ||
	    bvhlab_plugin_open(name, &p, &err) < 0) {
		printf("%s: NOT USABLE: %s\n\n", name, err.message);
		return 1;
	}
	const bvhlab_builder *b = bvhlab_plugin_builder(p);
	printf("%s — %s%s\n  file: %s\n", b->name, b->summary ? b->summary : "",
	       b->flags & BVHLAB_BUILDER_UNFINISHED ? " [UNFINISHED]" : "", bvhlab_plugin_path(p));
	print_flags(b->flags);
	if (bvhlab_builder_refine(b))
		printf("  stage: %s\n", b->build ? "builds, and refines trees (\"refine\" lists)"
		                                 : "refines trees only (\"refine\" lists, --refine)");
	if (bvhlab_builder_update(b)) /* ABI 1.4 */
		printf("  update: updates trees whose primitives moved (\"animation\": "
		       "{\"update\": \"%s\"})\n", b->name);
	printf("  options:%s\n", b->option_count ? "" : " none");
	for (uint32_t k = 0; k < b->option_count; k++)
		print_option(&b->options[k]);
	printf("\n");
	bvhlab_plugin_close(p);
	return 0;
}

int cmd_list(int argc, char **argv)
{
	if (argc > 1 && (!strcmp(argv[1], "--help") || !strcmp(argv[1], "-h"))) {
		fputs(usage, stdout);
		return 0;
	}
	int bad = 0;
	bool names_only = argc == 2 && strcmp(argv[1], "--names") == 0;
	if (argc > 1 && !names_only) {
		for (int k = 1; k < argc; k++)
			bad |= list_one(argv[k]);
		return bad ? EXIT_RUNS_FAILED : 0;
	}
	char **names = NULL;
	bvhlab_error err = {{0}};
	if (bvhlab_plugin_names(&names, &err) < 0) {
		fprintf(stderr, "bvhlab: %s\n", err.message);
		return EXIT_USAGE;
	}
	if (!names[0])
		printf("no plugins found on the search path %s\n", bvhlab_plugin_search_path());
	for (char **n = names; *n; n++)
		if (names_only)
			printf("%s\n", *n);
		else
			bad |= list_one(*n);
	bvhlab_plugin_names_free(names);
	return bad ? EXIT_RUNS_FAILED : 0;
}
