/*
 * `bvhlab report --reference/--scene/--threads`: a finished or merged
 * sweep seen another way. The view changes the document in memory only,
 * before it is rendered: the reference as if the config had named it
 * (config.report.reference, so the report is the one a sweep run with
 * that reference renders from the same figures), and the scenes and
 * thread counts kept. results.json itself is never written.
 */
#include <errno.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include <cJSON.h>

#include "output/report_doc.h"
#include "output/results.h"
#include "util/util.h"

static bool wanted_scene(const struct results_view *v, const char *scene)
{
	for (size_t k = 0; k < v->scene_count; k++)
		if (strcmp(v->scenes[k], scene) == 0)
			return true;
	return v->scene_count == 0;
}

static bool wanted_threads(const struct results_view *v, double threads)
{
	for (size_t k = 0; k < v->threads_count; k++)
		if (v->threads[k] == threads)
			return true;
	return v->threads_count == 0;
}

/* Removes the items of an array for which keep() is false. */
static void drop(cJSON *array, const struct results_view *v,
                 bool (*keep)(const struct results_view *, const cJSON *))
{
	cJSON *item = array ? array->child : NULL;
	while (item) {
		cJSON *next = item->next;
		if (!keep(v, item))
			cJSON_Delete(cJSON_DetachItemViaPointer(array, item));
		item = next;
	}
}

static bool keep_run(const struct results_view *v, const cJSON *run)
{
	return wanted_scene(v, report_str(run, "scene")) &&
	       wanted_threads(v, report_num(run, "threads"));
}

static bool keep_scene(const struct results_view *v, const cJSON *scene)
{
	return wanted_scene(v, report_str(scene, "name"));
}

/* Whether some run has the string at key (an ok one when ok). */
static bool any_run(const cJSON *runs, const char *key, const char *value, bool ok)
{
	const cJSON *run;
	cJSON_ArrayForEach(run, runs)
		if (strcmp(report_str(run, key), value) == 0 &&
		    (!ok || strcmp(report_str(run, "status"), "ok") == 0))
			return true;
	return false;
}

/* Every scene and thread count asked for is in the document. */
static int check_asked(const cJSON *doc, const struct results_view *v, const char *path,
                       bvhlab_error *err)
{
	const cJSON *runs = cJSON_GetObjectItemCaseSensitive(doc, "runs"), *run;
	for (size_t k = 0; k < v->scene_count; k++)
		if (!any_run(runs, "scene", v->scenes[k], false)) {
			error_set(err, "%s has no run of scene '%s' (--scene)", path, v->scenes[k]);
			return -EINVAL;
		}
	for (size_t k = 0; k < v->threads_count; k++) {
		bool found = false;
		cJSON_ArrayForEach(run, runs)
			found |= report_num(run, "threads") == v->threads[k];
		if (!found) {
			error_set(err, "%s has no run with %g threads (--threads)", path, v->threads[k]);
			return -EINVAL;
		}
	}
	return 0;
}

/* config.report.reference = name, the objects made as needed. */
static int set_reference(cJSON *doc, const char *name)
{
	cJSON *config = cJSON_GetObjectItemCaseSensitive(doc, "config"), *report;
	if (!cJSON_IsObject(config)) {
		cJSON_DeleteItemFromObjectCaseSensitive(doc, "config");
		config = cJSON_AddObjectToObject(doc, "config");
	}
	report = config ? cJSON_GetObjectItemCaseSensitive(config, "report") : NULL;
	if (config && !cJSON_IsObject(report)) {
		cJSON_DeleteItemFromObjectCaseSensitive(config, "report");
		report = cJSON_AddObjectToObject(config, "report");
	}
	if (!report)
		return -ENOMEM;
	cJSON_DeleteItemFromObjectCaseSensitive(report, "reference");
	return cJSON_AddStringToObject(report, "reference", name) ? 0 : -ENOMEM;
}

/* "Filtered by bvhlab report: scenes a, b; threads 2." for the reports. */
static int set_note(cJSON *doc, const struct results_view *v)
{
	struct strbuf sb = {0};
	sb_printf(&sb, "Filtered by bvhlab report:");
	for (size_t k = 0; k < v->scene_count; k++)
		sb_printf(&sb, "%s %s", k ? "," : " scenes:", v->scenes[k]);
	for (size_t k = 0; k < v->threads_count; k++)
		sb_printf(&sb, "%s %g", k ? "," : v->scene_count ? "; threads:" : " threads:",
		          v->threads[k]);
	sb_printf(&sb, "; the runs of other scenes and thread counts are left out.");
	char *note = sb_take(&sb);
	cJSON_DeleteItemFromObjectCaseSensitive(doc, "report_note");
	bool ok = note && cJSON_AddStringToObject(doc, "report_note", note);
	free(note);
	return ok ? 0 : -ENOMEM;
}

int results_view_apply(cJSON *doc, const struct results_view *v, const char *path,
                       bvhlab_error *err)
{
	int r = check_asked(doc, v, path, err);
	if (r < 0)
		return r;
	drop(cJSON_GetObjectItemCaseSensitive(doc, "runs"), v, keep_run);
	drop(cJSON_GetObjectItemCaseSensitive(doc, "scenes"), v, keep_scene);
	if (v->scene_count || v->threads_count)
		r = set_note(doc, v);
	const cJSON *runs = cJSON_GetObjectItemCaseSensitive(doc, "runs");
	if (r == 0 && v->reference && !any_run(runs, "builder", v->reference, true) &&
	    !any_run(runs, "plugin", v->reference, true)) {
		error_set(err, "%s has no ok run of a builder or plugin named '%s' (--reference)%s",
		          path, v->reference,
		          v->scene_count || v->threads_count ? " among the scenes and threads kept" : "");
		return -EINVAL;
	}
	if (r == 0 && v->reference)
		r = set_reference(doc, v->reference);
	if (r == -ENOMEM)
		error_set(err, "out of memory applying the report's view of %s", path);
	return r;
}
