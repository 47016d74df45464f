/*
 * The up-front memory check: a run that cannot fit is refused before its
 * child is forked, with the figures, instead of being killed by the
 * kernel (or by RLIMIT_AS) part-way through and taking the machine's
 * other work with it. The estimate is the data's, not the process's: the
 * scene's arrays as the builds read them and the bytes per primitive the
 * plugins declare (a builder and each refine stage, summed: a stage's
 * scratch comes on top of the tree it is given).
 */
#include <errno.h>
#include <stdio.h>

#include "harness/harness_estimate.h"
#include "harness/harness_memory.h"
#include "machine/machine.h"

#define MIB (1024.0 * 1024.0)

/* The declared bytes per primitive of the builder and its stages; *all:
 * whether every one of them declared its own. */
static uint64_t per_prim(const struct harness_builder *hb, bool *all)
{
	bool declared;
	uint64_t bytes = bvhlab_builder_peak_bytes_per_prim(bvhlab_plugin_builder(hb->plugin),
	                                                    hb->opts.filled, &declared);
	*all = declared;
	for (size_t k = 0; k < hb->cb->refine_count; k++) {
		bytes += bvhlab_builder_peak_bytes_per_prim(
			bvhlab_plugin_builder(hb->refine[k].plugin), hb->refine[k].opts->filled,
			&declared);
		*all = *all && declared;
	}
	return bytes;
}

static void describe(const struct memory_estimate *e, const char *scene,
                     const struct harness_builder *hb, uint32_t prims, char *why, size_t size)
{
	char limit[96];
	if (e->limit_from_config)
		snprintf(limit, sizeof(limit), "memory_limit_mb = %llu",
		         (unsigned long long)(e->limit_bytes >> 20));
	else
		snprintf(limit, sizeof(limit), "the memory available (%.0f MiB, memory_limit_mb "
		         "unset)", (double)e->limit_bytes / MIB);
	snprintf(why, size, "scene '%s', builder '%s': refused before building: estimated peak "
	         "%.0f MiB (the scene's %.0f MiB + %llu bytes per triangle %s x %u triangles) "
	         "exceeds %s", scene, hb->cb->name, (double)e->bytes / MIB,
	         (double)e->scene_bytes / MIB, (unsigned long long)e->bytes_per_prim,
	         e->declared ? "declared" : "assumed, not declared", prims, limit);
}

int harness_estimate_run(const struct config *cfg, const struct harness_builder *hb,
                         const char *scene, const bvhlab_build_input *in,
                         struct memory_estimate *e, char *why, size_t size)
{
	uint64_t mb = hb->cb->memory_limit_mb ? hb->cb->memory_limit_mb : cfg->memory_limit_mb;
	*e = (struct memory_estimate){.scene_bytes = harness_memory_scene_bytes(in)};
	e->bytes_per_prim = per_prim(hb, &e->declared);
	e->bytes = e->scene_bytes + e->bytes_per_prim * in->prim_count;
	e->limit_from_config = mb != 0;
	if (mb) {
		e->limit_bytes = mb << 20;
	} else {
		uint64_t available = machine_memory_available();
		/* The scene is resident already: it was taken out of what is available. */
		e->limit_bytes = available ? available + e->scene_bytes : 0;
	}
	e->known = e->limit_bytes != 0;
	if (!e->known || e->bytes <= e->limit_bytes)
		return 0;
	describe(e, scene, hb, in->prim_count, why, size);
	return -E2BIG;
}
