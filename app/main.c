/* bvhlab: build, check and compare BVH construction strategies. */
#include <stdio.h>
#include <string.h>

#include "cli.h"
#include "machine/machine.h"

static const char usage[] =
	"usage: bvhlab COMMAND [ARGS]\n"
	"\n"
	"Build, check and compare BVH construction strategies (builder plugins).\n"
	"\n"
	"commands:\n"
	"  run CONFIG.json [--out DIR] [--threads LIST] [--repeat N] [--only IDS]\n"
	"                        run an experiment: every scene x builder x thread count\n"
	"  list                  the plugins on the search path, with their options\n"
	"                        (--names: the names only)\n"
	"  info SCENE [--json]   triangle count and bounds of a mesh file or generator\n"
	"  info --machine        packages, physical cores, logical CPUs, caches (hwloc),\n"
	"                        OpenCL devices\n"
	"  build PLUGIN SCENE [--threads N] [-o KEY=VALUE]...\n"
	"                        one build, validated and measured\n"
	"  render PLUGIN SCENE -o FILE [--heat] [--width W --height H] [-O KEY=VALUE]...\n"
	"                        one image: the shaded scene or a heat map of nodes visited\n"
	"  report DIR|RESULTS.json [--out DIR] [--reference NAME] [--scene S] [--threads N]\n"
	"                        regenerate report.md, report.html and results.csv\n"
	"  plan CONFIG.json --out DIR [--format lines|slurm|json]\n"
	"                        split a sweep into commands for GNU parallel or Slurm\n"
	"  merge PART... --out DIR\n"
	"                        join the parts' results folders into one\n"
	"  help                  this text; `bvhlab COMMAND --help` for a command's\n"
	"  version               the version\n"
	"\n"
	"Plugins are found by name on $BVHLAB_PLUGIN_PATH, the build tree and the\n"
	"install folder, or given as a path to a .so file.\n";

int main(int argc, char **argv)
{
	if (argc < 2) {
		fputs(usage, stderr);
		return EXIT_USAGE;
	}
	const char *cmd = argv[1];
	/* Before any command can start the OpenCL ICD loader. */
	machine_icd_setup();
	if (!strcmp(cmd, "help") || !strcmp(cmd, "--help") || !strcmp(cmd, "-h")) {
		fputs(usage, stdout);
		return 0;
	}
	if (!strcmp(cmd, "version") || !strcmp(cmd, "--version")) {
		printf("bvhlab %s (plugin ABI %d.%d)\n", bvhlab_version(), BVHLAB_ABI_MAJOR,
		       BVHLAB_ABI_MINOR);
		return 0;
	}
	if (!strcmp(cmd, "run"))
		return cmd_run(argc - 1, argv + 1);
	if (!strcmp(cmd, "list"))
		return cmd_list(argc - 1, argv + 1);
	if (!strcmp(cmd, "info"))
		return cmd_info(argc - 1, argv + 1);
	if (!strcmp(cmd, "build"))
		return cmd_build(argc - 1, argv + 1);
	if (!strcmp(cmd, "render"))
		return cmd_render(argc - 1, argv + 1);
	if (!strcmp(cmd, "report"))
		return cmd_report(argc - 1, argv + 1);
	if (!strcmp(cmd, "plan"))
		return cmd_plan(argc - 1, argv + 1);
	if (!strcmp(cmd, "merge"))
		return cmd_merge(argc - 1, argv + 1);
	fprintf(stderr, "bvhlab: unknown command '%s'\n\n%s", cmd, usage);
	return EXIT_USAGE;
}
