/*
 * Peak memory of a run's builds, as Linux accounts it for the process that
 * runs them (the isolated child, or bvhlab itself with "isolate": false).
 * The kernel's high-water mark of the resident set (VmHWM) is reset to the
 * current resident set (clear_refs, value 5) right before the first build,
 * so the peak afterwards minus the resident set before is what the builds
 * added at their worst moment: the builder's scratch and the output, as far
 * as they were touched. Pages the child shares with its parent (the scene,
 * the primitives) are resident before and count for neither side. A
 * device builder's device is opened before that reset, so the OpenCL
 * runtime's memory is measured apart (harness_memory_device).
 */
#include <stdbool.h>
#include <stdio.h>
#include <string.h>

#include "harness/harness_memory.h"
#include "machine/machine.h"
#include "output/results.h"
#include "scene/instances.h"

/* A "Name:   123 kB" line of /proc/self/status, in bytes; 0 if absent. */
static uint64_t status_bytes(const char *name)
{
	FILE *f = fopen("/proc/self/status", "r");
	char line[256];
	size_t len = strlen(name);
	uint64_t kb = 0;
	if (!f)
		return 0;
	while (fgets(line, sizeof(line), f)) {
		unsigned long long v;
		if (strncmp(line, name, len) == 0 && line[len] == ':' &&
		    sscanf(line + len + 1, "%llu", &v) == 1) {
			kb = v;
			break;
		}
	}
	fclose(f);
	return kb * 1024;
}

uint64_t harness_memory_scene_bytes(const bvhlab_build_input *in)
{
	uint64_t per_prim = sizeof(bvhlab_aabb) + 3 * sizeof(float) +
	                    (in->indices ? 3 * sizeof(uint32_t) : 0);
	return (uint64_t)in->vertex_count * 3 * sizeof(float) + per_prim * in->prim_count;
}

uint64_t harness_memory_instanced_bytes(const struct scene_instanced *inst)
{
	uint64_t bytes = (uint64_t)inst->instance_count * sizeof(struct scene_instance);
	for (uint32_t m = 0; m < inst->mesh_count; m++) {
		const bvhlab_scene *mesh = inst->meshes[m];
		bvhlab_build_input in = {.vertex_count = mesh->vertex_count,
		                         .prim_count = mesh->triangle_count,
		                         .indices = mesh->indices};
		bytes += harness_memory_scene_bytes(&in);
	}
	return bytes;
}

void harness_memory_begin(struct build_memory *m, const bvhlab_build_input *in)
{
	harness_memory_begin_bytes(m, harness_memory_scene_bytes(in));
}

void harness_memory_begin_bytes(struct build_memory *m, uint64_t scene_bytes)
{
	FILE *f = fopen("/proc/self/clear_refs", "w");
	memset(m, 0, sizeof(*m));
	m->scene_bytes = scene_bytes;
	/* Without the reset the peak may predate the builds; then the growth
	 * is not known and is left at 0 (peak_rss still tells the peak). */
	m->reset = f && fputs("5", f) >= 0;
	if (f && fclose(f) != 0)
		m->reset = false;
	m->start_rss_bytes = status_bytes("VmRSS");
}

void harness_memory_end(struct build_memory *m, const bvhlab_tree *tree)
{
	m->peak_rss_bytes = status_bytes("VmHWM");
	m->output_bytes = harness_memory_tree_bytes(tree);
	if (m->reset && m->peak_rss_bytes > m->start_rss_bytes)
		m->peak_bytes = m->peak_rss_bytes - m->start_rss_bytes;
	m->measured = m->peak_rss_bytes > 0;
}

uint64_t harness_memory_tree_bytes(const bvhlab_tree *tree)
{
	return (uint64_t)tree->node_capacity * sizeof(bvhlab_node) +
	       (uint64_t)tree->index_capacity * sizeof(uint32_t);
}

void harness_memory_run_end(struct build_memory *m)
{
	if (m->measured)
		m->run_peak_rss_bytes = status_bytes("VmHWM");
}

/* The runtime's baseline: the resident memory machine_cl_open added the
 * first time in this process. */
static int open_device(const char *spec, struct run_device *dev)
{
	static bool measured;
	static uint64_t baseline;
	char why[256];
	uint64_t before = status_bytes("VmRSS");
	int r = machine_cl_open(spec, &dev->cl, why, sizeof(why));
	if (r < 0)
		return r;
	uint64_t after = status_bytes("VmRSS");
	if (!measured && before && after) {
		baseline = after > before ? after - before : 0;
		measured = true;
	}
	dev->runtime_measured = measured;
	dev->runtime_bytes = baseline;
	return 0;
}

bool harness_memory_device(const bvhlab_plugin *plugin, const bvhlab_options *opts,
                           struct run_device *dev)
{
	memset(dev, 0, sizeof(*dev));
	if (!(bvhlab_plugin_builder(plugin)->flags & BVHLAB_BUILDER_DEVICE))
		return false;
	int k = bvhlab_options_find(opts, "device");
	bool named = k >= 0 && opts->values[k].type == BVHLAB_OPTION_STRING;
	return open_device(named ? opts->values[k].s : NULL, dev) == 0;
}

const struct run_device *harness_memory_device_checked(struct run_device *dev)
{
	dev->cl.name[sizeof(dev->cl.name) - 1] = '\0';
	dev->cl.kind[sizeof(dev->cl.kind) - 1] = '\0';
	dev->cl.platform[sizeof(dev->cl.platform) - 1] = '\0';
	dev->cl.version[sizeof(dev->cl.version) - 1] = '\0';
	return dev;
}
