/* The bvhlab command's subcommands. Each returns the process exit status. */
#ifndef BVHLAB_APP_CLI_H
#define BVHLAB_APP_CLI_H

#include <bvhlab/bvhlab.h>

/* Exit statuses: 0 success, 1 some run or check failed, 2 usage or input error. */
enum { EXIT_RUNS_FAILED = 1, EXIT_USAGE = 2 };

int cmd_run(int argc, char **argv);
int cmd_list(int argc, char **argv);
int cmd_info(int argc, char **argv);
int cmd_build(int argc, char **argv);
int cmd_render(int argc, char **argv);
int cmd_report(int argc, char **argv);
int cmd_plan(int argc, char **argv);
int cmd_merge(int argc, char **argv);

/*
 * A scene named on the command line: a mesh file, or a generator with
 * optional parameters, "icosphere:frequency=300,seed=2". `subdivide` applies
 * to either.
 */
int cli_load_scene(const char *spec, unsigned subdivide, bvhlab_scene **out, bvhlab_error *err);

/* What `build` and `render` start from: a plugin, its options, a scene. */
struct cli_target {
	bvhlab_plugin *plugin;
	bvhlab_options opts;
	bvhlab_scene *scene;
};

/*
 * Opens PLUGIN, applies its KEY=VALUE options and loads SCENE (see
 * cli_load_scene); on failure prints why, leaves nothing open and
 * returns -1.
 */
int cli_target_open(struct cli_target *t, const char *plugin, const char *scene,
                    unsigned subdivide, const char *const *options, int option_count);
void cli_target_close(struct cli_target *t);

/* Parses a comma-separated list of thread counts ("1,2,0"). */
int cli_parse_threads(const char *text, uint32_t *out, size_t max, size_t *count);

/* Parses a non-negative integer argument of an option, or prints why not. */
int cli_parse_uint(const char *opt, const char *text, unsigned long max, unsigned long *out);

#endif
