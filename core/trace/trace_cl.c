/*
 * The device traversals' host side (trace_cl.h): a tree's program (from
 * the process's device layer, core/device) and buffers, a batch's
 * buffers, one timed pass.
 */
#include <errno.h>
#include <stdlib.h>
#include <string.h>

#include <bvhlab/opencl.h>
#include <bvhlab/trace.h>

#include "device/device.h"
#include "device/device_run.h"
#include "trace/cwbvh.h"
#include "trace/trace_cl.h"
#include "trace/trace_cl_host.h"
#include "trace/trace_cl_source.h"
#include "trace/trace_layout.h"
#include "tree/tree_view.h"
#include "util/util.h"

#define RAYS_PER_GROUP 64

/* The OpenCL C version; the stack kernel's stack size. No -cl-mad-enable,
 * no fast math: the same operations as the CPU, each rounded the same (the
 * device layer asks for correctly rounded division where the device has
 * it; a device without it may then give other hits, and the disagreements
 * say so). */
#define BUILD_OPTIONS "-cl-std=CL1.2 -DSTACK_SIZE=%u"

struct trace_cl_batch {
	struct trace_cl_tree *t;
	cl_mem rays, hits, counts;
	cl_mem inst; /* a two-level tree's: each ray's hit instance */
	size_t count;
	cl_uint any;
};

bool trace_cl_built(void)
{
	return true;
}

static void cl_error(bvhlab_error *err, const char *msg)
{
	error_set(err, "%s", msg);
}

/* The most far children the stack kernel holds at once on this tree: over
 * the root-to-leaf paths, the most sum of (children - 1) of the inner
 * nodes on one (a binary tree's depth). -EINVAL for links that leave the
 * array or a node wider than the ABI allows. */
static int stack_need(const bvhlab_tree *tree, unsigned *need)
{
	uint32_t n = tree->node_count, sp = 0;
	uint32_t (*stack)[2] = malloc((n ? n : 1) * sizeof(*stack));
	*need = 0;
	if (!stack)
		return -ENOMEM;
	if (n)
		stack[sp][0] = 0, stack[sp++][1] = 0;
	while (sp) {
		uint32_t node = stack[--sp][0], d = stack[sp][1];
		const bvhlab_node *nd = &tree->nodes[node];
		uint32_t k = tree_child_count(nd);
		if (tree_is_leaf(nd))
			continue;
		if (k > TREE_MAX_WIDTH || tree_child(nd, 0) == 0 || tree_children_end(nd) > n ||
		    sp + k > n) {
			free(stack);
			return -EINVAL;
		}
		*need = d + k - 1 > *need ? d + k - 1 : *need;
		for (uint32_t i = 0; i < k; i++)
			stack[sp][0] = tree_child(nd, i), stack[sp++][1] = d + k - 1;
	}
	free(stack);
	return 0;
}

static unsigned stack_size(unsigned need)
{
	unsigned s = TRACE_MIN_STACK;
	while (s < need + 1)
		s *= 2;
	return s;
}

/* The layer's check, so a tree or batch too big is refused with the
 * figures, not by the driver. */
int trace_cl_fits(const bvhlab_cl *d, const size_t *want, unsigned count, bvhlab_error *err)
{
	char why[512];
	int r = cl_bufs_fit_on(d, want, count, why, sizeof(why));
	if (r < 0)
		error_set(err, "%s", why);
	return r;
}

int trace_cl_upload(const bvhlab_cl *d, const void *data, size_t bytes, cl_mem *out,
                    const char *what, bvhlab_error *err)
{
	char why[256];
	cl_int rc;
	static const uint32_t zero = 0;
	*out = clCreateBuffer(d->context, CL_MEM_READ_ONLY | CL_MEM_COPY_HOST_PTR,
	                      bytes ? bytes : sizeof(zero), bytes ? (void *)data : (void *)&zero,
	                      &rc);
	int r = bvhlab_cl_check(rc, what, why, sizeof(why));
	if (r < 0)
		error_set(err, "%s (%zu bytes on %s)", why, bytes, d->name);
	return r;
}

/* As the CPU batch copy. */
void trace_cl_slot_vertices(const bvhlab_tree *tree, const bvhlab_scene *scene, float *v)
{
	memset(v, 0, (size_t)tree->index_count * TRACE_SLOT_FLOATS * sizeof(*v));
	for (uint32_t i = 0; i < tree->index_count; i++) {
		uint32_t prim = tree->prim_index[i];
		if (prim >= scene->triangle_count)
			continue; /* zeros: the kernel skips such slots */
		for (int k = 0; k < 3; k++)
			memcpy(v + TRACE_SLOT_FLOATS * (size_t)i + 3 * k,
			       scene->vertices + 3 * (size_t)scene->indices[3 * (size_t)prim + k],
			       3 * sizeof(float));
	}
}

int trace_cl_arrays(const bvhlab_tree *tree, int traversal, struct tree_arrays *a,
                    bvhlab_error *err)
{
	*a = (struct tree_arrays){.nodes = tree->nodes, .node_count = tree->node_count,
	                          .node_bytes = (size_t)tree->node_count * sizeof(bvhlab_node)};
	int r = stack_need(tree, &a->need);
	if (r < 0) {
		error_set(err, r == -ENOMEM ? "cl: out of memory" : "cl: the tree's links leave it");
		return r;
	}
	if (traversal == BVHLAB_TRAVERSAL_DEVICE_WIDE8) {
		r = cwbvh_encode(tree, &a->cw, err);
		a->nodes = a->cw.nodes;
		a->node_count = a->cw.node_count;
		a->node_bytes = (size_t)a->cw.node_count * sizeof(cw_node);
		a->extra = a->cw.leaves;
		a->extra_count = a->cw.leaf_count;
		a->extra_bytes = (size_t)a->cw.leaf_count * sizeof(*a->cw.leaves);
		a->need = a->cw.depth;
		return r;
	}
	r = bvhlab_tree_parents(tree, &a->parents);
	if (r == -EINVAL)
		error_set(err, "cl: the tree's child links do not make a tree");
	else if (r < 0)
		error_set(err, "cl: out of memory");
	a->extra = a->parents;
	a->extra_count = tree->node_count;
	a->extra_bytes = (size_t)tree->node_count * sizeof(uint32_t);
	return r;
}

void trace_cl_arrays_free(struct tree_arrays *a)
{
	free(a->parents);
	cwbvh_free(&a->cw);
	a->parents = NULL;
}

int trace_cl_upload_trees(struct trace_cl_tree *t, const struct tree_arrays *a,
                          const float *verts, const uint32_t *prim_index, size_t slots,
                          bvhlab_error *err)
{
	size_t want[] = {a->node_bytes, slots * TRACE_SLOT_FLOATS * sizeof(float),
	                 slots * sizeof(uint32_t), a->extra_bytes};
	int r = trace_cl_fits(t->dev, want, 4, err);
	if (r == 0)
		r = trace_cl_upload(t->dev, a->nodes, want[0], &t->nodes, "nodes", err);
	if (r == 0)
		r = trace_cl_upload(t->dev, verts, want[1], &t->tris, "triangles", err);
	if (r == 0)
		r = trace_cl_upload(t->dev, prim_index, want[2], &t->prim_index, "prim_index", err);
	if (r == 0)
		r = trace_cl_upload(t->dev, a->extra, want[3], &t->extra, "links", err);
	return r;
}

static int upload_tree(struct trace_cl_tree *t, const bvhlab_tree *tree,
                       const bvhlab_scene *scene, const struct tree_arrays *a,
                       bvhlab_error *err)
{
	float *verts = malloc(((size_t)tree->index_count * TRACE_SLOT_FLOATS + 1) * sizeof(*verts));
	if (!verts) {
		error_set(err, "cl: out of memory");
		return -ENOMEM;
	}
	trace_cl_slot_vertices(tree, scene, verts);
	int r = trace_cl_upload_trees(t, a, verts, tree->prim_index, tree->index_count, err);
	free(verts);
	return r;
}

int trace_cl_set_tree_args(struct trace_cl_tree *t, bvhlab_error *err)
{
	char why[256];
	cl_int rc = clSetKernelArg(t->kernel, TRACE_ARG_NODES, sizeof(cl_mem), &t->nodes);
	rc |= clSetKernelArg(t->kernel, TRACE_ARG_TRIS, sizeof(cl_mem), &t->tris);
	rc |= clSetKernelArg(t->kernel, TRACE_ARG_PRIM_INDEX, sizeof(cl_mem), &t->prim_index);
	rc |= clSetKernelArg(t->kernel, TRACE_ARG_PARENTS, sizeof(cl_mem), &t->extra);
	rc |= clSetKernelArg(t->kernel, TRACE_ARG_NODE_COUNT, sizeof(cl_uint), &t->node_count);
	rc |= clSetKernelArg(t->kernel, TRACE_ARG_INDEX_COUNT, sizeof(cl_uint), &t->index_count);
	rc |= clSetKernelArg(t->kernel, TRACE_ARG_TRI_COUNT, sizeof(cl_uint), &t->tri_count);
	int r = bvhlab_cl_check(rc ? CL_INVALID_KERNEL_ARGS : CL_SUCCESS, "clSetKernelArg", why,
	                        sizeof(why));
	if (r < 0)
		cl_error(err, why);
	return r;
}

const char *trace_cl_kernel_name(int traversal, bool two_level)
{
	switch (traversal) {
	case BVHLAB_TRAVERSAL_DEVICE_STACK:
		return two_level ? "trace_two_level_stack" : "trace_stack";
	case BVHLAB_TRAVERSAL_DEVICE_STACKLESS:
		return two_level ? "trace_two_level_stackless" : "trace_stackless";
	case BVHLAB_TRAVERSAL_DEVICE_WIDE8:
		return two_level ? "trace_two_level_wide8" : "trace_wide8";
	default:
		return NULL;
	}
}

/* From the process's device layer (core/device). */
int trace_cl_make_kernel(struct trace_cl_tree *t, const char *device, const char *name,
                         unsigned need, bvhlab_error *err)
{
	char why[BVHLAB_CL_ERROR_SIZE], options[64];
	const void *dev;
	void *prog;
	snprintf(options, sizeof(options), BUILD_OPTIONS, stack_size(need));
	int r = device_program(device, trace_cl_source, trace_cl_source_LEN, options, &dev, &prog,
	                       why, sizeof(why));
	if (r == 0) {
		t->dev = dev;
		r = bvhlab_cl_kernel(prog, name, &t->kernel, why, sizeof(why));
	}
	if (r < 0)
		cl_error(err, why);
	return r;
}

/* The stack and stackless kernels read trees of any width through
 * tree_node.h: a tree goes up as it is; wide8's compressed (cwbvh.c). */
int trace_cl_tree_create(const char *device, int traversal, const bvhlab_tree *tree,
                         const bvhlab_scene *scene, struct trace_cl_tree **out,
                         bvhlab_error *err)
{
	struct tree_arrays a;
	*out = NULL;
	if (!trace_cl_kernel_name(traversal, false)) {
		error_set(err, "cl: not a device traversal (%d)", traversal);
		return -EINVAL;
	}
	int r = trace_cl_arrays(tree, traversal, &a, err);
	struct trace_cl_tree *t = r == 0 ? calloc(1, sizeof(*t)) : NULL;
	if (r == 0 && !t)
		r = -ENOMEM;
	if (t) {
		t->node_count = a.node_count;
		t->index_count = tree->index_count;
		t->tri_count = scene->triangle_count;
		r = trace_cl_make_kernel(t, device, trace_cl_kernel_name(traversal, false), a.need,
		                         err);
	}
	if (r == 0)
		r = upload_tree(t, tree, scene, &a, err);
	if (r == 0)
		r = trace_cl_set_tree_args(t, err);
	trace_cl_arrays_free(&a);
	if (r < 0) {
		trace_cl_tree_destroy(t);
		return r;
	}
	*out = t;
	return 0;
}

void trace_cl_tree_destroy(struct trace_cl_tree *t)
{
	if (!t)
		return;
	bvhlab_cl_release_kernel(&t->kernel);
	bvhlab_cl_release_mem(&t->nodes);
	bvhlab_cl_release_mem(&t->tris);
	bvhlab_cl_release_mem(&t->prim_index);
	bvhlab_cl_release_mem(&t->extra);
	bvhlab_cl_release_mem(&t->top);
	bvhlab_cl_release_mem(&t->top_index);
	bvhlab_cl_release_mem(&t->top_parents);
	bvhlab_cl_release_mem(&t->meshes);
	bvhlab_cl_release_mem(&t->inverse);
	bvhlab_cl_release_mem(&t->inst_mesh);
	free(t);
}

const char *trace_cl_device_name(const struct trace_cl_tree *t)
{
	return t->dev->name;
}

static int output_buffer(struct trace_cl_tree *t, size_t bytes, cl_mem *out, bvhlab_error *err)
{
	char why[256];
	cl_int rc;
	*out = clCreateBuffer(t->dev->context, CL_MEM_WRITE_ONLY, bytes ? bytes : 16, NULL, &rc);
	int r = bvhlab_cl_check(rc, "clCreateBuffer", why, sizeof(why));
	if (r < 0)
		error_set(err, "%s (%zu bytes on %s)", why, bytes, t->dev->name);
	return r;
}

int trace_cl_batch_create(struct trace_cl_tree *t, const bvhlab_ray *rays, size_t count,
                          bool any_hit, struct trace_cl_batch **out, bvhlab_error *err)
{
	*out = NULL;
	if (count > UINT32_MAX - RAYS_PER_GROUP) {
		error_set(err, "cl: %zu rays in one batch: too many", count);
		return -EINVAL;
	}
	if (any_hit && t->two_level) { /* as trace_instances.c: closest hits only */
		error_set(err, "cl: a two-level scene is traced for closest hits only");
		return -EINVAL;
	}
	struct trace_cl_batch *b = calloc(1, sizeof(*b));
	if (!b)
		return -ENOMEM;
	b->t = t;
	b->count = count;
	b->any = any_hit;
	size_t want[] = {count * sizeof(*rays), count * sizeof(bvhlab_hit),
	                 count * 2 * sizeof(uint32_t), t->two_level ? count * sizeof(uint32_t) : 0};
	int r = trace_cl_fits(t->dev, want, 4, err);
	if (r == 0)
		r = trace_cl_upload(t->dev, rays, want[0], &b->rays, "rays", err);
	if (r == 0)
		r = output_buffer(t, count * sizeof(bvhlab_hit), &b->hits, err);
	if (r == 0)
		r = output_buffer(t, count * 2 * sizeof(uint32_t), &b->counts, err);
	if (r == 0 && t->two_level)
		r = output_buffer(t, want[3], &b->inst, err);
	if (r < 0) {
		trace_cl_batch_destroy(b);
		return r;
	}
	*out = b;
	return 0;
}

void trace_cl_batch_destroy(struct trace_cl_batch *b)
{
	if (!b)
		return;
	bvhlab_cl_release_mem(&b->rays);
	bvhlab_cl_release_mem(&b->hits);
	bvhlab_cl_release_mem(&b->counts);
	bvhlab_cl_release_mem(&b->inst);
	free(b);
}

/* The batch's own arguments: the kernel is the tree's, shared by its
 * batches, so they are set before every launch. */
static cl_int set_batch_args(struct trace_cl_batch *b)
{
	cl_kernel k = b->t->kernel;
	cl_uint n = (cl_uint)b->count;
	cl_int rc = clSetKernelArg(k, TRACE_ARG_RAYS, sizeof(cl_mem), &b->rays);
	rc |= clSetKernelArg(k, TRACE_ARG_RAY_COUNT, sizeof(cl_uint), &n);
	rc |= clSetKernelArg(k, TRACE_ARG_ANY, sizeof(cl_uint), &b->any);
	rc |= clSetKernelArg(k, TRACE_ARG_HITS, sizeof(cl_mem), &b->hits);
	rc |= clSetKernelArg(k, TRACE_ARG_COUNTS, sizeof(cl_mem), &b->counts);
	if (b->t->two_level)
		rc |= clSetKernelArg(k, TRACE_ARG_HIT_INSTANCE, sizeof(cl_mem), &b->inst);
	return rc ? CL_INVALID_KERNEL_ARGS : CL_SUCCESS;
}

/* The per-ray counters into nodes and stats; -EIO when a ray overflowed
 * the stack (the host sized it from the tree: cannot happen on one). */
static int take_counts(const uint32_t *c, size_t n, uint32_t *nodes, bvhlab_trace_stats *stats,
                       bvhlab_error *err)
{
	bvhlab_trace_stats s = {.rays = n};
	for (size_t i = 0; i < n; i++) {
		if (c[2 * i] == TRACE_OVERFLOW) {
			error_set(err, "cl: ray %zu overflowed the stack kernel's stack", i);
			return -EIO;
		}
		s.nodes_visited += c[2 * i];
		s.tris_tested += c[2 * i + 1];
		if (nodes)
			nodes[i] = c[2 * i];
	}
	if (stats)
		*stats = s;
	return 0;
}

static int read_back(struct trace_cl_batch *b, bvhlab_hit *hits, uint32_t *nodes,
                     bvhlab_trace_stats *stats, bvhlab_error *err)
{
	char why[256];
	cl_command_queue q = b->t->dev->queue;
	cl_int rc = CL_SUCCESS;
	uint32_t *c = malloc(b->count * 2 * sizeof(*c) + 1);
	if (!c)
		return -ENOMEM;
	if (hits) /* uint4 (t, u, v bits, prim): bvhlab_hit's layout */
		rc = clEnqueueReadBuffer(q, b->hits, CL_TRUE, 0, b->count * sizeof(*hits), hits, 0,
		                         NULL, NULL);
	if (rc == CL_SUCCESS)
		rc = clEnqueueReadBuffer(q, b->counts, CL_TRUE, 0, b->count * 2 * sizeof(*c), c, 0,
		                         NULL, NULL);
	int r = bvhlab_cl_check(rc, "clEnqueueReadBuffer", why, sizeof(why));
	if (r < 0)
		cl_error(err, why);
	else
		r = take_counts(c, b->count, nodes, stats, err);
	free(c);
	return r;
}

int trace_cl_pass(struct trace_cl_batch *b, bvhlab_hit *hits, uint32_t *nodes,
                  bvhlab_trace_stats *stats, double *kernel_s, double *wall_s,
                  bvhlab_error *err)
{
	char why[256];
	cl_events ev = {.count = 0};
	*kernel_s = *wall_s = 0;
	if (b->count == 0)
		return 0;
	cl_int rc = set_batch_args(b);
	int r = bvhlab_cl_check(rc, "clSetKernelArg", why, sizeof(why));
	double t0 = util_now();
	/* The arguments are set: the layer's launch with none of its own. */
	if (r == 0)
		r = cl_launch_on(b->t->dev, b->t->kernel, b->count, NULL, 0, &ev, why, sizeof(why));
	if (r == 0)
		r = bvhlab_cl_check(clFinish(b->t->dev->queue), "tracing kernel", why, sizeof(why));
	*wall_s = util_now() - t0;
	double ms = cl_events_ms(&ev);
	if (r < 0) {
		error_set(err, "%s on %s", why, b->t->dev->name);
		return r;
	}
	*kernel_s = ms > 0 ? ms * 1e-3 : *wall_s; /* no profiling: the wall clock */
	if (hits || nodes || stats)
		r = read_back(b, hits, nodes, stats, err);
	return r;
}

int trace_cl_instances(struct trace_cl_batch *b, uint32_t *instances, bvhlab_error *err)
{
	char why[256];
	if (!b->t->two_level) {
		error_set(err, "cl: a one-level tree's hits have no instance");
		return -EINVAL;
	}
	if (b->count == 0)
		return 0;
	cl_int rc = clEnqueueReadBuffer(b->t->dev->queue, b->inst, CL_TRUE, 0,
	                                b->count * sizeof(*instances), instances, 0, NULL, NULL);
	int r = bvhlab_cl_check(rc, "clEnqueueReadBuffer", why, sizeof(why));
	if (r < 0)
		cl_error(err, why);
	return r;
}
