/*
 * The device traversals' host side inside core/trace (trace_cl.c, and
 * trace_cl_two_level.c for two-level scenes): a tree's buffers and kernel,
 * and the helpers both files make them with. Only with OpenCL.
 */
#ifndef BVHLAB_CORE_TRACE_CL_HOST_H
#define BVHLAB_CORE_TRACE_CL_HOST_H

#include <bvhlab/opencl.h>

#include "trace/cwbvh.h"
#include "trace/trace_cl.h"

struct trace_cl_tree {
	const bvhlab_cl *dev; /* the device layer's */
	cl_kernel kernel;
	cl_mem nodes, tris, prim_index;
	cl_mem extra; /* parent links (stackless), leaf ranges (wide8) */
	uint32_t node_count, index_count, tri_count;
	/* A two-level scene's (trace_cl_two_level.c), with the bottom trees
	 * above: the top tree, its prim_index and parent links, the mesh
	 * table, the instances' inverse matrices and meshes. */
	bool two_level;
	cl_mem top, top_index, top_parents, meshes, inverse, inst_mesh;
};

/* What goes up for a traversal of one tree: its nodes and parent links,
 * or (wide8) its compressed nodes and leaf ranges; and the stack it needs. */
struct tree_arrays {
	const void *nodes, *extra; /* extra: parent links or leaf ranges */
	size_t node_bytes, extra_bytes;
	uint32_t node_count, extra_count;
	unsigned need;
	uint32_t *parents;
	struct cwbvh cw;
};

/* tree's arrays for traversal (BVHLAB_TRAVERSAL_DEVICE_*): 0, -EINVAL
 * (links that make no tree), -ENOMEM, err saying why. Freed by
 * trace_cl_arrays_free (also after a failure). */
int trace_cl_arrays(const bvhlab_tree *tree, int traversal, struct tree_arrays *a,
                    bvhlab_error *err);
void trace_cl_arrays_free(struct tree_arrays *a);

/* Whether buffers of want[] bytes fit the device (the figures in err). */
int trace_cl_fits(const bvhlab_cl *d, const size_t *want, unsigned count, bvhlab_error *err);

/* A read-only buffer holding bytes (at least 4, so empty arrays upload). */
int trace_cl_upload(const bvhlab_cl *d, const void *data, size_t bytes, cl_mem *out,
                    const char *what, bvhlab_error *err);

/* The one-level buffers of t: a's nodes and links, the vertices of `slots`
 * leaf slots and their prim_index. */
int trace_cl_upload_trees(struct trace_cl_tree *t, const struct tree_arrays *a,
                          const float *verts, const uint32_t *prim_index, size_t slots,
                          bvhlab_error *err);

/* The triangles' vertices in leaf-slot order (TRACE_SLOT_FLOATS a slot),
 * at dst (tree->index_count slots); zeros for a slot naming no triangle. */
void trace_cl_slot_vertices(const bvhlab_tree *tree, const bvhlab_scene *scene, float *dst);

/* The kernel of a device traversal, for one tree or a two-level scene
 * (trace_cl.cl, trace_cl_two_level.cl); NULL when traversal is not one. */
const char *trace_cl_kernel_name(int traversal, bool two_level);

/* The device, the program with a stack of at least `need` entries and its
 * kernel `name` into t (t->dev, t->kernel). */
int trace_cl_make_kernel(struct trace_cl_tree *t, const char *device, const char *name,
                         unsigned need, bvhlab_error *err);

/* The one-level arguments of t's kernel (enum trace_arg's tree part). */
int trace_cl_set_tree_args(struct trace_cl_tree *t, bvhlab_error *err);

#endif
