/*
 * The device traversals (results' "device_stack", "device_stackless",
 * "device_wide8"): trace_cl.cl's and trace_cl_wide8.cl's kernels on an
 * OpenCL device chosen by a spec (auto, gpu, cpu or P:D,
 * include/bvhlab/opencl.h). A tree is uploaded once (nodes, its
 * triangles' vertices in leaf-slot order, prim_index, parent links; for
 * wide8 its compressed nodes and leaf ranges, cwbvh.h, instead);
 * each batch of rays once; a pass is one kernel launch, timed by its
 * profiling event (the kernel's own time) and by the wall clock (launch to
 * completion). Built only with OpenCL (BVHLAB_HAVE_OPENCL); without it
 * trace_cl_tree_create says so.
 *
 * The device and its compiled program (one per device spec and stack
 * size) come from the process's device layer (core/device/device.h), which
 * keeps them for the life of the process and shares them with the device
 * builders: PoCL takes seconds to compile a program, and a sweep's child
 * builds and traces many times.
 */
#ifndef BVHLAB_CORE_TRACE_CL_H
#define BVHLAB_CORE_TRACE_CL_H

#include <stdbool.h>
#include <stddef.h>
#include <stdint.h>

#include <bvhlab/trace.h>
#include <bvhlab/types.h>

struct trace_cl_tree;
struct trace_cl_batch;

/* Whether this build has the device traversals. */
bool trace_cl_built(void);

/* Whether traversal (enum bvhlab_traversal) is one of the device ones:
 * the one list the config, the tracer and two-level runs ask. */
static inline bool trace_cl_traversal(int traversal)
{
	return traversal == BVHLAB_TRAVERSAL_DEVICE_STACK ||
	       traversal == BVHLAB_TRAVERSAL_DEVICE_STACKLESS ||
	       traversal == BVHLAB_TRAVERSAL_DEVICE_WIDE8;
}

/* The traversal (BVHLAB_TRAVERSAL_DEVICE_STACK, _STACKLESS or _WIDE8) of
 * tree on the device `device` names (NULL: "auto"). 0, or a negative errno
 * with err saying why: -ENOTSUP OpenCL not built, -ENODEV no platform or
 * device (what to install), -EINVAL a bad spec, tree links, or (wide8) a
 * box that is not finite, -ENOMEM, -EIO. */
int trace_cl_tree_create(const char *device, int traversal, const bvhlab_tree *tree,
                         const bvhlab_scene *scene, struct trace_cl_tree **out,
                         bvhlab_error *err);
void trace_cl_tree_destroy(struct trace_cl_tree *t);

struct trace_two_level; /* trace_instances.h */

/*
 * A two-level scene on the device (trace_cl_two_level.c): tl's top tree,
 * every mesh's bottom tree once (for wide8 each compressed), and the
 * instances' world-to-object matrices, traced as trace_instances.c traces
 * them with traversal at both levels (device_wide8: its bottoms, the top
 * with the stack walk, as the CPU's wide traversals). Its batches are
 * closest-hit ones; trace_cl_instances gives each ray's instance. Errors
 * as trace_cl_tree_create's, and -ENOTSUP on a device without doubles
 * (cl_khr_fp64), which the ray's carrying into an instance needs to round
 * as the CPU's does.
 */
int trace_cl_two_level_create(const char *device, int traversal,
                              const struct trace_two_level *tl, struct trace_cl_tree **out,
                              bvhlab_error *err);

/* The device's name (CL_DEVICE_NAME). */
const char *trace_cl_device_name(const struct trace_cl_tree *t);

/* A batch of rays on t's device (t must outlive it); count may be 0. */
int trace_cl_batch_create(struct trace_cl_tree *t, const bvhlab_ray *rays, size_t count,
                          bool any_hit, struct trace_cl_batch **out, bvhlab_error *err);
void trace_cl_batch_destroy(struct trace_cl_batch *b);

/*
 * One pass over the batch: *kernel_s the kernel's own time (profiling
 * event), *wall_s launch to completion. hits and nodes (may be NULL) get
 * each ray's hit and nodes entered, stats (may be NULL) this pass's
 * counters: read back after the timed part. 0 or a negative errno (err).
 */
int trace_cl_pass(struct trace_cl_batch *b, bvhlab_hit *hits, uint32_t *nodes,
                  bvhlab_trace_stats *stats, double *kernel_s, double *wall_s,
                  bvhlab_error *err);

/* After a pass over a two-level tree's batch: each ray's hit instance
 * (BVHLAB_NO_HIT for a miss) into instances[count]. 0, -EINVAL (a
 * one-level tree's batch) or -EIO. */
int trace_cl_instances(struct trace_cl_batch *b, uint32_t *instances, bvhlab_error *err);

#endif
