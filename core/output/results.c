/*
 * results.json: the document (schema in docs/design.md) and its atomic writing.
 */
#include <errno.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>
#include <time.h>
#include <unistd.h>

#include <cJSON.h>

#include "output/report.h"
#include "output/results.h"
#include "output/safe_file.h"
#include "util/util.h"

static cJSON *machine_json(void)
{
	struct machine_info m;
	machine_info_read(&m);
	cJSON *o = cJSON_CreateObject();
	char host[256] = "";
	/* Parts of one plan may run on several machines: merge tells them apart by it. */
	gethostname(host, sizeof(host) - 1);
	cJSON_AddStringToObject(o, "hostname", host);
	cJSON_AddStringToObject(o, "cpu", m.cpu);
	const struct results_number counts[] = {
		{"cores", m.cores},
		{"threads_available", m.threads_available},
		{"packages", m.topo.packages},
		{"physical_cores", m.topo.physical_cores},
		{"logical_cpus", m.topo.logical_cpus},
	};
	results_add_numbers(o, counts, RESULTS_NUMBERS(counts));
	/* "caches": { "L1d": { "bytes": 49152, "instances": 2 }, ... }, known levels. */
	cJSON *caches = cJSON_AddObjectToObject(o, "caches");
	for (int k = 0; caches && k < MACHINE_CACHE_LEVELS; k++) {
		if (m.topo.caches[k].size == 0)
			continue;
		cJSON *c = cJSON_AddObjectToObject(caches, machine_cache_name(k));
		cJSON_AddNumberToObject(c, "bytes", (double)m.topo.caches[k].size);
		cJSON_AddNumberToObject(c, "instances", m.topo.caches[k].instances);
	}
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
	res->dir = strdup(dir);
	res->doc = cJSON_CreateObject();
	if (!res->dir || !res->doc)
		goto nomem;
	results_normalise_dir(res->dir);
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
	results_unlock(res);
	free(res->stale);
	cJSON_Delete(res->doc);
	free(res->dir);
	memset(res, 0, sizeof(*res));
}

static cJSON *find_scene(const struct results *res, const char *name)
{
	cJSON *scene;
	cJSON_ArrayForEach(scene, res->scenes) {
		const cJSON *n = cJSON_GetObjectItemCaseSensitive(scene, "name");
		if (cJSON_IsString(n) && strcmp(n->valuestring, name) == 0)
			return scene;
	}
	return NULL;
}

/* A scene seen again (a resumed sweep loads it anew) replaces its entry. */
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
	cJSON *old = find_scene(res, name ? name : "");
	if (old)
		cJSON_ReplaceItemViaPointer(res->scenes, old, o);
	else
		cJSON_AddItemToArray(res->scenes, o);
	return 0;
}

int results_scene_instances(struct results *res, const char *name,
                            const struct results_instances *in)
{
	cJSON *scene = find_scene(res, name), *o = cJSON_CreateObject();
	if (!scene || !o) {
		cJSON_Delete(o);
		return -ENOMEM;
	}
	cJSON_AddNumberToObject(o, "meshes", in->meshes);
	cJSON_AddNumberToObject(o, "instances", in->instances);
	cJSON_AddNumberToObject(o, "unique_triangles", (double)in->unique_triangles);
	cJSON_AddNumberToObject(o, "instanced_triangles", (double)in->instanced_triangles);
	cJSON_AddItemToObject(scene, "instances", o);
	return 0;
}

static cJSON *find_any(const struct results *res, const struct run_identity *key, bool stale);

/* A run made again takes its stale record's place (which stayed on disk
 * until now); any other is appended. */
static void replace_or_add(struct results *res, const struct run_record *run, cJSON *o)
{
	struct run_identity slot = {.scene = run->scene ? run->scene : "", .builder = run->builder,
	                            .threads = run->threads,
	                            .threads_configured = RUN_THREADS_UNKNOWN};
	cJSON *old = find_any(res, run->key ? run->key : &slot, true);
	if (!old) {
		cJSON_AddItemToArray(res->runs, o);
		return;
	}
	for (size_t k = 0; k < res->stale_count; k++)
		if (res->stale[k] == old)
			res->stale[k] = res->stale[--res->stale_count];
	cJSON_ReplaceItemViaPointer(res->runs, old, o);
}

int results_add_run(struct results *res, const struct run_record *run)
{
	cJSON *o = results_run_json(run);
	if (!o)
		return -ENOMEM;
	replace_or_add(res, run, o);
	return 0;
}

int results_write_file(const char *dir, const char *name, const char *text, bvhlab_error *err)
{
	return safe_write_file(dir, name, text, strlen(text), err);
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

static const char *const renderings[] = {"results.json", "results.csv", "report.md",
                                         "report.html"};

int results_write_renderings(const struct results *res, bvhlab_error *err)
{
	int r = write_rendering(res, renderings[0], cJSON_Print(res->doc), err);
	if (r == 0)
		r = write_rendering(res, renderings[1], report_csv(res->doc), err);
	if (r == 0)
		r = write_rendering(res, renderings[2], report_markdown(res->doc), err);
	if (r == 0)
		r = write_rendering(res, renderings[3], report_html(res->doc), err);
	if (r == 0) /* animated scenes' frames, long form: results_frames.c */
		r = results_frames_csv(res->doc, res->dir, err);
	return r;
}

/* ---- resuming ---------------------------------------------------------------- */

static bool is_finished(const char *status)
{
	static const char *const finished[] = {"ok", "invalid", "failed", "crashed", "timeout"};
	for (size_t k = 0; k < sizeof(finished) / sizeof(finished[0]); k++)
		if (strcmp(status, finished[k]) == 0)
			return true;
	return false;
}

static const char *string_of(const cJSON *obj, const char *key)
{
	const cJSON *v = cJSON_GetObjectItemCaseSensitive(obj, key);
	return cJSON_IsString(v) ? v->valuestring : NULL;
}

bool results_is_stale(const struct results *res, const cJSON *run)
{
	for (size_t k = 0; k < res->stale_count; k++)
		if (res->stale[k] == run)
			return true;
	return false;
}

/* The document's run of key's slot, or NULL; one to be made again
 * (stale) only when `stale`. */
static cJSON *find_any(const struct results *res, const struct run_identity *key, bool stale)
{
	cJSON *run;
	cJSON_ArrayForEach(run, res->runs) {
		struct run_identity have;
		run_identity_read(run, &have);
		if (run_identity_compare(key, &have, NULL) != RUN_OTHER &&
		    stale == results_is_stale(res, run))
			return run;
	}
	return NULL;
}

static cJSON *find_run(const struct results *res, const struct run_identity *key)
{
	return find_any(res, key, false);
}

bool results_has_run(const struct results *res, const struct run_identity *key)
{
	return find_run(res, key) != NULL;
}

size_t results_mark_stale(struct results *res, cJSON *run)
{
	if (results_is_stale(res, run))
		return 0;
	cJSON **grown = realloc(res->stale, (res->stale_count + 1) * sizeof(*grown));
	if (!grown)
		return 0; /* kept as it is: a run not made again, not one lost */
	res->stale = grown;
	res->stale[res->stale_count++] = run;
	return 1;
}

size_t results_forget_runs(struct results *res, const char *builder, const char *options_hash,
                           bool not_ok)
{
	size_t n = 0;
	cJSON *run;
	cJSON_ArrayForEach(run, res->runs) {
		const char *b = string_of(run, "builder"), *h = string_of(run, "options_hash");
		const char *status = string_of(run, "status");
		bool other_options = options_hash && h && strcmp(h, options_hash) != 0;
		bool failed = not_ok && (!status || strcmp(status, "ok") != 0);
		if (b && strcmp(b, builder) == 0 && (other_options || failed))
			n += results_mark_stale(res, run);
	}
	return n;
}

size_t results_forget_provisional(struct results *res)
{
	size_t n = 0;
	cJSON *run;
	cJSON_ArrayForEach(run, res->runs) {
		const cJSON *rays = cJSON_GetObjectItemCaseSensitive(run, "rays");
		if (cJSON_IsTrue(cJSON_GetObjectItemCaseSensitive(rays, "provisional")))
			n += results_mark_stale(res, run);
	}
	return n;
}

bool results_all_ok(const struct results *res)
{
	const cJSON *run;
	cJSON_ArrayForEach(run, res->runs) {
		const char *status = string_of(run, "status");
		if (!results_is_stale(res, run) && (!status || strcmp(status, "ok") != 0))
			return false;
	}
	return true;
}

/* The file's text; -ENOENT quietly when there is none. */
static int read_text(const char *path, char **out, bvhlab_error *err)
{
	const char *why;
	int r = util_read_text(path, out, &why);
	if (r < 0 && r != -ENOENT)
		error_set(err, "cannot resume from %s: %s", path, why);
	return r;
}

/* Moves the old document's finished runs and named scenes into ours. */
static void take_over(struct results *res, cJSON *old, size_t *kept, size_t *not_ok)
{
	cJSON *runs = cJSON_GetObjectItemCaseSensitive(old, "runs");
	cJSON *scenes = cJSON_GetObjectItemCaseSensitive(old, "scenes");
	while (runs->child) {
		cJSON *run = cJSON_DetachItemViaPointer(runs, runs->child);
		const char *status = string_of(run, "status");
		if (!is_finished(status)) {
			cJSON_Delete(run);
			continue;
		}
		(*kept)++;
		*not_ok += strcmp(status, "ok") != 0;
		cJSON_AddItemToArray(res->runs, run);
	}
	while (cJSON_IsArray(scenes) && scenes->child) {
		cJSON *scene = cJSON_DetachItemViaPointer(scenes, scenes->child);
		if (string_of(scene, "name") && !find_scene(res, string_of(scene, "name")))
			cJSON_AddItemToArray(res->scenes, scene);
		else
			cJSON_Delete(scene);
	}
	/* The sweep began when the first attempt did. */
	const char *created = string_of(old, "created");
	if (created) {
		cJSON_AddStringToObject(res->doc, "resumed", string_of(res->doc, "created"));
		cJSON_ReplaceItemInObjectCaseSensitive(res->doc, "created", cJSON_CreateString(created));
	}
}

static const char *plan_hash(const cJSON *doc)
{
	return string_of(cJSON_GetObjectItemCaseSensitive(doc, "plan"), "hash");
}

/* Runs of one plan are resumed by that plan only (and a sweep's by a sweep):
 * the hash is the runs' identity in a merge, and must not be stamped anew. */
static int same_plan(const cJSON *doc, const cJSON *old, const char *path, bvhlab_error *err)
{
	const char *now = plan_hash(doc), *then = plan_hash(old);
	if ((!now && !then) || (now && then && strcmp(now, then) == 0))
		return 0;
	char a[40], b[40];
	snprintf(a, sizeof(a), then ? "from plan %s" : "without a plan", then);
	snprintf(b, sizeof(b), now ? "from plan %s" : "not from a plan", now);
	error_set(err, "cannot resume from %s: its runs were made %s, this sweep is %s: "
	          "resume it with what made it, or write to another folder", path, a, b);
	return -EINVAL;
}

int results_resume(struct results *res, const struct run_identity *keys, size_t key_count,
                   size_t *kept, size_t *not_ok, bvhlab_error *err)
{
	char path[4096], *text = NULL;
	*kept = *not_ok = 0;
	if ((size_t)snprintf(path, sizeof(path), "%s/results.json", res->dir) >= sizeof(path)) {
		error_set(err, "path too long: %s/results.json", res->dir);
		return -ENAMETOOLONG;
	}
	int r = read_text(path, &text, err);
	if (r < 0)
		return r;
	cJSON *old = cJSON_Parse(text);
	free(text);
	if (!cJSON_IsObject(old)) {
		error_set(err, "cannot resume from %s: not a valid JSON object (damaged? move it away "
		          "to start afresh)", path);
		r = -EINVAL;
	} else {
		r = results_check_runs(cJSON_GetObjectItemCaseSensitive(old, "runs"), keys, key_count,
		                       path, err);
	}
	if (r == 0)
		r = same_plan(res->doc, old, path, err);
	if (r == 0)
		take_over(res, old, kept, not_ok);
	cJSON_Delete(old);
	return r;
}

/* ---- images and saved documents ----------------------------------------------- */

int results_set_scene_image(struct results *res, const char *scene, const char *kind,
                            const char *name, uint32_t lo, uint32_t hi)
{
	cJSON *s = find_scene(res, scene);
	if (!s)
		return -ENOENT;
	cJSON *images = cJSON_GetObjectItemCaseSensitive(s, "images");
	if (!images && !(images = cJSON_AddObjectToObject(s, "images")))
		return -ENOMEM;
	cJSON_DeleteItemFromObjectCaseSensitive(images, kind);
	cJSON_AddStringToObject(images, kind, name);
	if (strcmp(kind, "legend") == 0) {
		cJSON_DeleteItemFromObjectCaseSensitive(images, "heat_min");
		cJSON_DeleteItemFromObjectCaseSensitive(images, "heat_max");
		cJSON_DeleteItemFromObjectCaseSensitive(images, "heat_scale");
		cJSON_AddNumberToObject(images, "heat_min", lo);
		cJSON_AddNumberToObject(images, "heat_max", hi);
		cJSON_AddStringToObject(images, "heat_scale", "log"); /* image_heat's */
	}
	return 0;
}

int results_set_run_image(struct results *res, const struct run_identity *key,
                          const char *name)
{
	cJSON *run = find_run(res, key);
	if (!run)
		return -ENOENT;
	cJSON_DeleteItemFromObjectCaseSensitive(run, "heat_image");
	return cJSON_AddStringToObject(run, "heat_image", name) ? 0 : -ENOMEM;
}

int results_set_run_rays(struct results *res, const struct run_identity *key,
                         const struct ray_metrics *m)
{
	cJSON *run = find_run(res, key);
	cJSON *rays = run ? results_rays_json(m) : NULL;
	if (!run)
		return -ENOENT;
	if (!rays)
		return -ENOMEM;
	if (!cJSON_ReplaceItemInObjectCaseSensitive(run, "rays", rays)) {
		cJSON_Delete(rays);
		return -ENOENT;
	}
	return 0;
}

/* The reports of a folder describe its results.json: another document's
 * are not written there. */
static int own_reports(const char *json_path, const char *dir, bvhlab_error *err)
{
	char path[4096];
	struct stat mine, theirs;
	if ((size_t)snprintf(path, sizeof(path), "%s/results.json", dir) >= sizeof(path)) {
		error_set(err, "path too long: %s/results.json", dir);
		return -ENAMETOOLONG;
	}
	if (stat(path, &theirs) < 0 || (stat(json_path, &mine) == 0 &&
	                                mine.st_dev == theirs.st_dev && mine.st_ino == theirs.st_ino))
		return 0;
	error_set(err, "%s holds the results.json of another sweep, whose reports these would "
	          "replace: nothing written; render into another folder", dir);
	return -EEXIST;
}

int results_render_saved(const char *json_path, const char *dir,
                         const struct results_view *view, bvhlab_error *err)
{
	char *text = NULL;
	int r = read_text(json_path, &text, err);
	if (r == -ENOENT)
		error_set(err, "cannot read %s: %s", json_path, strerror(ENOENT));
	if (r < 0)
		return r;
	struct results res = {.doc = cJSON_Parse(text), .dir = (char *)dir};
	free(text);
	if (!cJSON_IsObject(res.doc) ||
	    !cJSON_IsArray(cJSON_GetObjectItemCaseSensitive(res.doc, "runs"))) {
		error_set(err, "%s is not a bvhlab results document", json_path);
		r = -EINVAL;
	}
	if (r == 0 && view)
		r = results_view_apply(res.doc, view, json_path, err);
	if (r == 0)
		r = results_make_dirs(dir, err);
	if (r == 0)
		r = results_lock(&res, err);
	if (r == 0)
		r = own_reports(json_path, dir, err);
	if (r == 0)
		r = write_rendering(&res, "results.csv", report_csv(res.doc), err);
	if (r == 0)
		r = write_rendering(&res, "report.md", report_markdown(res.doc), err);
	if (r == 0)
		r = write_rendering(&res, "report.html", report_html(res.doc), err);
	if (r == 0)
		r = results_frames_csv(res.doc, dir, err);
	results_unlock(&res);
	cJSON_Delete(res.doc);
	return r;
}
