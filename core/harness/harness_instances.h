/*
 * A config's two-level scene made real (harness_instances.c): its meshes
 * loaded once, its instances and scatters expanded.
 */
#ifndef BVHLAB_CORE_HARNESS_INSTANCES_H
#define BVHLAB_CORE_HARNESS_INSTANCES_H

#include "config/config.h"
#include "output/results.h"
#include "scene/instances.h"

/* cs has "instances": 0, or a negative errno with err naming the scene and
 * the mesh or instance entry at fault, *out then as it was or zeroed. */
int harness_load_instanced(const struct config_scene *cs, struct scene_instanced *out,
                           bvhlab_error *err);

/* The same scene flattened (every instance's triangles in world space),
 * for the builders of one-level trees; named cs->name. */
int harness_load_flattened(const struct config_scene *cs, bvhlab_scene **out,
                           bvhlab_error *err);

/* For a sweep that has one-level builders on the two-level scene inst:
 * the scene flattened into *flat, refused (-E2BIG, err naming the scene
 * and its instanced triangles) when it and its primitive boxes would not
 * fit in the memory available, or past the one-level limit (-EOVERFLOW);
 * *flat NULL on failure. */
int harness_flatten(const struct config_scene *cs, const struct scene_instanced *inst,
                    bvhlab_scene **flat, bvhlab_error *err);

/* The scene's meshes, instances and triangle counts into its results
 * entry; nothing for a one-level scene (inst zeroed). */
void harness_record_instances(struct results *res, const char *scene,
                              const struct scene_instanced *inst);

#endif
