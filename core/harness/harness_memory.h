/* Peak memory of a run's builds (harness_memory.c). */
#ifndef BVHLAB_CORE_HARNESS_MEMORY_H
#define BVHLAB_CORE_HARNESS_MEMORY_H

#include <bvhlab/bvhlab.h>

struct build_memory; /* output/results.h */

/* Before the first build (warm-up included), and after the last one;
 * in is the run's input (its scene's share is recorded). */
void harness_memory_begin(struct build_memory *m, const bvhlab_build_input *in);
/* The same with the scene's share given (a two-level scene's, below). */
void harness_memory_begin_bytes(struct build_memory *m, uint64_t scene_bytes);
void harness_memory_end(struct build_memory *m, const bvhlab_tree *tree);
/* The output buffers the host allocated for a tree, capacity. */
uint64_t harness_memory_tree_bytes(const bvhlab_tree *tree);
/* After validation and tracing: the run's peak over all of it. */
void harness_memory_run_end(struct build_memory *m);

/*
 * The scene's own bytes as the builds get it: vertices, indices and the
 * per-primitive boxes and centroids (bvhlab_prims); what every run of the
 * scene holds whatever the builder, so per-triangle figures can state it.
 */
uint64_t harness_memory_scene_bytes(const bvhlab_build_input *in);
struct scene_instanced; /* scene/instances.h */
/* A two-level scene's: each mesh's as above, and the instances' records
 * (placement and inverse). */
uint64_t harness_memory_instanced_bytes(const struct scene_instanced *inst);

struct run_device; /* output/results.h */

/*
 * For a device builder (BVHLAB_BUILDER_DEVICE): the device its "device"
 * option names (auto without one) opened before harness_memory_begin, with
 * the OpenCL runtime loaded and a context made on it (machine_cl_open), so
 * the builds' peak is their own; the resident memory that took, the
 * runtime's baseline, is measured once per process (a later run in it
 * reuses the figure). True when *dev was filled; false for a CPU builder
 * or when there is no such device (its build says so itself).
 */
bool harness_memory_device(const bvhlab_plugin *plugin, const bvhlab_options *opts,
                           struct run_device *dev);
/* dev, as sent back by a run's child, with its strings ended in their arrays. */
const struct run_device *harness_memory_device_checked(struct run_device *dev);

#endif
