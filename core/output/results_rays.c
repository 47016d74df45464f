/*
 * The "rays" member of a run: what the core's traverser measured on the
 * run's tree. Per-ray averages make runs with different ray counts
 * (resolutions, scenes with more misses) comparable.
 */
#include <cJSON.h>

#include "output/results.h"

static cJSON *kind_json(const bvhlab_trace_stats *st, double seconds)
{
	cJSON *o = cJSON_CreateObject();
	double rays = (double)st->rays;
	cJSON_AddNumberToObject(o, "rays", rays);
	cJSON_AddNumberToObject(o, "mrays_per_s", seconds > 0 ? rays / seconds * 1e-6 : 0);
	cJSON_AddNumberToObject(o, "nodes_per_ray", rays > 0 ? (double)st->nodes_visited / rays : 0);
	cJSON_AddNumberToObject(o, "tris_per_ray", rays > 0 ? (double)st->tris_tested / rays : 0);
	cJSON_AddNumberToObject(o, "seconds", seconds);
	return o;
}

cJSON *results_rays_json(const struct ray_metrics *m)
{
	cJSON *o = cJSON_CreateObject();
	cJSON_AddNumberToObject(o, "threads", m->threads);
	cJSON_AddItemToObject(o, "primary", kind_json(&m->primary, m->primary_s));
	cJSON_AddItemToObject(o, "diffuse", kind_json(&m->diffuse, m->diffuse_s));
	return o;
}
