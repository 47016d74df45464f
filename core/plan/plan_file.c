/*
 * plan.json: a config frozen for a sweep split across machines. It holds a
 * copy of the config with every path absolute (so any machine that sees
 * the same files can run it from anywhere: scene and part paths, frame
 * patterns, plugin paths), the copy's hash (the plan's
 * identity, recorded in every part's results), the hash of the config file
 * it came from (so a changed config is noticed before runs get mixed up)
 * and the run list with ids.
 */
#include <errno.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <time.h>
#include <unistd.h>

#include <cJSON.h>

#include "output/results.h"
#include "plan/plan.h"
#include "util/util.h"

int plan_read_file(const char *path, char **out, bvhlab_error *err)
{
	const char *why;
	int r = util_read_text(path, out, &why);
	if (r < 0)
		error_set(err, "cannot read %s: %s", path, why);
	return r;
}

/* path, relative to folder dir (NULL: the working folder), made absolute; the
 * file need not exist on this machine. */
static char *absolute_in(const char *dir, const char *path)
{
	char cwd[4096];
	struct strbuf sb = {0};
	if (path[0] == '/')
		return strdup(path);
	if (dir && strcmp(dir, ".") == 0)
		dir = NULL;
	if (!getcwd(cwd, sizeof(cwd)))
		return NULL;
	if (dir && dir[0] == '/')
		sb_printf(&sb, "%s/", dir);
	else
		sb_printf(&sb, "%s/%s%s", cwd, dir ? dir : "", dir ? "/" : "");
	sb_printf(&sb, "%s", strncmp(path, "./", 2) == 0 ? path + 2 : path);
	return sb_take(&sb);
}

static char *absolute(const char *path)
{
	return absolute_in(NULL, path);
}

/* Replaces the string member key of obj by its path made absolute (relative
 * paths in a config are relative to its folder); a frame pattern's folder
 * is escaped. */
static int absolute_member(const struct config *cfg, cJSON *obj, const char *key,
                           bool pattern)
{
	const cJSON *v = cJSON_GetObjectItemCaseSensitive(obj, key);
	char *abs = NULL;
	if (!cJSON_IsString(v))
		return 0;
	const char *path = v->valuestring;
	abs = absolute_in(cfg->dir, path);
	if (abs && pattern && path[0] != '/')
		abs = util_pattern_folder(abs, strlen(abs) - strlen(strncmp(path, "./", 2) == 0
		                                                     ? path + 2 : path));
	if (!abs)
		return -ENOMEM;
	cJSON_ReplaceItemInObjectCaseSensitive(obj, key, cJSON_CreateString(abs));
	free(abs);
	return 0;
}

/* Every path a scene of the copy reads: its own, its parts' and meshes', its frame
 * pattern (the plan runs from its own folder, not the config's). */
static int absolute_scene(const struct config *cfg, cJSON *scene)
{
	cJSON *part;
	int r = absolute_member(cfg, scene, "path", false);
	cJSON_ArrayForEach(part, cJSON_GetObjectItemCaseSensitive(scene, "parts"))
		r = r ? r : absolute_member(cfg, part, "path", false);
	cJSON_ArrayForEach(part, cJSON_GetObjectItemCaseSensitive(scene, "meshes"))
		r = r ? r : absolute_member(cfg, part, "path", false);
	cJSON *frames = cJSON_GetObjectItemCaseSensitive(scene, "frames");
	return r ? r : absolute_member(cfg, frames, "pattern", true);
}

static bool is_plugin_path(const char *plugin)
{
	size_t n = strlen(plugin);
	return strchr(plugin, '/') || (n >= 3 && strcmp(plugin + n - 3, ".so") == 0);
}

/* The config with its scene files, plugin files and output absolute. */
static cJSON *config_copy(const struct config *cfg)
{
	cJSON *copy = cJSON_Duplicate(cfg->root, 1), *e;
	char *output = copy ? absolute(cfg->output) : NULL;
	int r = output ? 0 : -ENOMEM;
	if (r == 0)
		cJSON_DeleteItemFromObjectCaseSensitive(copy, "output");
	if (r == 0 && !cJSON_AddStringToObject(copy, "output", output))
		r = -ENOMEM;
	cJSON_ArrayForEach(e, cJSON_GetObjectItemCaseSensitive(copy, "scenes"))
		r = r ? r : absolute_scene(cfg, e);
	cJSON_ArrayForEach(e, cJSON_GetObjectItemCaseSensitive(copy, "builders")) {
		const cJSON *p = cJSON_GetObjectItemCaseSensitive(e, "plugin");
		if (cJSON_IsString(p) && is_plugin_path(p->valuestring))
			r = r ? r : absolute_member(cfg, e, "plugin", false);
	}
	free(output);
	if (r == 0)
		return copy;
	cJSON_Delete(copy);
	return NULL;
}

/* The plan's identity: its config copy and, when recorded, the content of
 * its scene files. */
static int doc_hash(const cJSON *config, const cJSON *files, char out[17])
{
	struct strbuf sb = {0};
	char *c = cJSON_PrintUnformatted(config);
	char *f = files ? cJSON_PrintUnformatted(files) : NULL;
	if (c && (f || !files))
		sb_printf(&sb, "%s%s%s", c, f ? "\n" : "", f ? f : "");
	free(c);
	free(f);
	char *text = sb_take(&sb);
	if (!text)
		return -ENOMEM;
	plan_hash_text(text, out);
	free(text);
	return 0;
}

/* The run list as planned: threads as configured (0 resolves where it
 * runs), each run's identity (its config fragments are the plan's config). */
static cJSON *runs_json(const struct run_list *list)
{
	cJSON *array = cJSON_CreateArray();
	for (size_t k = 0; array && k < list->count; k++) {
		const struct plan_run *run = &list->runs[k];
		struct run_identity key = run->key;
		cJSON *o = cJSON_CreateObject();
		cJSON_AddItemToArray(array, o);
		cJSON_AddNumberToObject(o, "id", run->key.id);
		cJSON_AddStringToObject(o, "scene", run->key.scene);
		cJSON_AddStringToObject(o, "builder", run->key.builder);
		cJSON_AddStringToObject(o, "plugin", list->cfg->builders[run->builder].plugin);
		key.scene_config = key.builder_config = key.measure_config = NULL;
		if (run_identity_add(o, &key) < 0)
			return cJSON_Delete(array), NULL;
	}
	return array;
}

/* Fills plan's fields from a checked document (which it takes). */
static int adopt(struct plan_file *plan, const char *path, cJSON *doc)
{
	const cJSON *source = cJSON_GetObjectItemCaseSensitive(doc, "source");
	const cJSON *spath = cJSON_GetObjectItemCaseSensitive(source, "path");
	const cJSON *shash = cJSON_GetObjectItemCaseSensitive(source, "hash");
	plan->doc = doc;
	plan->path = strdup(path);
	snprintf(plan->hash, sizeof(plan->hash), "%s",
	         cJSON_GetObjectItemCaseSensitive(doc, "hash")->valuestring);
	if (cJSON_IsString(spath) && cJSON_IsString(shash)) {
		plan->source = strdup(spath->valuestring);
		snprintf(plan->source_hash, sizeof(plan->source_hash), "%s", shash->valuestring);
	}
	plan->run_count = (size_t)cJSON_GetArraySize(cJSON_GetObjectItemCaseSensitive(doc, "runs"));
	return plan->path ? 0 : -ENOMEM;
}

static cJSON *plan_doc(const struct run_list *list, cJSON *copy, cJSON *files,
                       const char *hash)
{
	const struct config *cfg = list->cfg;
	char source_hash[17], stamp[32];
	char *source = absolute(cfg->path);
	time_t now = time(NULL);
	struct tm tm;
	cJSON *doc = cJSON_CreateObject();
	plan_hash_text(cfg->text, source_hash);
	strftime(stamp, sizeof(stamp), "%Y-%m-%dT%H:%M:%SZ", gmtime_r(&now, &tm));
	cJSON_AddNumberToObject(doc, "bvhlab_plan", 1);
	cJSON_AddStringToObject(doc, "hash", hash);
	cJSON *src = cJSON_AddObjectToObject(doc, "source");
	cJSON_AddStringToObject(src, "path", source ? source : cfg->path);
	cJSON_AddStringToObject(src, "hash", source_hash);
	cJSON_AddStringToObject(doc, "created", stamp);
	cJSON_AddItemToObject(doc, "config", copy);
	cJSON_AddItemToObject(doc, "scene_files", files);
	cJSON_AddItemToObject(doc, "runs", runs_json(list));
	free(source);
	return doc;
}

static int load_doc(struct plan_file *plan, const char *path, bvhlab_error *err);

/*
 * An existing DIR/plan.json: kept (0) when it is this plan from this very
 * config text; written anew (1) when it is this plan from a config that
 * changed only in ways that leave its copy alone (spacing, say), so that its
 * runs do not refuse the config as changed; refused otherwise.
 */
static int existing_plan(const struct config *cfg, const char *path, const char *hash,
                         struct plan_file *plan, bvhlab_error *err)
{
	char source_hash[17];
	if (access(path, F_OK) != 0)
		return 1;
	int r = load_doc(plan, path, err);
	plan_hash_text(cfg->text, source_hash);
	if (r == 0 && strcmp(plan->hash, hash) == 0 && strcmp(plan->source_hash, source_hash)) {
		plan_file_finish(plan);
		return 1;
	}
	if (r == 0 && strcmp(plan->hash, hash) != 0) {
		error_set(err, "%s holds another plan (hash %s; this config's is %s): nothing "
		          "overwritten; plan into a new folder, or remove that folder to start over",
		          path, plan->hash, hash);
		plan_file_finish(plan);
		return -EEXIST;
	}
	return r;
}

int plan_file_write(const struct run_list *list, const char *dir, struct plan_file *plan,
                    bvhlab_error *err)
{
	const struct config *cfg = list->cfg;
	char hash[17], path[4096];
	memset(plan, 0, sizeof(*plan));
	cJSON *copy = config_copy(cfg), *files = plan_scene_files(cfg);
	int r = copy && files ? doc_hash(copy, files, hash) : -ENOMEM;
	if (r == 0 && (size_t)snprintf(path, sizeof(path), "%s/plan.json", dir) >= sizeof(path))
		r = -ENAMETOOLONG;
	if (r < 0) {
		cJSON_Delete(copy);
		cJSON_Delete(files);
		error_set(err, r == -ENOMEM ? "out of memory" : "path too long: %s", dir);
		return r;
	}
	if ((r = existing_plan(cfg, path, hash, plan, err)) <= 0) {
		cJSON_Delete(copy);
		cJSON_Delete(files);
		return r;
	}
	cJSON *doc = plan_doc(list, copy, files, hash);
	char *out = doc ? cJSON_Print(doc) : NULL;
	r = out ? results_make_dirs(dir, err) : -ENOMEM;
	if (r == 0)
		r = results_write_file(dir, "plan.json", out, err);
	free(out);
	if (r == 0)
		return adopt(plan, path, doc);
	cJSON_Delete(doc);
	return r;
}

/* ---- reading ------------------------------------------------------------------ */

static const char *string_at(const cJSON *o, const char *key)
{
	const cJSON *v = cJSON_GetObjectItemCaseSensitive(o, key);
	return cJSON_IsString(v) ? v->valuestring : NULL;
}

/* The document's shape and its hash against its config copy. */
static int check_doc(const char *path, const cJSON *doc, bvhlab_error *err)
{
	const cJSON *config = cJSON_GetObjectItemCaseSensitive(doc, "config");
	const char *hash = string_at(doc, "hash");
	if (!cJSON_IsNumber(cJSON_GetObjectItemCaseSensitive(doc, "bvhlab_plan")) || !hash ||
	    !cJSON_IsObject(config) ||
	    !cJSON_IsArray(cJSON_GetObjectItemCaseSensitive(doc, "runs"))) {
		error_set(err, "%s is not a bvhlab plan (made by `bvhlab plan`: bvhlab_plan, hash, "
		          "config and runs)", path);
		return -EINVAL;
	}
	char now[17];
	if (doc_hash(config, cJSON_GetObjectItemCaseSensitive(doc, "scene_files"), now) < 0) {
		error_set(err, "out of memory");
		return -ENOMEM;
	}
	if (strcmp(now, hash) != 0) {
		error_set(err, "%s: its config no longer matches its hash (%s, now %s): the plan was "
		          "edited after planning; plan again", path, hash, now);
		return -EINVAL;
	}
	return 0;
}

/* Parsed and checked, without looking at the source config. */
static int load_doc(struct plan_file *plan, const char *path, bvhlab_error *err)
{
	char *text = NULL;
	memset(plan, 0, sizeof(*plan));
	int r = plan_read_file(path, &text, err);
	if (r < 0)
		return r;
	cJSON *doc = cJSON_Parse(text);
	free(text);
	if (!doc) {
		error_set(err, "%s is not valid JSON (damaged?)", path);
		return -EINVAL;
	}
	r = check_doc(path, doc, err);
	if (r == 0)
		r = adopt(plan, path, doc);
	else
		cJSON_Delete(doc);
	return r;
}

/* The config the plan came from must still read as it did then. */
static int check_source(const struct plan_file *plan, bvhlab_error *err)
{
	char *text = NULL, now[17];
	if (!plan->source || access(plan->source, F_OK) != 0)
		return 0; /* not on this machine: the plan's copy is complete */
	int r = plan_read_file(plan->source, &text, err);
	if (r < 0)
		return r;
	plan_hash_text(text, now);
	free(text);
	if (strcmp(now, plan->source_hash) == 0)
		return 0;
	error_set(err, "%s: the config %s has changed since planning (hash %s then, %s now); "
	          "plan again into a new folder so that run ids keep their meaning",
	          plan->path, plan->source, plan->source_hash, now);
	return -ESTALE;
}

bool plan_file_detect(const char *path)
{
	char *text = NULL;
	if (plan_read_file(path, &text, NULL) < 0)
		return false;
	cJSON *doc = cJSON_Parse(text);
	bool plan = cJSON_IsObject(doc) && cJSON_GetObjectItemCaseSensitive(doc, "bvhlab_plan");
	cJSON_Delete(doc);
	free(text);
	return plan;
}

int plan_file_load(struct plan_file *plan, const char *path, struct config *cfg,
                   bvhlab_error *err)
{
	int r = load_doc(plan, path, err);
	if (r == 0)
		r = check_source(plan, err);
	char *text = NULL;
	if (r == 0 && cfg) {
		text = cJSON_PrintUnformatted(cJSON_GetObjectItemCaseSensitive(plan->doc, "config"));
		r = text ? config_parse(cfg, path, text, err) : -ENOMEM;
	}
	free(text);
	if (r == 0 && cfg && (r = plan_check_scene_files(plan, cfg, err)) < 0)
		config_finish(cfg);
	if (r < 0)
		plan_file_finish(plan);
	return r;
}

/* One run of the plan against the list's run of its id: RUN_SAME, or
 * *changed says what differs (a plugin or its defaults differ here). */
static enum run_match same_run(const cJSON *want, const struct plan_run *run,
                               const char **changed)
{
	struct run_identity planned;
	const cJSON *id = cJSON_GetObjectItemCaseSensitive(want, "id");
	run_identity_read(want, &planned);
	if (!cJSON_IsNumber(id) || id->valuedouble != run->key.id)
		return RUN_OTHER;
	/* A plan records only what it can know: the thread count as configured. */
	enum run_match m = run_identity_compare(&run->key, &planned, changed);
	return m == RUN_CHANGED && !planned.hash ? RUN_SAME : m;
}

int plan_check_list(const struct plan_file *plan, const struct run_list *list,
                    bvhlab_error *err)
{
	const cJSON *runs = cJSON_GetObjectItemCaseSensitive(plan->doc, "runs"), *want;
	const char *changed = NULL;
	enum run_match m = RUN_SAME;
	size_t k = 0;
	cJSON_ArrayForEach(want, runs) {
		if (k >= list->count || (m = same_run(want, &list->runs[k], &changed)) != RUN_SAME)
			break;
		k++;
	}
	if (k == list->count && k == plan->run_count)
		return 0;
	if (m == RUN_CHANGED) {
		bool builder = !strcmp(changed, "builder");
		error_set(err, "%s: run %zu (%s, %s) would be made another way here than planned: "
		          "its %s differs (%s); plan again here", plan->path, k,
		          list->runs[k].key.scene, list->runs[k].key.builder,
		          builder ? "builder" : !strcmp(changed, "scene") ? "scene" : "measurement",
		          builder ? "a plugin or its defaults here are not the planning machine's"
		                  : "scene files missing when planning, or settings given here");
		return -EINVAL;
	}
	error_set(err, "%s: this machine makes %zu runs of its config and the plan lists %zu, "
	          "%s at run %zu (a builder's plugin here differs: its PARALLEL flag?); plan again "
	          "here", plan->path, list->count, plan->run_count,
	          k < list->count && k < plan->run_count ? "differing" : "ending", k);
	return -EINVAL;
}

void plan_file_finish(struct plan_file *plan)
{
	if (!plan)
		return;
	cJSON_Delete(plan->doc);
	free(plan->path);
	free(plan->source);
	memset(plan, 0, sizeof(*plan));
}
