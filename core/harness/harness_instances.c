/*
 * Two-level scenes from configs: each mesh loaded (or generated) once, each
 * "instances" entry expanded in config order, a scatter into its count of
 * instances drawn from its seed.
 */
#include <errno.h>
#include <stdio.h>
#include <stdlib.h>

#include "harness/harness_instances.h"
#include "harness/harness_scene.h"
#include "machine/machine.h"
#include "util/util.h"

/* Prefixes err's message with the scene and what in it failed. */
static void entry_error(bvhlab_error *err, const char *scene, const char *what, size_t i)
{
	char msg[sizeof(err->message)];
	snprintf(msg, sizeof(msg), "%s", err->message);
	error_set(err, "scene '%s' %s %zu: %s", scene, what, i, msg);
}

static int load_meshes(const struct config_scene *cs, bvhlab_scene ***out,
                       bvhlab_error *err)
{
	bvhlab_scene **meshes = calloc(cs->mesh_count, sizeof(*meshes));
	int r = meshes ? 0 : -ENOMEM;
	if (!meshes)
		error_set(err, "scene '%s': out of memory", cs->name);
	for (size_t m = 0; r == 0 && m < cs->mesh_count; m++) {
		struct config_scene src = cs->meshes[m].src;
		src.name = cs->meshes[m].name;
		r = harness_load_scene(&src, &meshes[m], err);
		if (r < 0)
			entry_error(err, cs->name, "mesh", m);
	}
	if (r < 0) {
		for (size_t m = 0; meshes && m < cs->mesh_count; m++)
			bvhlab_scene_destroy(meshes[m]);
		free(meshes);
		return r;
	}
	*out = meshes;
	return 0;
}

static int add_entry(struct scene_instanced *s, const struct config_instance *in,
                     bvhlab_error *err)
{
	if (!in->scatter)
		return scene_instanced_add(s, in->mesh, in->xf, err);
	struct scene_scatter sc = {.mesh = in->mesh, .count = in->count, .seed = in->seed,
	                           .scale = {in->scale[0], in->scale[1]},
	                           .random_y = in->rotate == CONFIG_SCATTER_RANDOM_Y};
	for (int k = 0; k < 3; k++) {
		sc.lo[k] = in->lo[k];
		sc.hi[k] = in->hi[k];
	}
	return scene_instanced_scatter(s, &sc, err);
}

int harness_load_instanced(const struct config_scene *cs, struct scene_instanced *out,
                           bvhlab_error *err)
{
	bvhlab_scene **meshes;
	int r = load_meshes(cs, &meshes, err);
	if (r < 0)
		return r;
	scene_instanced_init(out, meshes, (uint32_t)cs->mesh_count);
	for (size_t i = 0; r == 0 && i < cs->instance_count; i++) {
		r = add_entry(out, &cs->instances[i], err);
		if (r < 0)
			entry_error(err, cs->name, "instances entry", i);
	}
	if (r < 0)
		scene_instanced_finish(out);
	return r;
}

int harness_load_flattened(const struct config_scene *cs, bvhlab_scene **out,
                           bvhlab_error *err)
{
	struct scene_instanced s = {0}; /* left zeroed by a load that fails */
	int r = harness_load_instanced(cs, &s, err);
	if (r == 0)
		r = scene_instanced_flatten(&s, cs->name, out, err);
	scene_instanced_finish(&s);
	return r;
}

/* What the flattened scene and its primitives take: vertices, indices,
 * and per triangle a box and a centroid (bvhlab_prims). */
static uint64_t flat_bytes(const struct scene_instanced *inst)
{
	uint64_t v = 0;
	for (uint32_t i = 0; i < inst->instance_count; i++)
		v += inst->meshes[inst->instances[i].mesh]->vertex_count;
	return 12 * v + (12 + 24 + 12) * scene_instanced_triangles(inst);
}

int harness_flatten(const struct config_scene *cs, const struct scene_instanced *inst,
                    bvhlab_scene **flat, bvhlab_error *err)
{
	uint64_t bytes = flat_bytes(inst), available = machine_memory_available();
	*flat = NULL;
	if (available && bytes > available) {
		error_set(err, "scene '%s': flattened, its %llu instanced triangles would take "
		          "%.1f GiB with their primitive boxes, more than the %.1f GiB available; "
		          "one-level builders cannot run on it (two-level builders need no flat "
		          "scene)", cs->name, (unsigned long long)scene_instanced_triangles(inst),
		          (double)bytes / (1u << 30), (double)available / (1u << 30));
		return -E2BIG;
	}
	return scene_instanced_flatten(inst, cs->name, flat, err);
}

void harness_record_instances(struct results *res, const char *scene,
                              const struct scene_instanced *inst)
{
	if (!inst->meshes)
		return;
	struct results_instances in = {
		.meshes = inst->mesh_count, .instances = inst->instance_count,
		.unique_triangles = scene_instanced_unique_triangles(inst),
		.instanced_triangles = scene_instanced_triangles(inst)};
	results_scene_instances(res, scene, &in);
}
