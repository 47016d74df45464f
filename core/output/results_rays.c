/*
 * The "rays" member of a run: what the core's traverser measured on the
 * run's tree. Per-ray averages make runs with different ray counts
 * (resolutions, scenes with more misses) comparable. Throughput:
 * mrays_per_s from each tile's best pass (see bvhlab_trace_timing), and the
 * median, min and max over the passes beside it.
 */
#include <cJSON.h>

#include "output/results.h"

static cJSON *kind_json(const bvhlab_trace_timing *t)
{
	cJSON *o = cJSON_CreateObject();
	const bvhlab_trace_stats *st = &t->stats;
	double rays = (double)st->rays;
	const struct results_number figures[] = {
		{"rays", rays},
		{"mrays_per_s", t->mrays_best},
		{"mrays_median", t->mrays_median},
		{"mrays_min", t->mrays_min},
		{"mrays_max", t->mrays_max},
		{"wall_mrays_per_s", t->wall_mrays_median},
		{"repeats", t->repeats},
		{"nodes_per_ray", rays > 0 ? (double)st->nodes_visited / rays : 0},
		{"tris_per_ray", rays > 0 ? (double)st->tris_tested / rays : 0},
		{"seconds", t->seconds_total},
	};
	results_add_numbers(o, figures, RESULTS_NUMBERS(figures));
	return o;
}

/* primary and diffuse always (as before kinds existed); shadow and ao
 * when asked for. */
static void add_kinds(cJSON *o, const struct ray_metrics *m, int k)
{
	unsigned kinds = m->kinds ? m->kinds : RAY_KINDS_DEFAULT;
	cJSON_AddItemToObject(o, "primary", kind_json(&m->primary[k]));
	cJSON_AddItemToObject(o, "diffuse", kind_json(&m->diffuse[k]));
	if (kinds & (1u << RAY_SHADOW))
		cJSON_AddItemToObject(o, "shadow", kind_json(&m->shadow[k]));
	if (kinds & (1u << RAY_AO))
		cJSON_AddItemToObject(o, "ao", kind_json(&m->ao[k]));
}

cJSON *results_rays_json(const struct ray_metrics *m)
{
	cJSON *o = cJSON_CreateObject();
	cJSON_AddNumberToObject(o, "threads", m->threads);
	cJSON_AddStringToObject(o, "traversal", bvhlab_traversal_name(m->main));
	cJSON_AddNumberToObject(o, "rounds", m->rounds ? m->rounds : 1);
	if (m->provisional)
		cJSON_AddBoolToObject(o, "provisional", true);
	if (m->device[0])
		cJSON_AddStringToObject(o, "device", m->device);
	/* Why there are no figures, or none of one traversal: never silent. */
	if (m->error[0])
		cJSON_AddStringToObject(o, "error", m->error);
	if (!m->measured)
		return o;
	add_kinds(o, m, m->main);
	bool others = false;
	for (int k = 0; k < BVHLAB_TRAVERSAL_COUNT; k++) {
		if (k == m->main || !(m->traversals & (1u << k)))
			continue;
		cJSON *other = cJSON_CreateObject();
		add_kinds(other, m, k);
		cJSON_AddItemToObject(o, bvhlab_traversal_name(k), other);
		others = true;
	}
	/* Rays (of every kind) whose hit differs from the main traversal's,
	 * summed over the others; a shadow or AO ray differs when one
	 * traversal finds it blocked and the other not. */
	if (others)
		cJSON_AddNumberToObject(o, "traversal_disagreements", (double)m->disagreements);
	return o;
}
