/*
 * The "stages" member of a run whose builder has a "refine" list: each
 * refinement stage's median time over the timed repeats (already part of
 * the run's build_ms, which times the build and every stage together) and
 * the SAH cost of the tree just before and after it, on the last repeat;
 * and the "build_phases" member of a run whose builder reported phases of
 * its build (ABI 1.3): each phase's median over the timed repeats, part of
 * build_ms too; and "own_ms", the build time fronts and verdicts compare.
 */
#include <math.h>
#include <string.h>

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

/* The phases that translate between bvhlab's layouts and a builder's own
 * (a peer library's input made from the host's, its tree written in the
 * standard layout): harness work a user of the library never pays. */
static const char *const translation_phases[] = {"input", "convert"};

double results_own_ms(const cJSON *run)
{
	const cJSON *t = cJSON_GetObjectItemCaseSensitive(run, "build_ms");
	const cJSON *med = cJSON_GetObjectItemCaseSensitive(t, "median");
	const cJSON *phases = cJSON_GetObjectItemCaseSensitive(run, "build_phases");
	if (!cJSON_IsNumber(med))
		return NAN;
	double ms = med->valuedouble;
	for (size_t k = 0; k < sizeof(translation_phases) / sizeof(*translation_phases); k++) {
		const cJSON *p = cJSON_GetObjectItemCaseSensitive(phases, translation_phases[k]);
		if (cJSON_IsNumber(p))
			ms -= p->valuedouble;
	}
	/* Each phase's median is taken apart from the whole's: never below 0. */
	return ms > 0 ? ms : 0;
}
