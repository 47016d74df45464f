/*
 * A run's record in results.json (docs/design.md, "results.json"): its
 * slot, identity, status and figures as the harness measured them.
 */
#include <cJSON.h>

#include "output/results.h"
#include "util/util.h"

cJSON *results_options_json(const bvhlab_options *opts)
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

void results_add_numbers(cJSON *o, const struct results_number *f, size_t n)
{
	for (size_t k = 0; o && k < n; k++)
		cJSON_AddNumberToObject(o, f[k].name, f[k].value);
}

static cJSON *timing_json(const struct run_record *run)
{
	double med, mn, mx;
	util_summarise(run->samples_ms, run->sample_count, &med, &mn, &mx);
	cJSON *o = cJSON_CreateObject();
	const struct results_number times[] = {
		{"median", med}, {"min", mn}, {"max", mx}, {"cold", run->cold_ms}};
	results_add_numbers(o, times, RESULTS_NUMBERS(times));
	cJSON *samples = cJSON_AddArrayToObject(o, "samples");
	for (uint32_t k = 0; k < run->sample_count; k++)
		cJSON_AddItemToArray(samples, cJSON_CreateNumber(run->samples_ms[k]));
	return o;
}

static cJSON *memory_json(const struct build_memory *m)
{
	cJSON *o = cJSON_CreateObject();
	const struct results_number bytes[] = {
		{"peak_bytes", (double)m->peak_bytes},
		{"peak_rss_bytes", (double)m->peak_rss_bytes},
		{"start_rss_bytes", (double)m->start_rss_bytes},
		{"output_bytes", (double)m->output_bytes},
	};
	results_add_numbers(o, bytes, RESULTS_NUMBERS(bytes));
	return o;
}

/* dup_ratio: references per triangle, 1 unless spatial splits duplicated some. */
static cJSON *tree_json(const bvhlab_tree_stats *st, uint32_t triangles)
{
	cJSON *o = cJSON_CreateObject();
	const struct results_number shape[] = {
		{"nodes", st->nodes},
		{"leaves", st->leaves},
		{"max_depth", st->max_depth},
		{"avg_leaf_size", st->avg_leaf_size},
		{"sah_cost", st->sah_cost},
		{"refs", (double)st->refs},
	};
	results_add_numbers(o, shape, RESULTS_NUMBERS(shape));
	if (triangles)
		cJSON_AddNumberToObject(o, "dup_ratio", (double)st->refs / triangles);
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

cJSON *results_run_json(const struct run_record *run)
{
	cJSON *o = cJSON_CreateObject();
	if (!o)
		return NULL;
	cJSON_AddNumberToObject(o, "id", run->id);
	cJSON_AddStringToObject(o, "scene", run->scene ? run->scene : "");
	cJSON_AddStringToObject(o, "builder", run->builder);
	cJSON_AddStringToObject(o, "plugin", run->plugin ? run->plugin : "");
	cJSON_AddNumberToObject(o, "threads", run->threads);
	cJSON_AddItemToObject(o, "options", results_options_json(run->opts));
	if (run->options_hash)
		cJSON_AddStringToObject(o, "options_hash", run->options_hash);
	if (run->key && run_identity_add(o, run->key) < 0)
		return cJSON_Delete(o), NULL;
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
	if (run->phase_count)
		cJSON_AddItemToObject(o, "build_phases",
		                      results_phases_json(run->phases, run->phase_count));
	if (run->sample_count)
		cJSON_AddNumberToObject(o, "own_ms", results_own_ms(o));
	if (run->stage_count)
		cJSON_AddItemToObject(o, "stages", results_stages_json(run->stages, run->stage_count));
	if (run->stats)
		cJSON_AddItemToObject(o, "tree", tree_json(run->stats, run->triangles));
	if (run->stats && run->epo)
		cJSON_AddNumberToObject(cJSON_GetObjectItem(o, "tree"), "epo", *run->epo);
	if (run->memory)
		cJSON_AddItemToObject(o, "memory", memory_json(run->memory));
	if (run->device) /* after "memory", which it adds to */
		results_device_add(o, run->device);
	if (run->validated)
		cJSON_AddItemToObject(o, "validation", validation_json(run));
	if (run->rays)
		cJSON_AddItemToObject(o, "rays", results_rays_json(run->rays));
	if (run->frame_count) /* an animated scene: results_frames.c */
		cJSON_AddItemToObject(o, "frames", results_frames_json(run->frames, run->frame_count));
	if (run->load_read) {
		cJSON_AddNumberToObject(o, "load_before", run->load_before);
		cJSON_AddNumberToObject(o, "load_after", run->load_after);
		if (run->load_other >= 0)
			cJSON_AddNumberToObject(o, "load_other", run->load_other);
	}
	return o;
}

