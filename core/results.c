/*
 * results.json: the document (schema in DESIGN.md) and its atomic writing.
 */
#include <errno.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>
#include <time.h>
#include <unistd.h>

#include <cJSON.h>

#include "harness.h"
#include "results.h"
#include "util.h"

/* mkdir -p: creates every missing folder of `path`. */
static int make_dirs(const char *path, bvhlab_error *err)
{
	char buf[4096];
	if ((size_t)snprintf(buf, sizeof(buf), "%s", path) >= sizeof(buf)) {
		error_set(err, "output folder name too long: %s", path);
		return -ENAMETOOLONG;
	}
	for (char *p = buf + 1;; p++) {
		char c = *p;
		if (c != '/' && c != '\0')
			continue;
		*p = '\0';
		if (mkdir(buf, 0777) < 0 && errno != EEXIST) {
			int e = errno;
			error_set(err, "cannot create output folder %s: %s", buf, strerror(e));
			return -e;
		}
		*p = c;
		if (c == '\0')
			return 0;
	}
}

static cJSON *machine_json(void)
{
	struct machine_info m;
	machine_info_read(&m);
	cJSON *o = cJSON_CreateObject();
	cJSON_AddStringToObject(o, "cpu", m.cpu);
	cJSON_AddNumberToObject(o, "cores", m.cores);
	cJSON_AddNumberToObject(o, "threads_available", m.threads_available);
	return o;
}

static void add_created(cJSON *doc)
{
	char stamp[64];
	time_t now = time(NULL);
	struct tm tm;
	gmtime_r(&now, &tm);
	strftime(stamp, sizeof(stamp), "%Y-%m-%dT%H:%M:%SZ", &tm);
	cJSON_AddStringToObject(doc, "created", stamp);
}

int results_init(struct results *res, const struct config *cfg, const char *dir,
                 bvhlab_error *err)
{
	memset(res, 0, sizeof(*res));
	int r = make_dirs(dir, err);
	if (r < 0)
		return r;
	res->dir = strdup(dir);
	res->doc = cJSON_CreateObject();
	if (!res->dir || !res->doc)
		goto nomem;
	cJSON_AddStringToObject(res->doc, "bvhlab_version", bvhlab_version());
	add_created(res->doc);
	cJSON_AddItemToObject(res->doc, "machine", machine_json());
	cJSON_AddItemToObject(res->doc, "config", cJSON_Duplicate(cfg->root, 1));
	res->scenes = cJSON_AddArrayToObject(res->doc, "scenes");
	res->runs = cJSON_AddArrayToObject(res->doc, "runs");
	if (!res->scenes || !res->runs)
		goto nomem;
	return 0;
nomem:
	results_finish(res);
	error_set(err, "out of memory creating results");
	return -ENOMEM;
}

void results_finish(struct results *res)
{
	cJSON_Delete(res->doc);
	free(res->dir);
	memset(res, 0, sizeof(*res));
}

int results_add_scene(struct results *res, const char *name, const char *source,
                      uint32_t triangles, const char *error)
{
	cJSON *o = cJSON_CreateObject();
	if (!o)
		return -ENOMEM;
	cJSON_AddStringToObject(o, "name", name ? name : "");
	cJSON_AddStringToObject(o, "source", source ? source : "");
	cJSON_AddNumberToObject(o, "triangles", triangles);
	if (error)
		cJSON_AddStringToObject(o, "error", error);
	cJSON_AddItemToArray(res->scenes, o);
	return 0;
}

static cJSON *options_json(const bvhlab_options *opts)
{
	cJSON *o = cJSON_CreateObject();
	for (uint32_t k = 0; opts && k < opts->builder->option_count; k++) {
		const char *name = opts->builder->options[k].name;
		const bvhlab_option_value *v = &opts->values[k];
		if (v->type == BVHLAB_OPTION_BOOL)
			cJSON_AddBoolToObject(o, name, v->b);
		else if (v->type == BVHLAB_OPTION_INT)
			cJSON_AddNumberToObject(o, name, (double)v->i);
		else if (v->type == BVHLAB_OPTION_FLOAT)
			cJSON_AddNumberToObject(o, name, v->f);
		else
			cJSON_AddStringToObject(o, name, v->s ? v->s : "");
	}
	return o;
}

static cJSON *timing_json(const struct run_record *run)
{
	double med, mn, mx;
	harness_summarise(run->samples_ms, run->sample_count, &med, &mn, &mx);
	cJSON *o = cJSON_CreateObject();
	cJSON_AddNumberToObject(o, "median", med);
	cJSON_AddNumberToObject(o, "min", mn);
	cJSON_AddNumberToObject(o, "max", mx);
	cJSON *samples = cJSON_AddArrayToObject(o, "samples");
	for (uint32_t k = 0; k < run->sample_count; k++)
		cJSON_AddItemToArray(samples, cJSON_CreateNumber(run->samples_ms[k]));
	return o;
}

static cJSON *tree_json(const bvhlab_tree_stats *st)
{
	cJSON *o = cJSON_CreateObject();
	cJSON_AddNumberToObject(o, "nodes", st->nodes);
	cJSON_AddNumberToObject(o, "leaves", st->leaves);
	cJSON_AddNumberToObject(o, "max_depth", st->max_depth);
	cJSON_AddNumberToObject(o, "avg_leaf_size", st->avg_leaf_size);
	cJSON_AddNumberToObject(o, "sah_cost", st->sah_cost);
	cJSON_AddNumberToObject(o, "memory_bytes", (double)st->memory_bytes);
	cJSON *hist = cJSON_AddArrayToObject(o, "leaf_size_histogram");
	for (int k = 0; k < BVHLAB_LEAF_HISTOGRAM; k++)
		cJSON_AddItemToArray(hist, cJSON_CreateNumber(st->leaf_histogram[k]));
	return o;
}

static cJSON *validation_json(const struct run_record *run)
{
	cJSON *o = cJSON_CreateObject();
	cJSON_AddBoolToObject(o, "valid", run->valid);
	cJSON_AddNumberToObject(o, "rays_checked", (double)run->rays_checked);
	cJSON_AddNumberToObject(o, "mismatches", (double)run->mismatches);
	return o;
}

int results_add_run(struct results *res, const struct run_record *run)
{
	cJSON *o = cJSON_CreateObject();
	if (!o)
		return -ENOMEM;
	cJSON_AddStringToObject(o, "scene", run->scene ? run->scene : "");
	cJSON_AddStringToObject(o, "builder", run->builder);
	cJSON_AddStringToObject(o, "plugin", run->plugin ? run->plugin : "");
	cJSON_AddNumberToObject(o, "threads", run->threads);
	cJSON_AddItemToObject(o, "options", options_json(run->opts));
	cJSON_AddStringToObject(o, "status", run->status);
	if (run->error)
		cJSON_AddStringToObject(o, "error", run->error);
	if (run->sample_count) {
		cJSON *t = timing_json(run);
		double med = cJSON_GetObjectItem(t, "median")->valuedouble;
		cJSON_AddItemToObject(o, "build_ms", t);
		cJSON_AddNumberToObject(o, "mtris_per_s",
		                        med > 0 ? run->triangles / (med * 1e3) : 0);
	}
	if (run->stats)
		cJSON_AddItemToObject(o, "tree", tree_json(run->stats));
	if (run->validated)
		cJSON_AddItemToObject(o, "validation", validation_json(run));
	cJSON_AddItemToArray(res->runs, o);
	return 0;
}

int results_write_file(const char *dir, const char *name, const char *text, bvhlab_error *err)
{
	char path[4096], tmp[4096];
	if ((size_t)snprintf(path, sizeof(path), "%s/%s", dir, name) >= sizeof(path) ||
	    (size_t)snprintf(tmp, sizeof(tmp), "%s/.%s.tmp", dir, name) >= sizeof(tmp)) {
		error_set(err, "path too long: %s/%s", dir, name);
		return -ENAMETOOLONG;
	}
	FILE *f = fopen(tmp, "w");
	if (!f)
		goto fail;
	size_t len = strlen(text);
	bool ok = fwrite(text, 1, len, f) == len;
	ok = (fflush(f) == 0) && ok;
	ok = (fclose(f) == 0) && ok;
	if (ok && rename(tmp, path) == 0)
		return 0;
fail:;
	int e = errno ? errno : EIO;
	error_set(err, "cannot write %s: %s", path, strerror(e));
	unlink(tmp);
	return -e;
}

/* One rendering of the document into one file. */
static int write_rendering(const struct results *res, const char *name, char *text,
                           bvhlab_error *err)
{
	if (!text) {
		error_set(err, "out of memory rendering %s", name);
		return -ENOMEM;
	}
	int r = results_write_file(res->dir, name, text, err);
	free(text);
	return r;
}

int results_write(const struct results *res, bvhlab_error *err)
{
	int r = write_rendering(res, "results.json", cJSON_Print(res->doc), err);
	if (r == 0)
		r = write_rendering(res, "results.csv", results_csv(res->doc), err);
	if (r == 0)
		r = write_rendering(res, "report.md", report_markdown(res->doc), err);
	return r;
}
