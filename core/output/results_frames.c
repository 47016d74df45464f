/*
 * The frames of a run on an animated scene: its "frames" member of
 * results.json, and frames.csv, one line per run and frame (long form,
 * for plotting with anything that reads CSV).
 */
#include <errno.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include <cJSON.h>

#include "output/report.h"
#include "output/results.h"
#include "output/safe_file.h"
#include "util/util.h"

static void number_or_null(cJSON *o, const char *key, double v, bool measured)
{
	if (measured && isfinite(v))
		cJSON_AddNumberToObject(o, key, v);
	else
		cJSON_AddNullToObject(o, key);
}

cJSON *results_frames_json(const struct frame_metrics *frames, uint32_t count)
{
	cJSON *a = cJSON_CreateArray();
	for (uint32_t k = 0; a && k < count; k++) {
		const struct frame_metrics *f = &frames[k];
		cJSON *o = cJSON_CreateObject();
		cJSON_AddNumberToObject(o, "frame", f->frame);
		cJSON_AddNumberToObject(o, "update_ms", f->update_ms);
		/* What was not measured is null, never a 0 to be read as a figure. */
		number_or_null(o, "sah", f->sah, f->valid);
		cJSON_AddBoolToObject(o, "valid", f->valid);
		number_or_null(o, "nodes_per_ray", f->nodes_per_ray, f->valid && f->traced);
		number_or_null(o, "mrays_per_s", f->mrays_per_s, f->valid && f->traced);
		number_or_null(o, "cost_ms", f->cost_ms, f->valid && f->costed);
		cJSON_AddBoolToObject(o, "rebuilt", f->rebuilt);
		cJSON_AddBoolToObject(o, "rays_checked", f->rays_checked);
		cJSON_AddItemToArray(a, o);
	}
	return a;
}

static void number(struct strbuf *sb, const cJSON *o, const char *key, bool last)
{
	double v = report_num(o, key);
	char buf[32] = "";
	if (isfinite(v))
		snprintf(buf, sizeof(buf), "%.9g", v);
	report_csv_field(sb, buf, last);
}

static void field(struct strbuf *sb, const char *s)
{
	report_csv_field(sb, s, false);
}

static const char *flag(const cJSON *o, const char *key)
{
	const cJSON *b = cJSON_GetObjectItemCaseSensitive(o, key);
	return cJSON_IsBool(b) ? (cJSON_IsTrue(b) ? "true" : "false") : "";
}

static void run_lines(struct strbuf *sb, const cJSON *run, const cJSON *frames)
{
	const cJSON *f;
	cJSON_ArrayForEach(f, frames) {
		if (!cJSON_IsObject(f))
			continue;
		field(sb, report_str(run, "scene"));
		field(sb, report_str(run, "builder"));
		field(sb, report_str(run, "plugin"));
		number(sb, run, "threads", false);
		number(sb, f, "frame", false);
		field(sb, flag(f, "rebuilt"));
		field(sb, flag(f, "valid"));
		number(sb, f, "update_ms", false);
		number(sb, f, "sah", false);
		number(sb, f, "nodes_per_ray", false);
		number(sb, f, "mrays_per_s", false);
		number(sb, f, "cost_ms", true);
	}
}

int results_frames_csv(const cJSON *doc, const char *dir, bvhlab_error *err)
{
	struct strbuf sb = {0};
	const cJSON *run, *runs = cJSON_GetObjectItemCaseSensitive(doc, "runs");
	bool any = false;
	sb_printf(&sb, "scene,builder,plugin,threads,frame,rebuilt,valid,update_ms,sah,"
	               "nodes_per_ray,mrays_per_s,cost_ms\n");
	cJSON_ArrayForEach(run, runs) {
		const cJSON *frames = cJSON_GetObjectItemCaseSensitive(run, "frames");
		if (!cJSON_IsArray(frames))
			continue;
		any = true;
		run_lines(&sb, run, frames);
	}
	char *text = sb_take(&sb);
	if (!any || !text) {
		free(text);
		if (any)
			error_set(err, "out of memory rendering frames.csv");
		return any ? -ENOMEM : 0;
	}
	int r = safe_write_file(dir, "frames.csv", text, strlen(text), err);
	free(text);
	return r;
}
