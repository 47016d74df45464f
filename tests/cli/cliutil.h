/*
 * Helpers of the CLI tests: run the bvhlab command as a user would, with
 * its output captured, and read what it wrote. Static, for one test
 * program each.
 */
#ifndef BVHLAB_TEST_CLIUTIL_H
#define BVHLAB_TEST_CLIUTIL_H

#include <fcntl.h>
#include <stdbool.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/wait.h>
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

/* Runs bvhlab with args (NULL-terminated); stdout/stderr into the buffers. */
static int run(const char *const *args)
{
	return finish(start(args));
}

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

static cJSON *load_results(const char *dir)
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

static int count_runs(const cJSON *doc, const char *builder, const char *status)
{
	int n = 0;
	const cJSON *run;
	cJSON_ArrayForEach(run, cJSON_GetObjectItem(doc, "runs"))
		n += !strcmp(run_str(run, "builder"), builder) && !strcmp(run_str(run, "status"), status);
	return n;
}

#define ARGS(...) ((const char *const[]){__VA_ARGS__, NULL})

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

#endif
