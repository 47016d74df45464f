/*
 * results.json's "not_applicable": the thread counts of a config that a
 * builder was not run at, and why (a builder without the PARALLEL flag
 * runs once per scene), so a reader can tell them from missing runs.
 */
#include <errno.h>
#include <string.h>

#include <cJSON.h>

#include "output/results.h"

int results_set_not_applicable(struct results *res, const char *builder,
                               const uint32_t *threads, size_t count, const char *reason)
{
	cJSON *list = cJSON_GetObjectItemCaseSensitive(res->doc, "not_applicable");
	if (!list && !(list = cJSON_AddArrayToObject(res->doc, "not_applicable")))
		return -ENOMEM;
	cJSON *o = cJSON_CreateObject(), *t = cJSON_CreateArray();
	if (!o || !t) {
		cJSON_Delete(o);
		cJSON_Delete(t);
		return -ENOMEM;
	}
	cJSON_AddStringToObject(o, "builder", builder);
	cJSON_AddItemToObject(o, "threads", t);
	for (size_t k = 0; k < count; k++)
		cJSON_AddItemToArray(t, cJSON_CreateNumber(threads[k]));
	cJSON_AddStringToObject(o, "reason", reason);
	for (cJSON *old = list->child; old; old = old->next) {
		const cJSON *name = cJSON_GetObjectItemCaseSensitive(old, "builder");
		if (cJSON_IsString(name) && strcmp(name->valuestring, builder) == 0)
			return cJSON_ReplaceItemViaPointer(list, old, o) ? 0 : -ENOMEM;
	}
	cJSON_AddItemToArray(list, o);
	return 0;
}
