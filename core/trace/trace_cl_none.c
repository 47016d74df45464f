/*
 * The device traversals in a build without OpenCL (trace_cl.h): every
 * request is refused with the reason, so a config or caller that names
 * device_stack, device_stackless or device_wide8 learns why instead of
 * getting nothing.
 */
#include <errno.h>

#include "trace/trace_cl.h"
#include "util/util.h"

bool trace_cl_built(void)
{
	return false;
}

int trace_cl_tree_create(const char *device, int traversal, const bvhlab_tree *tree,
                         const bvhlab_scene *scene, struct trace_cl_tree **out,
                         bvhlab_error *err)
{
	(void)device, (void)traversal, (void)tree, (void)scene;
	*out = NULL;
	error_set(err, "the device traversals need OpenCL, and this bvhlab was built without it "
	               "(install ocl-icd-opencl-dev and opencl-c-headers, then meson setup again)");
	return -ENOTSUP;
}

int trace_cl_two_level_create(const char *device, int traversal,
                              const struct trace_two_level *tl, struct trace_cl_tree **out,
                              bvhlab_error *err)
{
	(void)tl;
	return trace_cl_tree_create(device, traversal, NULL, NULL, out, err);
}

void trace_cl_tree_destroy(struct trace_cl_tree *t)
{
	(void)t;
}

const char *trace_cl_device_name(const struct trace_cl_tree *t)
{
	(void)t;
	return "";
}

int trace_cl_batch_create(struct trace_cl_tree *t, const bvhlab_ray *rays, size_t count,
                          bool any_hit, struct trace_cl_batch **out, bvhlab_error *err)
{
	(void)t, (void)rays, (void)count, (void)any_hit;
	*out = NULL;
	error_set(err, "OpenCL was not built");
	return -ENOTSUP;
}

void trace_cl_batch_destroy(struct trace_cl_batch *b)
{
	(void)b;
}

int trace_cl_pass(struct trace_cl_batch *b, bvhlab_hit *hits, uint32_t *nodes,
                  bvhlab_trace_stats *stats, double *kernel_s, double *wall_s,
                  bvhlab_error *err)
{
	(void)b, (void)hits, (void)nodes, (void)stats;
	*kernel_s = *wall_s = 0;
	error_set(err, "OpenCL was not built");
	return -ENOTSUP;
}

int trace_cl_instances(struct trace_cl_batch *b, uint32_t *instances, bvhlab_error *err)
{
	(void)b, (void)instances;
	error_set(err, "OpenCL was not built");
	return -ENOTSUP;
}
