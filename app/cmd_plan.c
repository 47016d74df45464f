/* bvhlab plan: a config's runs as commands for GNU parallel, xargs or Slurm. */
#include <errno.h>
#include <getopt.h>
#include <limits.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <unistd.h>

#include <cJSON.h>

#include "cli.h"
#include "config/config.h"
#include "harness/harness_builders.h"
#include "harness/harness_threads.h"
#include "output/results.h"
#include "plan/plan.h"
#include "util/util.h"

static const char usage[] =
	"usage: bvhlab plan CONFIG.json --out DIR [--format lines|slurm|json] [options]\n"
	"       bvhlab plan --missing DIR [--format lines|slurm|json] [options]\n"
	"\n"
	"Splits a sweep into its runs (scene x builder x thread count, ids from 0 in\n"
	"the order `bvhlab run` takes them; a builder without the parallel flag once\n"
	"per scene, at 1 thread, as run does) so that other engines can spread them\n"
	"over machines. Checks every builder's plugin, refine stages and options\n"
	"(each plugin opened first in a forked probe; an optional builder whose\n"
	"plugin is missing is kept, as run keeps it) and the thread counts, writes\n"
	"DIR/plan.json (the config with absolute paths, its scene files' sizes and\n"
	"hashes, the plan's hash over both, the run list) and\n"
	"gives one command per run, each writing the results folder DIR/parts/ID:\n"
	"\n"
	"  lines   one shell command per line on stdout, for\n"
	"          `parallel --jobs 1 --sshloginfile hosts` or `xargs -P`\n"
	"  slurm   DIR/sweep.sbatch: a job array, one task per run, --exclusive (a\n"
	"          run's timings are not shared with other jobs), --cpus-per-task\n"
	"          the largest thread count; submit with `sbatch DIR/sweep.sbatch`\n"
	"  json    the runs with their commands, as a JSON array on stdout\n"
	"\n"
	"Then `bvhlab merge DIR/parts/* --out DIR` joins the parts. With --missing,\n"
	"only the runs that no folder of DIR/parts holds ended ok (--format slurm:\n"
	"DIR/sweep-missing.sbatch): a run that failed, crashed or timed out is run\n"
	"again (each command resumes its part with --retry-failed). Planning again\n"
	"into DIR is fine for the same config; another plan there is refused.\n"
	"\n"
	"options:\n"
	"  --out DIR        the plan's folder (plan.json, parts/, slurm/)\n"
	"  --missing DIR    commands for the runs not yet done of DIR/plan.json\n"
	"  --format F       lines (default), slurm or json\n"
	"  --jobs K         slurm: at most K array tasks at once (default 4)\n"
	"  --command CMD    how the machines call bvhlab (default: this program's\n"
	"                   absolute path)\n"
	"\n"
	"exit status: 0 planned, 2 bad arguments, config or plugin options.\n";

enum format { FORMAT_LINES, FORMAT_SLURM, FORMAT_JSON };

struct plan_args {
	const char *config, *out, *missing, *command;
	enum format format;
	unsigned long jobs;
};

static int parse_format(const char *text, enum format *out)
{
	static const char *const names[] = {"lines", "slurm", "json"};
	for (int k = 0; k < 3; k++)
		if (strcmp(text, names[k]) == 0)
			return *out = (enum format)k, 0;
	fprintf(stderr, "bvhlab plan: --format must be lines, slurm or json, not '%s'\n", text);
	return -1;
}

static bool has_control(const char *s)
{
	for (; *s; s++)
		if ((unsigned char)*s < 0x20 || *s == 0x7f)
			return true;
	return false;
}

static int parse(int argc, char **argv, struct plan_args *a)
{
	static const struct option longopts[] = {
		{"out", required_argument, NULL, 'o'},     {"missing", required_argument, NULL, 'm'},
		{"format", required_argument, NULL, 'f'},  {"jobs", required_argument, NULL, 'j'},
		{"command", required_argument, NULL, 'c'}, {"help", no_argument, NULL, 'h'},
		{NULL, 0, NULL, 0}};
	int c, r = 0;
	while (r == 0 && (c = getopt_long(argc, argv, "h", longopts, NULL)) != -1) {
		if (c == 'h')
			exit((fputs(usage, stdout), 0));
		else if (c == 'o' || c == 'm' || c == 'c')
			*(c == 'o' ? &a->out : c == 'm' ? &a->missing : &a->command) = optarg;
		else if (c == 'f')
			r = parse_format(optarg, &a->format);
		else if (c == 'j')
			r = cli_parse_uint("--jobs", optarg, 1000000, &a->jobs);
		else
			r = -1;
	}
	if (r == 0 && a->jobs == 0) {
		fprintf(stderr, "bvhlab plan: --jobs must be at least 1\n");
		r = -1;
	}
	bool operands_ok = a->missing ? optind == argc && !a->out : optind == argc - 1 && a->out;
	const char *dir = a->missing ? a->missing : a->out;
	if (r == 0 && operands_ok && (has_control(dir) || (a->command && has_control(a->command)))) {
		/* Shell lines, Slurm's #SBATCH lines and comments end at a newline. */
		fprintf(stderr, "bvhlab plan: the %s contains a control character (a newline?), "
		        "which a command line or sweep.sbatch cannot carry: choose another\n",
		        has_control(dir) ? "plan folder's name" : "--command");
		return -1;
	}
	if (r == 0 && !operands_ok) {
		fprintf(stderr, "bvhlab plan: expected CONFIG.json --out DIR, or --missing DIR\n\n%s",
		        usage);
		return -1;
	}
	a->config = a->missing ? NULL : argv[optind];
	return r;
}

/*
 * Opens every builder's plugin and refine stages, each first in a forked
 * probe, and applies their options: a plan that cannot run is refused
 * (every reason printed). An optional builder whose plugin is not here is
 * kept, as `run` keeps it: the machines that run the parts may have it.
 * Then the run list, as `run` makes it from the same builders.
 */
static int make_list(const struct config *cfg, struct run_list *list)
{
	struct harness_builder *builders = NULL;
	struct plan_builder *pb = calloc(cfg->builder_count + 1, sizeof(*pb));
	bvhlab_error err = {{0}};
	size_t bad_configs = 0;
	int bad = !pb || harness_open_builders(cfg, true, &builders, &bad_configs) < 0 ? -1 : 0;
	for (size_t b = 0; bad == 0 && b < cfg->builder_count; b++) {
		if (!builders[b].skipped && (!builders[b].plugin || !builders[b].opts_ok))
			bad = -1;
		pb[b] = harness_plan_builder(&builders[b]);
		pb[b].options_hash = NULL; /* closed with the builders; the parts record it */
	}
	if (bad == 0 && plan_list_make(list, cfg, pb, &err) < 0) {
		fprintf(stderr, "bvhlab: %s\n", err.message);
		bad = -1;
	}
	harness_close_builders(cfg, builders);
	free(pb);
	return bad;
}

/* A word for sh: as it is when harmless, else in single quotes. */
static void shell_word(struct strbuf *sb, const char *w)
{
	if (*w && strspn(w, "ABCDEFGHIJKLMNOPQRSTUVWXYZabcdefghijklmnopqrstuvwxyz0123456789"
	                    "_./-=,:+@%") == strlen(w)) {
		sb_printf(sb, "%s", w);
		return;
	}
	sb_printf(sb, "'");
	for (; *w; w++)
		sb_printf(sb, *w == '\'' ? "'\\''" : "%c", *w);
	sb_printf(sb, "'");
}

/* The command of one run; id NULL: "$SLURM_ARRAY_TASK_ID". */
static void run_command(struct strbuf *sb, const char *command, const char *dir, const char *id)
{
	char plan[PATH_MAX + 16], part[PATH_MAX + 64];
	snprintf(plan, sizeof(plan), "%s/plan.json", dir);
	snprintf(part, sizeof(part), "%s/parts/%s", dir, id ? id : "");
	shell_word(sb, command);
	sb_printf(sb, " run ");
	shell_word(sb, plan);
	sb_printf(sb, " --only %s --out ", id ? id : "\"$SLURM_ARRAY_TASK_ID\"");
	shell_word(sb, part);
	/* --retry-failed: a part that did not end ok is not done (--missing). */
	sb_printf(sb, "%s --resume --retry-failed --quiet", id ? "" : "\"$SLURM_ARRAY_TASK_ID\"");
}

/* What to emit: the plan's runs, those with want[id]. */
struct emit {
	const struct plan_file *plan;
	const char *dir;     /* absolute */
	const char *command; /* absolute or as given */
	const bool *want;    /* [run_count] */
	size_t count;        /* how many want */
};

/* The command of a run of the plan's, in *line (caller frees; NULL when
 * out of memory); false for a run not wanted. */
static bool wanted_command(const struct emit *e, const cJSON *run, char **line)
{
	int id = cJSON_GetObjectItemCaseSensitive(run, "id")->valueint;
	char idtext[16];
	struct strbuf sb = {0};
	if (!e->want[id])
		return false;
	snprintf(idtext, sizeof(idtext), "%d", id);
	run_command(&sb, e->command, e->dir, idtext);
	*line = sb_take(&sb);
	return true;
}

static void emit_lines(const struct emit *e)
{
	const cJSON *run;
	char *line;
	cJSON_ArrayForEach(run, cJSON_GetObjectItemCaseSensitive(e->plan->doc, "runs")) {
		if (!wanted_command(e, run, &line))
			continue;
		if (line)
			puts(line);
		free(line);
	}
}

static int emit_json(const struct emit *e)
{
	cJSON *out = cJSON_CreateArray();
	const cJSON *run;
	char *line;
	cJSON_ArrayForEach(run, cJSON_GetObjectItemCaseSensitive(e->plan->doc, "runs")) {
		if (!wanted_command(e, run, &line))
			continue;
		cJSON *o = cJSON_Duplicate(run, 1);
		cJSON_AddStringToObject(o, "command", line ? line : "");
		cJSON_AddItemToArray(out, o);
		free(line);
	}
	char *text = cJSON_Print(out);
	if (text)
		puts(text);
	free(text);
	cJSON_Delete(out);
	return text ? 0 : -1;
}

/* "0-11" or "3,5,9": the array indexes, which are the run ids. */
static void array_spec(struct strbuf *sb, const struct emit *e)
{
	if (e->count == e->plan->run_count) {
		sb_printf(sb, "0-%zu", e->plan->run_count - 1);
		return;
	}
	const char *sep = "";
	for (size_t id = 0; id < e->plan->run_count; id++)
		if (e->want[id]) {
			sb_printf(sb, "%s%zu", sep, id);
			sep = ",";
		}
}

/* The largest thread count; 0 (all cores) asks for no number: --exclusive gives the node. */
static unsigned max_threads(const struct plan_file *plan)
{
	unsigned most = 1;
	const cJSON *run;
	cJSON_ArrayForEach(run, cJSON_GetObjectItemCaseSensitive(plan->doc, "runs")) {
		const cJSON *t = cJSON_GetObjectItemCaseSensitive(run, "threads_configured");
		if (cJSON_IsNumber(t) && t->valuedouble > most)
			most = (unsigned)t->valuedouble;
	}
	return most;
}

static int emit_slurm(const struct emit *e, const char *name, unsigned long jobs)
{
	struct strbuf sb = {0};
	bvhlab_error err = {{0}};
	char slurm_dir[PATH_MAX + 8];
	snprintf(slurm_dir, sizeof(slurm_dir), "%s/slurm", e->dir);
	sb_printf(&sb, "#!/bin/sh\n# bvhlab plan %s: %zu of its %zu runs, one array task each.\n"
	               "# Submit: sbatch %s/%s\n# Then:   bvhlab merge %s/parts/* --out %s\n",
	          e->plan->hash, e->count, e->plan->run_count, e->dir, name, e->dir, e->dir);
	sb_printf(&sb, "#SBATCH --job-name=bvhlab-%.8s\n#SBATCH --array=", e->plan->hash);
	array_spec(&sb, e);
	/* --exclusive: another job on the node would skew the timings. */
	sb_printf(&sb, "%%%lu\n#SBATCH --exclusive\n#SBATCH --cpus-per-task=%u\n"
	               "#SBATCH --output=%s/task-%%a.out\n\nexec ",
	          jobs, max_threads(e->plan), slurm_dir);
	run_command(&sb, e->command, e->dir, NULL);
	sb_printf(&sb, "\n");
	char *text = sb_take(&sb);
	int r = text ? results_make_dirs(slurm_dir, &err) : -1;
	if (r == 0)
		r = results_write_file(e->dir, name, text, &err);
	free(text);
	if (r < 0) {
		fprintf(stderr, "bvhlab: %s\n", err.message[0] ? err.message : "out of memory");
		return -1;
	}
	fprintf(stderr, "bvhlab: %s/%s: %zu runs as a Slurm job array; submit it with "
	                "`sbatch %s/%s`\n", e->dir, name, e->count, e->dir, name);
	return 0;
}

static int emit(const struct emit *e, const struct plan_args *a)
{
	if (e->count == 0) {
		fprintf(stderr, "bvhlab: every run of %s is in %s/parts\n", e->plan->path, e->dir);
		return 0;
	}
	if (a->format == FORMAT_LINES)
		return emit_lines(e), 0;
	if (a->format == FORMAT_JSON)
		return emit_json(e);
	return emit_slurm(e, a->missing ? "sweep-missing.sbatch" : "sweep.sbatch", a->jobs);
}

/* The plan (new, or DIR/plan.json for --missing) and its folder, absolute. */
static int load_plan(const struct plan_args *a, struct plan_file *plan, char *dir)
{
	struct config cfg = {0};
	bvhlab_error err = {{0}};
	struct run_list list = {0};
	const char *d = a->missing ? a->missing : a->out;
	char path[PATH_MAX + 16];
	int r = 0;
	if (!a->missing && (r = config_load(&cfg, a->config, &err)) == 0 &&
	    (r = make_list(&cfg, &list)) == 0)
		r = plan_file_write(&list, d, plan, &err);
	plan_list_finish(&list);
	config_finish(&cfg);
	if (r == 0 && !realpath(d, dir)) {
		error_set(&err, "cannot resolve %s: %s", d, strerror(errno));
		r = -1;
	}
	if (r == 0 && has_control(dir)) {
		error_set(&err, "the plan folder's path %s contains a control character (a "
		          "newline?), which a command line or sweep.sbatch cannot carry", dir);
		r = -1;
	}
	snprintf(path, sizeof(path), "%s/plan.json", dir);
	if (r == 0 && a->missing)
		r = plan_file_load(plan, path, NULL, &err);
	if (r < 0 && err.message[0])
		fprintf(stderr, "bvhlab: %s\n", err.message);
	return r;
}

static int wanted(const struct plan_args *a, const struct plan_file *plan, const char *dir,
                  bool **want, size_t *count)
{
	bvhlab_error err = {{0}};
	char parts[PATH_MAX + 8];
	snprintf(parts, sizeof(parts), "%s/parts", dir);
	if (plan_done_runs(plan, parts, want, &err) < 0) {
		fprintf(stderr, "bvhlab: %s\n", err.message);
		return -1;
	}
	*count = 0;
	for (size_t id = 0; id < plan->run_count; id++) {
		(*want)[id] = !a->missing || !(*want)[id];
		*count += (*want)[id];
	}
	return 0;
}

int cmd_plan(int argc, char **argv)
{
	struct plan_args a = {.format = FORMAT_LINES, .jobs = 4};
	struct plan_file plan = {0};
	char dir[PATH_MAX], self[PATH_MAX];
	bool *want = NULL;
	if (parse(argc, argv, &a) < 0 || load_plan(&a, &plan, dir) < 0)
		return EXIT_USAGE;
	if (!a.command)
		a.command = realpath("/proc/self/exe", self) ? self : "bvhlab";
	struct emit e = {.plan = &plan, .dir = dir, .command = a.command};
	int status = wanted(&a, &plan, dir, &want, &e.count) < 0 ? EXIT_USAGE : 0;
	e.want = want;
	if (status == 0 && emit(&e, &a) < 0)
		status = EXIT_USAGE;
	free(want);
	plan_file_finish(&plan);
	return status;
}
