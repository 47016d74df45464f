/*
 * The "device" member of a device builder's run (BVHLAB_BUILDER_DEVICE):
 * the OpenCL device its "device" option chose, so its figures are read as
 * that device's and not as a 1-thread CPU run's, and the memory the OpenCL
 * runtime took before its builds, kept apart from theirs.
 */
#include <stdio.h>

#include <cJSON.h>

#include "output/results.h"

void results_device_add(cJSON *o, const struct run_device *d)
{
	char index[32];
	cJSON *dev = cJSON_AddObjectToObject(o, "device");
	if (!dev)
		return;
	snprintf(index, sizeof(index), "%u:%u", d->cl.platform_index, d->cl.device_index);
	cJSON_AddStringToObject(dev, "name", d->cl.name);
	cJSON_AddStringToObject(dev, "kind", d->cl.kind);
	cJSON_AddNumberToObject(dev, "compute_units", d->cl.compute_units);
	cJSON_AddStringToObject(dev, "platform", d->cl.platform);
	cJSON_AddStringToObject(dev, "index", index);
	cJSON_AddNumberToObject(dev, "global_mem_bytes", (double)d->cl.global_mem);
	cJSON *memory = cJSON_GetObjectItemCaseSensitive(o, "memory");
	if (memory && d->runtime_measured)
		cJSON_AddNumberToObject(memory, "runtime_bytes", (double)d->runtime_bytes);
}
