/*
 * The up-front memory check: a run that cannot fit is refused before its
 * child is forked, with the figures, instead of being killed by the
 * kernel (or by RLIMIT_AS) part-way through and taking the machine's
 * other work with it. The estimate is the data's, not the process's: the
 * scene's arrays as the builds read them, plus per primitive the larger
 * of what the builds hold (the bytes the plugins declare: a builder and
 * each refine stage, summed, since a stage's scratch comes on top of the
 * tree it is given) and what validation and tracing hold after them.
 */
#include <errno.h>
#include <stdio.h>

#include "harness/harness_estimate.h"
#include "harness/harness_memory.h"
#include "machine/machine.h"
#include "scene/instances.h"
#include "trace/trace_cl.h"

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

/*
 * After the builds (docs/benchmarks.md, "What a run holds"): the tree they
 * left, 2N - 1 nodes of 32 bytes and N indices (68; the host gives the
 * builders' spare capacity back before validating, harness.c), or the
 * build's whole declaration for a builder whose spatial splits add
 * references; then the largest of validation's and EPO's arrays (slot and
 * primitive owners, the coverage check's reference lists, parent links,
 * area sums: 24 at most) and the tracing copies of the configured
 * traversals (trace_per_prim).
 */
#define TREE_PER_PRIM 68
#define CHECKS_PER_PRIM 24
/* The binary copies (trace_view.c): the nodes and the vertices in slot order. */
#define BINARY_COPY_PER_PRIM (2 * 32 + 36)
/* The wide nodes and triangle groups (wide_bvh.c): groups of 4 triangles,
 * 160 bytes each, a leaf lane's subtree of up to 8 taking one or two, and
 * 4-child nodes of 128 bytes; what tracing added on igea subdivided twice
 * was 62.5 (lbvh) and 60.6 (hlbvh), with a margin for other trees. */
#define WIDE_COPY_PER_PRIM 72

/* The largest tracing copy of the traversals (a bit per enum
 * bvhlab_traversal) a run times (the traversals of a batch run one after
 * another, each freeing its copy). A device traversal counts the host's
 * copy and the device's buffers, which a CPU device (PoCL) keeps in host
 * memory too. */
static uint64_t trace_per_prim(const struct config *cfg, unsigned traversals)
{
	static const uint64_t per[BVHLAB_TRAVERSAL_COUNT] = {
		[BVHLAB_TRAVERSAL_STACK] = BINARY_COPY_PER_PRIM,
		[BVHLAB_TRAVERSAL_STACKLESS] = BINARY_COPY_PER_PRIM + 8,
		[BVHLAB_TRAVERSAL_WIDE] = WIDE_COPY_PER_PRIM,
		[BVHLAB_TRAVERSAL_WIDE4] = WIDE_COPY_PER_PRIM,
		[BVHLAB_TRAVERSAL_WIDE8] = WIDE_COPY_PER_PRIM,
		[BVHLAB_TRAVERSAL_DEVICE_STACK] = 2 * BINARY_COPY_PER_PRIM,
		[BVHLAB_TRAVERSAL_DEVICE_STACKLESS] = 2 * BINARY_COPY_PER_PRIM + 8,
	};
	uint64_t most = 0;
	if ((uint64_t)cfg->ray_width * cfg->ray_height == 0)
		return 0;
	for (int k = 0; k < BVHLAB_TRAVERSAL_COUNT; k++)
		if (traversals & (1u << k) && per[k] > most)
			most = per[k];
	return most;
}

/* Bytes per primitive held after the builds, the tree included; with
 * `spare_kept` (frames build again) the output keeps the builds' scratch. */
static uint64_t after_per_prim(const struct config *cfg, const struct harness_builder *hb,
                               uint64_t declared, bool spare_kept)
{
	bool spatial = bvhlab_plugin_builder(hb->plugin)->flags & BVHLAB_BUILDER_SPATIAL_SPLITS;
	uint64_t tree = spatial || spare_kept || declared < TREE_PER_PRIM ? declared
	                                                                    : TREE_PER_PRIM;
	uint64_t trace = trace_per_prim(cfg, cfg->ray_traversals);
	return tree + (trace > CHECKS_PER_PRIM ? trace : CHECKS_PER_PRIM);
}

/* e's limit (the builder's or the config's memory_limit_mb, else the memory
 * available plus the scene's arrays, resident already: taken out of what is
 * available); whether e->bytes exceeds a known one. */
static bool over_limit(const struct config *cfg, const struct harness_builder *hb,
                       struct memory_estimate *e)
{
	uint64_t mb = hb->cb->memory_limit_mb ? hb->cb->memory_limit_mb : cfg->memory_limit_mb;
	e->limit_from_config = mb != 0;
	if (mb) {
		e->limit_bytes = mb << 20;
	} else {
		uint64_t available = machine_memory_available();
		e->limit_bytes = available ? available + e->scene_bytes : 0;
	}
	e->known = e->limit_bytes != 0;
	return e->known && e->bytes > e->limit_bytes;
}

/* What a refused run was held against, for its message. */
static void limit_text(const struct memory_estimate *e, char *buf, size_t size)
{
	if (e->limit_from_config)
		snprintf(buf, size, "memory_limit_mb = %llu", (unsigned long long)(e->limit_bytes >> 20));
	else
		snprintf(buf, size, "the memory available (%.0f MiB, memory_limit_mb unset)",
		         (double)e->limit_bytes / MIB);
}

static void describe(const struct memory_estimate *e, const char *scene,
                     const struct harness_builder *hb, uint32_t prims, char *why, size_t size)
{
	char limit[96];
	limit_text(e, limit, sizeof(limit));
	uint64_t most = e->bytes_per_prim > e->after_bytes_per_prim ? e->bytes_per_prim
	                                                            : e->after_bytes_per_prim;
	snprintf(why, size, "scene '%s', builder '%s': refused before building: estimated peak "
	         "%.0f MiB (the scene's %.0f MiB + %u triangles x %llu bytes, the larger of "
	         "the build's %llu per triangle (%s) and validation and tracing's %llu) "
	         "exceeds %s",
	         scene, hb->cb->name, (double)e->bytes / MIB, (double)e->scene_bytes / MIB,
	         prims, (unsigned long long)most, (unsigned long long)e->bytes_per_prim,
	         e->declared ? "declared" : "assumed, not declared",
	         (unsigned long long)e->after_bytes_per_prim, limit);
}

int harness_estimate_run(const struct config *cfg, const struct harness_builder *hb,
                         const char *scene, const bvhlab_build_input *in, bool frames,
                         struct memory_estimate *e, char *why, size_t size)
{
	*e = (struct memory_estimate){.scene_bytes = harness_memory_scene_bytes(in)};
	e->bytes_per_prim = per_prim(hb, &e->declared);
	e->after_bytes_per_prim = after_per_prim(cfg, hb, e->bytes_per_prim, frames);
	uint64_t most = e->bytes_per_prim > e->after_bytes_per_prim ? e->bytes_per_prim
	                                                            : e->after_bytes_per_prim;
	e->bytes = e->scene_bytes + most * in->prim_count;
	if (!over_limit(cfg, hb, e))
		return 0;
	describe(e, scene, hb, in->prim_count, why, size);
	return -E2BIG;
}

/* ---- two-level runs ------------------------------------------------------------ */

/*
 * A two-level run holds its bottom trees all at once, as built (their
 * scratch is not given back: the top and tracing follow), so per unique
 * triangle it needs the bottom build's declaration plus validation's or
 * tracing's copies (per mesh, trace_instances.c); per instance the top
 * build's declaration, the instances' world boxes and the top's input
 * (box and centroid: 24 + 24 + 12) and the stackless traversal's parent
 * links over the top (2 nodes x 4 bytes).
 */
#define TOP_INPUT_PER_INSTANCE (24 + 24 + 12)
#define TOP_TRACE_PER_INSTANCE 8

/* The traversals a two-level run times: the device ones are left out, and
 * stack stands in for them (harness_two_level.c). */
static unsigned two_level_traversals(const struct config *cfg)
{
	unsigned cpu = 0;
	for (int k = 0; k < BVHLAB_TRAVERSAL_COUNT; k++)
		if (cfg->ray_traversals & (1u << k))
			cpu |= trace_cl_traversal(k) ? 1u << BVHLAB_TRAVERSAL_STACK : 1u << k;
	return cpu;
}

static void describe_two_level(const struct memory_estimate *e, const char *scene,
                               const struct harness_builder *hb, uint64_t unique,
                               uint64_t top_declared, char *why, size_t size)
{
	char limit[96];
	limit_text(e, limit, sizeof(limit));
	snprintf(why, size, "scene '%s', builder '%s': refused before building: estimated peak "
	         "%.0f MiB (the meshes' and instances' %.0f MiB + %llu unique triangles x %llu "
	         "bytes, the bottom builds' %llu (%s) and validation and tracing's %llu, + %llu "
	         "instances x %llu bytes, the top build's %llu and its input and tracing's %u) "
	         "exceeds %s",
	         scene, hb->cb->name, (double)e->bytes / MIB, (double)e->scene_bytes / MIB,
	         (unsigned long long)unique,
	         (unsigned long long)(e->bytes_per_prim + e->after_bytes_per_prim),
	         (unsigned long long)e->bytes_per_prim, e->declared ? "declared" : "assumed",
	         (unsigned long long)e->after_bytes_per_prim, (unsigned long long)e->instances,
	         (unsigned long long)e->top_bytes_per_instance, (unsigned long long)top_declared,
	         TOP_INPUT_PER_INSTANCE + TOP_TRACE_PER_INSTANCE, limit);
}

int harness_estimate_two_level(const struct config *cfg, const struct harness_builder *hb,
                               const char *scene, const struct scene_instanced *inst,
                               struct memory_estimate *e, char *why, size_t size)
{
	uint64_t unique = scene_instanced_unique_triangles(inst), trace;
	bool top_declared;
	uint64_t top = bvhlab_builder_peak_bytes_per_prim(bvhlab_plugin_builder(hb->top.plugin),
	                                                  hb->top.opts.filled, &top_declared);
	*e = (struct memory_estimate){.scene_bytes = harness_memory_instanced_bytes(inst),
	                              .instances = inst->instance_count};
	e->bytes_per_prim = per_prim(hb, &e->declared);
	e->declared = e->declared && top_declared;
	trace = trace_per_prim(cfg, two_level_traversals(cfg));
	e->after_bytes_per_prim = trace > CHECKS_PER_PRIM ? trace : CHECKS_PER_PRIM;
	e->top_bytes_per_instance = top + TOP_INPUT_PER_INSTANCE + TOP_TRACE_PER_INSTANCE;
	e->bytes = e->scene_bytes + (e->bytes_per_prim + e->after_bytes_per_prim) * unique +
	           e->top_bytes_per_instance * e->instances;
	if (!over_limit(cfg, hb, e))
		return 0;
	describe_two_level(e, scene, hb, unique, top, why, size);
	return -E2BIG;
}
