/*
 * A plan's part folders as read: each one's results.json, checked to come
 * from this very plan, and which runs ended ok (`bvhlab plan --missing`);
 * `bvhlab merge` (plan_merge.c) reads its parts the same way.
 */
#include <dirent.h>
#include <errno.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>
#include <unistd.h>

#include <cJSON.h>

#include "plan/plan.h"
#include "util/util.h"

static const char *string_at(const cJSON *o, const char *key)
{
	const cJSON *v = cJSON_GetObjectItemCaseSensitive(o, key);
	return cJSON_IsString(v) ? v->valuestring : NULL;
}

const char *plan_part_hash(const cJSON *doc)
{
	return string_at(cJSON_GetObjectItemCaseSensitive(doc, "plan"), "hash");
}

/* dir/results.json parsed; -ENOENT when there is none. */
int plan_part_read(const char *dir, cJSON **doc, bvhlab_error *err)
{
	char path[4096], *text = NULL;
	*doc = NULL;
	snprintf(path, sizeof(path), "%s/results.json", dir);
	if (access(path, F_OK) != 0)
		return -ENOENT;
	int r = plan_read_file(path, &text, err);
	if (r < 0)
		return r;
	*doc = cJSON_Parse(text);
	free(text);
	if (cJSON_IsObject(*doc) && cJSON_IsArray(cJSON_GetObjectItemCaseSensitive(*doc, "runs")))
		return 0;
	cJSON_Delete(*doc);
	*doc = NULL;
	error_set(err, "%s is not a bvhlab results document (damaged?)", path);
	return -EINVAL;
}

/* A part must be a results folder of this very plan. */
int plan_part_check(const struct plan_file *plan, const char *dir, const cJSON *doc,
                    bvhlab_error *err)
{
	const char *hash = plan_part_hash(doc);
	if (!hash) {
		error_set(err, "part %s was not run from a plan (its results.json has no \"plan\"): "
		          "run it as `bvhlab run %s --only ID --out %s`", dir, plan->path, dir);
		return -EINVAL;
	}
	if (strcmp(hash, plan->hash) != 0) {
		error_set(err, "part %s comes from another plan (hash %s; %s is %s): nothing merged",
		          dir, hash, plan->path, plan->hash);
		return -EINVAL;
	}
	return 0;
}

/* Marks the runs of one part folder that ended ok (a failed one is to be
 * run again); none when it has no results.json. */
static int mark_done(const struct plan_file *plan, const char *dir, bool *done,
                     bvhlab_error *err)
{
	cJSON *doc = NULL;
	int r = plan_part_read(dir, &doc, err);
	if (r == -ENOENT)
		return 0;
	if (r == 0)
		r = plan_part_check(plan, dir, doc, err);
	const cJSON *run, *runs = r == 0 ? cJSON_GetObjectItemCaseSensitive(doc, "runs") : NULL;
	cJSON_ArrayForEach(run, runs) {
		const cJSON *id = cJSON_GetObjectItemCaseSensitive(run, "id");
		const char *status = string_at(run, "status");
		if (cJSON_IsNumber(id) && id->valuedouble >= 0 &&
		    id->valuedouble < (double)plan->run_count && status && !strcmp(status, "ok"))
			done[(size_t)id->valuedouble] = true;
	}
	cJSON_Delete(doc);
	return r;
}

int plan_done_runs(const struct plan_file *plan, const char *parts_dir, bool **done,
                   bvhlab_error *err)
{
	char path[4096];
	*done = calloc(plan->run_count ? plan->run_count : 1, sizeof(**done));
	if (!*done) {
		error_set(err, "out of memory");
		return -ENOMEM;
	}
	DIR *d = opendir(parts_dir);
	if (!d)
		return 0; /* nothing run yet */
	int r = 0;
	for (struct dirent *e; r == 0 && (e = readdir(d));) {
		struct stat st;
		if ((size_t)snprintf(path, sizeof(path), "%s/%s", parts_dir, e->d_name) >= sizeof(path))
			continue;
		if (e->d_name[0] != '.' && stat(path, &st) == 0 && S_ISDIR(st.st_mode))
			r = mark_done(plan, path, *done, err);
	}
	closedir(d);
	return r;
}
