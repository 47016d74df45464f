/*
 * The "stages" member of a run whose builder has a "refine" list: each
 * refinement stage's median time over the timed repeats (already part of
 * the run's build_ms, which times the build and every stage together) and
 * the SAH cost of the tree just before and after it, on the last repeat;
 * and the "build_phases" member of a run whose builder reported phases of
 * its build (ABI 1.3): each phase's median over the timed repeats, part of
 * build_ms too.
 */
#include <cJSON.h>

#include "output/results.h"

cJSON *results_stages_json(const struct stage_metrics *stages, uint32_t count)
{
	cJSON *a = cJSON_CreateArray();
	for (uint32_t k = 0; a && k < count; k++) {
		cJSON *o = cJSON_CreateObject();
		if (!o)
			break;
		cJSON_AddStringToObject(o, "plugin", stages[k].plugin);
		cJSON_AddNumberToObject(o, "ms", stages[k].ms);
		cJSON_AddNumberToObject(o, "sah_before", stages[k].sah_before);
		cJSON_AddNumberToObject(o, "sah_after", stages[k].sah_after);
		cJSON_AddItemToArray(a, o);
	}
	return a;
}

cJSON *results_phases_json(const bvhlab_phase *phases, uint32_t count)
{
	cJSON *o = cJSON_CreateObject();
	for (uint32_t k = 0; o && k < count; k++)
		cJSON_AddNumberToObject(o, phases[k].name, phases[k].ms);
	return o;
}
