/*
 * Helpers of the CLI tests: run the bvhlab command as a user would, with
 * its output captured, and read what it wrote. Static, for one test
 * program each.
 */
#ifndef BVHLAB_TEST_CLIUTIL_H
#define BVHLAB_TEST_CLIUTIL_H

#include <fcntl.h>
#include <signal.h>
#include <stdbool.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>
#include <sys/wait.h>
#include <time.h>
#include <unistd.h>

#include <cJSON.h>

#include "../testutil.h"

static const char *exe;
static char tmpdir[] = "/tmp/bvhlab-cli-XXXXXX";
static char out_text[1 << 16], err_text[1 << 16];

static void slurp(const char *path, char *buf, size_t size)
{
	buf[0] = '\0';
	FILE *f = fopen(path, "r");
	if (!f)
		return;
	size_t n = fread(buf, 1, size - 1, f);
	buf[n] = '\0';
	fclose(f);
}

static char *read_file(const char *dir, const char *name)
{
	char path[512];
	snprintf(path, sizeof(path), "%s/%s", dir, name);
	FILE *f = fopen(path, "r");
	if (!f)
		return NULL;
	fseek(f, 0, SEEK_END);
	long n = ftell(f);
	rewind(f);
	char *text = calloc(1, (size_t)n + 1);
	if (text && fread(text, 1, (size_t)n, f) != (size_t)n)
		text[0] = '\0';
	fclose(f);
	return text;
}

/* Starts bvhlab with args (NULL-terminated) in `cwd` (NULL: here), killed
 * by SIGALRM after `limit` s (0: never); stdout/stderr into files. */
static pid_t start_in(const char *cwd, unsigned limit, const char *const *args)
{
	char out_path[256], err_path[256];
	snprintf(out_path, sizeof(out_path), "%s/stdout", tmpdir);
	snprintf(err_path, sizeof(err_path), "%s/stderr", tmpdir);
	pid_t pid = fork();
	if (pid == 0) {
		int o = open(out_path, O_WRONLY | O_CREAT | O_TRUNC, 0644);
		int e = open(err_path, O_WRONLY | O_CREAT | O_TRUNC, 0644);
		dup2(o, 1);
		dup2(e, 2);
		if (cwd && chdir(cwd) != 0)
			_exit(126);
		char *argv[32] = {(char *)exe};
		for (int k = 0; args[k] && k < 30; k++)
			argv[k + 1] = (char *)args[k];
		if (limit)
			alarm(limit); /* survives exec: a hung bvhlab dies of SIGALRM */
		execv(exe, argv);
		_exit(127);
	}
	return pid;
}

/* Starts bvhlab with args (NULL-terminated), here, with no time limit. */
static pid_t start(const char *const *args)
{
	return start_in(NULL, 0, args);
}

/* Waits for a started bvhlab; its output into the buffers. */
static int finish(pid_t pid)
{
	char out_path[256], err_path[256];
	snprintf(out_path, sizeof(out_path), "%s/stdout", tmpdir);
	snprintf(err_path, sizeof(err_path), "%s/stderr", tmpdir);
	int status = 0;
	waitpid(pid, &status, 0);
	slurp(out_path, out_text, sizeof(out_text));
	slurp(err_path, err_text, sizeof(err_text));
	return WIFEXITED(status) ? WEXITSTATUS(status) : 128 + WTERMSIG(status);
}

/* tmpdir/name, in one of four rotating buffers (so up to four may be used
 * at once, in one call's arguments). */
static inline const char *cli_path_in(const char *name)
{
	static char buf[4][600];
	static int next;
	char *p = buf[next++ % 4];
	snprintf(p, 600, "%s/%s", tmpdir, name);
	return p;
}

/* Whether something (a link too) is at path. */
static inline bool cli_exists(const char *path)
{
	struct stat st;
	return lstat(path, &st) == 0;
}

/* Runs bvhlab with args (NULL-terminated); stdout/stderr into the buffers. */
static int run(const char *const *args)
{
	return finish(start(args));
}

#define ARGS(...) ((const char *const[]){__VA_ARGS__, NULL})

static char *write_config(const char *name, const char *text)
{
	static char path[512];
	snprintf(path, sizeof(path), "%s/%s", tmpdir, name);
	FILE *f = fopen(path, "w");
	fputs(text, f);
	fclose(f);
	return path;
}

/* The number of runs in dir/results.json, or -1 while there is none to read. */
static inline int runs_written(const char *dir)
{
	char *text = read_file(dir, "results.json");
	cJSON *doc = text ? cJSON_Parse(text) : NULL;
	int n = doc ? cJSON_GetArraySize(cJSON_GetObjectItem(doc, "runs")) : -1;
	cJSON_Delete(doc);
	free(text);
	return n;
}

static inline cJSON *load_results(const char *dir)
{
	char *text = read_file(dir, "results.json");
	CHECK(text != NULL);
	cJSON *doc = text ? cJSON_Parse(text) : NULL;
	CHECK(doc != NULL);
	free(text);
	return doc;
}

static const char *run_str(const cJSON *run, const char *key)
{
	const cJSON *v = cJSON_GetObjectItem(run, key);
	return cJSON_IsString(v) ? v->valuestring : "";
}

static inline int count_runs(const cJSON *doc, const char *builder, const char *status)
{
	int n = 0;
	const cJSON *run;
	cJSON_ArrayForEach(run, cJSON_GetObjectItem(doc, "runs"))
		n += !strcmp(run_str(run, "builder"), builder) && !strcmp(run_str(run, "status"), status);
	return n;
}

/* The run of `builder` on `scene` with `threads` threads in a results
 * document; NULL when there is none (or its threads are not a number). */
static inline const cJSON *find_run(const cJSON *doc, const char *scene, const char *builder,
                                    int threads)
{
	const cJSON *run;
	cJSON_ArrayForEach(run, cJSON_GetObjectItem(doc, "runs")) {
		const cJSON *t = cJSON_GetObjectItem(run, "threads");
		if (!strcmp(run_str(run, "scene"), scene) && !strcmp(run_str(run, "builder"), builder) &&
		    cJSON_IsNumber(t) && t->valueint == threads)
			return run;
	}
	return NULL;
}

/* Polls (bounded: about a minute) until the sweep has written at least one
 * run to dir/results.json; that count, or -1 when it never did. */
static inline int wait_for_runs(const char *dir)
{
	const struct timespec pause = {.tv_nsec = 10 * 1000 * 1000};
	int n = -1;
	for (int k = 0; k < 6000 && n < 1; k++) {
		n = runs_written(dir);
		if (n < 1)
			nanosleep(&pause, NULL);
	}
	return n;
}

/*
 * A sweep killed mid-way and resumed: its config kill.json has a builder
 * "gated" that blocks until the file `gate` appears, so the kill surely
 * lands mid-sweep; its output folder is out-kill.
 */
struct kill_sweep {
	char gate[512], dir[512], cfg[512];
};

/* Writes kill.json from `format` (its one %s: the gate file), runs it until
 * it has written a run, then kills it with SIGKILL (checked): the runs
 * written before, -1 if none ever was. */
static inline int kill_sweep_start(struct kill_sweep *k, const char *format)
{
	char text[2048];
	snprintf(k->gate, sizeof(k->gate), "%s/gate", tmpdir);
	snprintf(k->dir, sizeof(k->dir), "%s/out-kill", tmpdir);
	snprintf(text, sizeof(text), format, k->gate);
	snprintf(k->cfg, sizeof(k->cfg), "%s", write_config("kill.json", text));
	pid_t pid = start(ARGS("run", k->cfg));
	int before = wait_for_runs(k->dir);
	kill(pid, SIGKILL);
	CHECK_INT(finish(pid), 128 + SIGKILL);
	return before;
}

/* Opens the gate (checked) and runs the sweep with --resume: its status. */
static inline int kill_sweep_resume(const struct kill_sweep *k)
{
	FILE *f = fopen(k->gate, "w");
	CHECK(f != NULL);
	if (f)
		fclose(f);
	return run(ARGS("run", k->cfg, "--resume"));
}

/* A run's member `key` as compact JSON text (to free), NULL for no run. */
static inline char *run_item_text(const cJSON *run, const char *key)
{
	return run ? cJSON_PrintUnformatted(cJSON_GetObjectItem(run, key)) : NULL;
}

/* Appends `more` to the colon-separated options in environment variable
 * `var`, for the children started after. */
static inline void append_option(const char *var, const char *more)
{
	const char *old = getenv(var);
	char opts[512];
	snprintf(opts, sizeof(opts), "%s%s%s", old ? old : "", old && *old ? ":" : "", more);
	setenv(var, opts, 1);
}

/* ASan's own SEGV handler would turn the plugins' crashes into aborts. */
static inline void plain_crashes(void)
{
	append_option("ASAN_OPTIONS", "handle_segv=0");
}

/* Long enough for any run of the tests on a loaded machine; a hang ends here. */
#define CLI_LIMIT_S 60

/* Runs bvhlab with args (NULL-terminated) in `cwd` (NULL: here), killed
 * after CLI_LIMIT_S; stdout/stderr into the buffers. */
static inline int run_in(const char *cwd, const char *const *args)
{
	return finish(start_in(cwd, CLI_LIMIT_S, args));
}

/* Runs config `text`, written as `name` in tmpdir (`run --quiet`): it
 * must exit 2 with `message` on stderr (checked). */
static inline void cli_refused(const char *name, const char *text, const char *message)
{
	CHECK_INT(run_in(NULL, ARGS("run", "--quiet", write_config(name, text))), 2);
	CHECK_CONTAINS(err_text, message);
}

/* cli_refused of the config `format` gives with `value` in its one %s. */
static inline void cli_refused_with(const char *name, const char *format, const char *value,
                                    const char *message)
{
	char text[2048];
	snprintf(text, sizeof(text), format, value);
	cli_refused(name, text, message);
}

/* Plans config `name` (checked) into tmpdir/`plan`: builders "a" and "b"
 * of fake_good over one 100-triangle soup "s", repeat 1, with `more`
 * (members and their commas, "" for none) besides. */
static inline void cli_plan_ab(const char *name, const char *more, const char *plan)
{
	char text[1024];
	snprintf(text, sizeof(text),
	         "{ \"repeat\": 1, %s\n"
	         "  \"scenes\": [ { \"name\": \"s\", \"generator\": \"soup\", \"count\": 100 } ],\n"
	         "  \"builders\": [ { \"plugin\": \"fake_good\", \"name\": \"a\" },\n"
	         "                  { \"plugin\": \"fake_good\", \"name\": \"b\" } ] }\n",
	         more);
	CHECK_INT(run_in(tmpdir, ARGS("plan", write_config(name, text), "--out", plan)), 0);
}

/* Runs part k of the plan in tmpdir/`plan` into plan/parts/K (`run
 * PLAN/plan.json --only K --out ... --quiet`, in tmpdir): its exit status. */
static inline int cli_run_part(const char *plan, int k)
{
	char id[16], plan_json[512], out[512];
	snprintf(id, sizeof(id), "%d", k);
	snprintf(plan_json, sizeof(plan_json), "%s/plan.json", plan);
	snprintf(out, sizeof(out), "%s/parts/%d", plan, k);
	return run_in(tmpdir, ARGS("run", cli_path_in(plan_json), "--only", id, "--out",
	                           cli_path_in(out), "--quiet"));
}

/* Makes tmpdir and takes the command's path; false on bad arguments. */
static bool cli_begin(int argc, char **argv)
{
	if (argc != 3 || !mkdtemp(tmpdir))
		return false;
	exe = argv[1];
	return true;
}

/* Leaves tmpdir for inspection only when something failed; the exit status. */
static int cli_end(void)
{
	if (!test_failures) {
		char cmd[600];
		snprintf(cmd, sizeof(cmd), "rm -rf '%s'", tmpdir);
		CHECK_INT(system(cmd), 0);
	} else {
		fprintf(stderr, "files kept in %s\n", tmpdir);
	}
	return test_finish();
}

/* A test program's modes: the one named on its command line runs. */
struct cli_mode {
	const char *name;
	void (*fn)(void);
};

/* main() of a program run as `PROGRAM BVHLAB_EXE MODE`: runs MODE from
 * `modes` with the command's absolute path (modes may run it from other
 * folders); the exit status, 2 on bad arguments or an unknown mode. */
static inline int cli_main_modes(int argc, char **argv, const char *program,
                                 const struct cli_mode *modes, size_t n)
{
	static char absolute[4096];
	if (!cli_begin(argc, argv))
		return fprintf(stderr, "usage: %s BVHLAB_EXE MODE\n", program), 2;
	if (realpath(argv[1], absolute))
		exe = absolute;
	for (size_t k = 0; k < n; k++)
		if (!strcmp(argv[2], modes[k].name)) {
			modes[k].fn();
			return cli_end();
		}
	fprintf(stderr, "%s: unknown mode %s\n", program, argv[2]);
	return 2;
}

#endif
