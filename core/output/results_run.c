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

/* Bytes per triangle: the build's peak alone and with the scene it read
 * (the figure to hold against a budget), the whole child's, the scene's.
 * Without the high-water mark's reset the build's own peak is unknown. */
static void per_triangle_json(cJSON *o, const struct build_memory *m, uint32_t triangles)
{
	double n = triangles;
	const struct results_number per[] = {
		{"build_bytes_per_triangle", (double)m->peak_bytes / n},
		{"with_scene_bytes_per_triangle", (double)(m->peak_bytes + m->scene_bytes) / n},
	};
	if (m->reset)
		results_add_numbers(o, per, RESULTS_NUMBERS(per));
	cJSON_AddNumberToObject(o, "child_bytes_per_triangle", (double)m->peak_rss_bytes / n);
	if (m->run_peak_rss_bytes)
		cJSON_AddNumberToObject(o, "run_bytes_per_triangle",
		                        (double)m->run_peak_rss_bytes / n);
	cJSON_AddNumberToObject(o, "scene_bytes_per_triangle", (double)m->scene_bytes / n);
}

static cJSON *memory_json(const struct build_memory *m, uint32_t triangles)
{
	cJSON *o = cJSON_CreateObject();
	const struct results_number bytes[] = {
		{"peak_bytes", (double)m->peak_bytes},
		{"peak_rss_bytes", (double)m->peak_rss_bytes},
		{"start_rss_bytes", (double)m->start_rss_bytes},
		{"output_bytes", (double)m->output_bytes},
		{"scene_bytes", (double)m->scene_bytes},
	};
	results_add_numbers(o, bytes, RESULTS_NUMBERS(bytes));
	if (m->run_peak_rss_bytes)
		cJSON_AddNumberToObject(o, "run_peak_rss_bytes", (double)m->run_peak_rss_bytes);
	if (triangles)
		per_triangle_json(o, m, triangles);
	return o;
}

static cJSON *estimate_json(const struct memory_estimate *e)
{
	cJSON *o = cJSON_CreateObject();
	const struct results_number bytes[] = {
		{"bytes", (double)e->bytes},
		{"scene_bytes", (double)e->scene_bytes},
		{"bytes_per_triangle", (double)e->bytes_per_prim},
		{"after_bytes_per_triangle", (double)e->after_bytes_per_prim},
	};
	results_add_numbers(o, bytes, RESULTS_NUMBERS(bytes));
	cJSON_AddBoolToObject(o, "declared", e->declared);
	if (e->instances) { /* a two-level run's: per unique triangle above */
		cJSON_AddNumberToObject(o, "instances", (double)e->instances);
		cJSON_AddNumberToObject(o, "top_bytes_per_instance", (double)e->top_bytes_per_instance);
	}
	if (e->known)
		cJSON_AddNumberToObject(o, "limit_bytes", (double)e->limit_bytes);
	cJSON_AddStringToObject(o, "limit", !e->known ? "unknown"
	                                    : e->limit_from_config ? "memory_limit_mb"
	                                                           : "available");
	return o;
}

/* A tree's memory per triangle in two layouts: as stored (32-byte nodes,
 * 4 bytes a reference: memory_bytes), and packed as wide tracers store it,
 * each inner node one block of `width` child slots (a box, 24 bytes, and a
 * 32-bit reference: 28 bytes a slot, Embree's BVH4/BVH8 node with 32-bit
 * references), leaves as ranges of the 4-byte references. */
static void bytes_json(cJSON *o, const bvhlab_tree_stats *st, uint32_t width, uint32_t triangles)
{
	double inner = (double)st->nodes - st->leaves;
	double packed = inner * width * 28.0 + (double)st->refs * sizeof(uint32_t);
	cJSON_AddNumberToObject(o, "bytes_per_triangle", (double)st->memory_bytes / triangles);
	cJSON_AddNumberToObject(o, "packed_bytes_per_triangle", packed / triangles);
	/* The compressed 8-wide layout of device_wide8 (core/trace/cwbvh.h):
	 * an 80-byte node per inner node and an 8-byte range per leaf, with
	 * the same references. Only for trees it takes as built: a narrower
	 * one is collapsed first, into nodes these counts do not give. */
	if (width > 4) {
		double cw = inner * 80.0 + (double)st->leaves * 8.0 + (double)st->refs * 4.0;
		cJSON_AddNumberToObject(o, "cwbvh_bytes_per_triangle", cw / triangles);
	}
}

/* dup_ratio: references per triangle, 1 unless spatial splits duplicated some. */
static cJSON *tree_json(const bvhlab_tree_stats *st, uint32_t width, uint32_t triangles)
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
	cJSON_AddNumberToObject(o, "width", width < 2 ? 2 : width);
	if (triangles)
		cJSON_AddNumberToObject(o, "dup_ratio", (double)st->refs / triangles);
	if (triangles)
		bytes_json(o, st, width < 2 ? 2 : width, triangles);
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

static cJSON *level_json(const struct results_level *l)
{
	const struct {
		const char *key;
		double value;
	} numbers[] = {
		{"build_ms", l->build_ms}, {"trees", l->trees},     {"nodes", l->nodes},
		{"leaves", l->leaves},     {"sah_cost", l->sah}, {"memory_bytes", (double)l->memory_bytes},
	};
	cJSON *o = cJSON_CreateObject();
	cJSON_AddStringToObject(o, "plugin", l->plugin);
	for (size_t k = 0; k < sizeof(numbers) / sizeof(numbers[0]); k++)
		cJSON_AddNumberToObject(o, numbers[k].key, numbers[k].value);
	return o;
}

/* "two_level": {"bottom", "top", "build_ms": their sum, "sah_cost"}. */
static cJSON *two_level_json(const struct results_two_level *t)
{
	cJSON *o = cJSON_CreateObject();
	cJSON_AddItemToObject(o, "bottom", level_json(&t->bottom));
	cJSON_AddItemToObject(o, "top", level_json(&t->top));
	cJSON_AddNumberToObject(o, "build_ms", t->bottom.build_ms + t->top.build_ms);
	cJSON_AddNumberToObject(o, "sah_cost", t->sah);
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
		cJSON_AddItemToObject(o, "tree", tree_json(run->stats, run->width, run->triangles));
	if (run->stats && run->epo)
		cJSON_AddNumberToObject(cJSON_GetObjectItem(o, "tree"), "epo", *run->epo);
	if (run->memory)
		/* A two-level run's triangles are instanced (clipped past 2^32 - 1):
		 * its memory has totals only. */
		cJSON_AddItemToObject(o, "memory", memory_json(run->memory,
		                                                run->two_level ? 0 : run->triangles));
	if (run->estimate)
		cJSON_AddItemToObject(o, "memory_estimate", estimate_json(run->estimate));
	if (run->device) /* after "memory", which it adds to */
		results_device_add(o, run->device);
	if (run->validated)
		cJSON_AddItemToObject(o, "validation", validation_json(run));
	if (run->rays)
		cJSON_AddItemToObject(o, "rays", results_rays_json(run->rays));
	if (run->two_level)
		cJSON_AddItemToObject(o, "two_level", two_level_json(run->two_level));
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

