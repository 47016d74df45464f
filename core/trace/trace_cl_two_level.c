/*
 * A two-level scene on the device (trace_cl.h's trace_cl_two_level_create,
 * kernels in trace_cl_two_level.cl): every mesh's bottom tree goes up once,
 * the meshes' arrays one after another with a table of where each begins
 * (so a kernel reads mesh m's tree as the one-level kernels read a tree,
 * its links and leaf ranges unchanged); then the top tree and its parent
 * links, and each instance's world-to-object matrix (the inverse the CPU
 * keeps, in double) and mesh.
 */
#include <errno.h>
#include <stdlib.h>
#include <string.h>

#include "trace/trace_cl_host.h"
#include "trace/trace_instances.h"
#include "trace/trace_layout.h"
#include "util/util.h"

/* The bottom trees concatenated, host side. */
struct bottoms {
	struct tree_arrays all; /* nodes and extra: every mesh's in turn */
	float *verts;
	uint32_t *prim_index;
	uint32_t *table; /* [mesh_count][TRACE_MESH_FIELDS] */
	size_t slots;
};

/* Mesh m's place in the concatenation: its row of the table, and the
 * running totals (nodes, links, slots) moved past it. */
static int place_mesh(struct bottoms *b, uint32_t m, const struct tree_arrays *a,
                      const bvhlab_tree *tree, const bvhlab_scene *mesh, size_t *totals,
                      bvhlab_error *err)
{
	uint32_t *row = b->table + (size_t)m * TRACE_MESH_FIELDS;
	row[TRACE_MESH_NODE_BASE] = (uint32_t)totals[0];
	row[TRACE_MESH_NODES] = a->node_count;
	row[TRACE_MESH_LINK_BASE] = (uint32_t)totals[1];
	row[TRACE_MESH_SLOT_BASE] = (uint32_t)totals[2];
	row[TRACE_MESH_SLOTS] = tree->index_count;
	row[TRACE_MESH_TRIS] = mesh->triangle_count;
	totals[0] += a->node_count;
	totals[1] += a->extra_count;
	totals[2] += tree->index_count;
	for (int k = 0; k < 3; k++)
		if (totals[k] > UINT32_MAX) {
			error_set(err, "cl: the bottom trees have more than 2^32 %s, past the kernels' "
			          "32-bit offsets", k == 0 ? "nodes" : k == 1 ? "links" : "leaf slots");
			return -EINVAL;
		}
	return 0;
}

/* The meshes' arrays one after another (sizes from place_mesh's totals). */
static int concatenate(const struct trace_two_level *tl, const struct tree_arrays *a,
                       const size_t *totals, struct bottoms *b)
{
	const struct scene_instanced *inst = tl->inst;
	size_t node_size = 0, extra_size = 0, n = 0, e = 0, s = 0;
	for (uint32_t m = 0; m < inst->mesh_count; m++) {
		node_size = a[m].node_count ? a[m].node_bytes / a[m].node_count : node_size;
		extra_size = a[m].extra_count ? a[m].extra_bytes / a[m].extra_count : extra_size;
	}
	b->all.node_bytes = totals[0] * node_size;
	b->all.extra_bytes = totals[1] * extra_size;
	b->slots = totals[2];
	char *nodes = malloc(b->all.node_bytes + 1), *extra = malloc(b->all.extra_bytes + 1);
	b->all.nodes = nodes;
	b->all.extra = extra;
	b->verts = malloc((b->slots * TRACE_SLOT_FLOATS + 1) * sizeof(float));
	b->prim_index = malloc((b->slots + 1) * sizeof(uint32_t));
	if (!nodes || !extra || !b->verts || !b->prim_index)
		return -ENOMEM;
	for (uint32_t m = 0; m < inst->mesh_count; m++) {
		const bvhlab_tree *tree = &tl->bottom[m];
		memcpy(nodes + n, a[m].nodes, a[m].node_bytes);
		memcpy(extra + e, a[m].extra, a[m].extra_bytes);
		memcpy(b->prim_index + s, tree->prim_index, tree->index_count * sizeof(uint32_t));
		trace_cl_slot_vertices(tree, inst->meshes[m], b->verts + s * TRACE_SLOT_FLOATS);
		n += a[m].node_bytes;
		e += a[m].extra_bytes;
		s += tree->index_count;
	}
	return 0;
}

/* Every mesh's arrays for traversal, concatenated into b; *need the
 * deepest stack one of them needs. */
static int gather(const struct trace_two_level *tl, int traversal, struct bottoms *b,
                  unsigned *need, bvhlab_error *err)
{
	uint32_t count = tl->inst->mesh_count;
	struct tree_arrays *a = calloc(count ? count : 1, sizeof(*a));
	size_t totals[3] = {0, 0, 0};
	b->table = calloc((size_t)(count ? count : 1) * TRACE_MESH_FIELDS, sizeof(uint32_t));
	int r = a && b->table ? 0 : -ENOMEM;
	for (uint32_t m = 0; r == 0 && m < count; m++) {
		r = trace_cl_arrays(&tl->bottom[m], traversal, &a[m], err);
		if (r < 0 && r != -ENOMEM)
			error_prefix(err, "mesh %u's bottom tree", m);
		if (r == 0)
			r = place_mesh(b, m, &a[m], &tl->bottom[m], tl->inst->meshes[m], totals, err);
		*need = r == 0 && a[m].need > *need ? a[m].need : *need;
	}
	if (r == 0)
		r = concatenate(tl, a, totals, b);
	if (r == -ENOMEM)
		error_set(err, "cl: out of memory");
	for (uint32_t m = 0; a && m < count; m++)
		trace_cl_arrays_free(&a[m]);
	free(a);
	return r;
}

static void bottoms_free(struct bottoms *b)
{
	free((void *)b->all.nodes);
	free((void *)b->all.extra);
	free(b->verts);
	free(b->prim_index);
	free(b->table);
}

/* The instances' inverse matrices and meshes, as the kernels read them. */
static int upload_instances(struct trace_cl_tree *t, const struct scene_instanced *inst,
                            bvhlab_error *err)
{
	uint32_t n = inst->instance_count;
	double *inv = malloc(((size_t)n * 12 + 1) * sizeof(*inv));
	uint32_t *mesh = malloc(((size_t)n + 1) * sizeof(*mesh));
	size_t want[] = {(size_t)n * 12 * sizeof(*inv), (size_t)n * sizeof(*mesh)};
	int r = inv && mesh ? 0 : -ENOMEM;
	if (r < 0)
		error_set(err, "cl: out of memory");
	for (uint32_t i = 0; r == 0 && i < n; i++) {
		memcpy(inv + 12 * (size_t)i, inst->instances[i].inv, 12 * sizeof(*inv));
		mesh[i] = inst->instances[i].mesh;
	}
	if (r == 0)
		r = trace_cl_fits(t->dev, want, 2, err);
	if (r == 0)
		r = trace_cl_upload(t->dev, inv, want[0], &t->inverse, "instance matrices", err);
	if (r == 0)
		r = trace_cl_upload(t->dev, mesh, want[1], &t->inst_mesh, "instance meshes", err);
	free(inv);
	free(mesh);
	return r;
}

/* The top tree (top: its arrays, the parent links as extra) and the mesh
 * table. */
static int upload_top(struct trace_cl_tree *t, const bvhlab_tree *top,
                      const struct tree_arrays *a, const struct bottoms *b, uint32_t meshes,
                      bvhlab_error *err)
{
	size_t want[] = {a->node_bytes, (size_t)top->index_count * sizeof(uint32_t), a->extra_bytes,
	                 (size_t)meshes * TRACE_MESH_FIELDS * sizeof(uint32_t)};
	int r = trace_cl_fits(t->dev, want, 4, err);
	if (r == 0)
		r = trace_cl_upload(t->dev, a->nodes, want[0], &t->top, "top nodes", err);
	if (r == 0)
		r = trace_cl_upload(t->dev, top->prim_index, want[1], &t->top_index, "top prim_index",
		                    err);
	if (r == 0)
		r = trace_cl_upload(t->dev, a->extra, want[2], &t->top_parents, "top links", err);
	if (r == 0)
		r = trace_cl_upload(t->dev, b->table, want[3], &t->meshes, "mesh table", err);
	return r;
}

static int set_two_level_args(struct trace_cl_tree *t, const struct trace_two_level *tl,
                              bvhlab_error *err)
{
	char why[256];
	cl_kernel k = t->kernel;
	cl_uint top_count = tl->top->node_count, top_index = tl->top->index_count;
	cl_uint instances = tl->inst->instance_count;
	cl_int rc = clSetKernelArg(k, TRACE_ARG_TOP, sizeof(cl_mem), &t->top);
	rc |= clSetKernelArg(k, TRACE_ARG_TOP_INDEX, sizeof(cl_mem), &t->top_index);
	rc |= clSetKernelArg(k, TRACE_ARG_TOP_PARENTS, sizeof(cl_mem), &t->top_parents);
	rc |= clSetKernelArg(k, TRACE_ARG_TOP_COUNT, sizeof(cl_uint), &top_count);
	rc |= clSetKernelArg(k, TRACE_ARG_TOP_INDEX_COUNT, sizeof(cl_uint), &top_index);
	rc |= clSetKernelArg(k, TRACE_ARG_MESHES, sizeof(cl_mem), &t->meshes);
	rc |= clSetKernelArg(k, TRACE_ARG_INVERSE, sizeof(cl_mem), &t->inverse);
	rc |= clSetKernelArg(k, TRACE_ARG_INSTANCE_MESH, sizeof(cl_mem), &t->inst_mesh);
	rc |= clSetKernelArg(k, TRACE_ARG_INSTANCE_COUNT, sizeof(cl_uint), &instances);
	int r = bvhlab_cl_check(rc ? CL_INVALID_KERNEL_ARGS : CL_SUCCESS, "clSetKernelArg", why,
	                        sizeof(why));
	if (r < 0)
		error_set(err, "%s", why);
	return r;
}

/* Whether the device has doubles: without, the program has no two-level
 * kernels (trace_cl_two_level.cl), and that is the reason to give. */
static bool has_doubles(const bvhlab_cl *d)
{
	char ext[8192] = "";
	if (clGetDeviceInfo(d->device, CL_DEVICE_EXTENSIONS, sizeof(ext) - 1, ext, NULL) !=
	    CL_SUCCESS)
		return true; /* unknown: the kernel's own error stands */
	return strstr(ext, "cl_khr_fp64") != NULL;
}

static int make_kernel(struct trace_cl_tree *t, const char *device, int traversal,
                       unsigned need, bvhlab_error *err)
{
	int r = trace_cl_make_kernel(t, device, trace_cl_kernel_name(traversal, true), need, err);
	if (r < 0 && t->dev && !has_doubles(t->dev)) {
		error_set(err, "cl: %s has no doubles (cl_khr_fp64), which a two-level scene's "
		          "traversal needs to carry rays into instances as the CPU does",
		          t->dev->name);
		r = -ENOTSUP;
	}
	return r;
}

static int create(struct trace_cl_tree *t, const char *device, int traversal,
                  const struct trace_two_level *tl, bvhlab_error *err)
{
	struct bottoms b = {0};
	struct tree_arrays top;
	unsigned need = 0;
	int r = trace_cl_arrays(tl->top, BVHLAB_TRAVERSAL_DEVICE_STACK, &top, err);
	if (r == 0)
		r = gather(tl, traversal, &b, &need, err);
	t->two_level = true;
	t->node_count = t->index_count = t->tri_count = 0; /* per mesh, in the table */
	if (r == 0)
		r = make_kernel(t, device, traversal, top.need > need ? top.need : need, err);
	if (r == 0)
		r = trace_cl_upload_trees(t, &b.all, b.verts, b.prim_index, b.slots, err);
	if (r == 0)
		r = upload_top(t, tl->top, &top, &b, tl->inst->mesh_count, err);
	if (r == 0)
		r = upload_instances(t, tl->inst, err);
	if (r == 0)
		r = trace_cl_set_tree_args(t, err);
	if (r == 0)
		r = set_two_level_args(t, tl, err);
	trace_cl_arrays_free(&top);
	bottoms_free(&b);
	return r;
}

int trace_cl_two_level_create(const char *device, int traversal,
                              const struct trace_two_level *tl, struct trace_cl_tree **out,
                              bvhlab_error *err)
{
	*out = NULL;
	if (!trace_cl_kernel_name(traversal, true)) {
		error_set(err, "cl: not a device traversal (%d)", traversal);
		return -EINVAL;
	}
	struct trace_cl_tree *t = calloc(1, sizeof(*t));
	if (!t) {
		error_set(err, "cl: out of memory");
		return -ENOMEM;
	}
	int r = create(t, device, traversal, tl, err);
	if (r < 0) {
		trace_cl_tree_destroy(t);
		return r;
	}
	*out = t;
	return 0;
}
