/*
 * cl_hploc: H-PLOC (Benthin et al. 2024) on an OpenCL device, the tree of
 * the CPU hploc plugin for the same options. Morton codes and their sort
 * (plugins/common/cl), then the whole hierarchy in one launch
 * (cl_hploc.cl: a work-item per leaf climbs the radix tree, merging each
 * node's clusters by PLOC rounds), then the merge tree is downloaded and
 * laid out on the host by hploc's own emission (plugins/hploc/hploc_emit.c).
 *
 * Every buffer is sized, against the device's memory, before any is made
 * or any kernel runs. Phases reported: upload, device (the kernels' own
 * times, from their events), download, convert (the emission), as
 * cl_lbvh's and cl_ploc's.
 */
#include <errno.h>
#include <stdlib.h>
#include <string.h>

#include "cl_dev.h"
#include "cl_hploc_src.h"
#include "hploc_tree.h"
#include "morton_front.h"
#include "plugin_options.h"

#define NONE_WORD 0xffffffffu /* meet[]'s "no arrival yet" */

/* The device buffers besides the sort's. */
enum { HB_BOUNDS, HB_CL, HB_REC, HB_IDX, HB_COUNT, HB_MEET, HB_ROOT, HB_BUFS };

typedef struct cl_hploc {
	const bvhlab_build_input *in;
	uint32_t n;
	const char *device;
	unsigned bits;
	uint32_t radius, threshold;
	bool collapse;
	uint32_t max_leaf;
	float c_trav, c_isect;

	cl_dev *dev;
	cl_sort *sort;
	cl_buf *b;              /* [HB_BUFS] */
	hploc_rec *rec;         /* [n] the merge tree, downloaded */
	uint32_t root;
	double ms[CL_PHASES];   /* upload, device, download, convert */
} cl_hploc;

static const plugin_option options[] = {
	HPLOC_OPTIONS(cl_hploc),
	MORTON_OPTIONS(cl_hploc, bits),
	CL_DEVICE_OPTION(cl_hploc),
};
CL_DEVICE_CHECK(cl_hploc)
PLUGIN_DECLS(options, cl_hploc, cl_device_check)

static const char *const kernel_names[] = { CL_SORT_KERNEL_NAMES, "hploc_climb" };
enum { K_CLIMB = CL_SORT_KERNELS };

static const cl_builder program = CL_BUILDER(cl_hploc_src, kernel_names, HPLOC_PRIMS);

/* Kept between builds (one build at a time, ABI rule), with the host's
 * copy of the merge tree; released when the plugin is unloaded. */
static struct {
	CL_KEPT(HB_BUFS);
	hploc_rec *rec;
	uint32_t cap;
} S;

__attribute__((destructor)) static void release_device(void)
{
	CL_KEPT_FREE(S, HB_BUFS);
	free(S.rec);
}

/* ---- the device run ------------------------------------------------------ */

/* The host's copy of the merge tree, kept between builds. */
static int host_tree(cl_hploc *b, char *err, size_t err_size)
{
	if (S.cap < b->n) {
		free(S.rec);
		S.rec = malloc(sizeof(*S.rec) * (size_t)b->n);
		S.cap = S.rec ? b->n : 0;
		if (!S.cap)
			return bvhlab_cl_fail(-ENOMEM, err, err_size,
			                      "out of memory for the merge tree of %u primitives",
			                      b->n);
	}
	b->rec = S.rec;
	return 0;
}

/* Both sets of buffers' sizes against the device's memory, then made;
 * the host's copy of the tree first. */
static int size_buffers(cl_hploc *b, char *err, size_t err_size)
{
	size_t n = b->n, want[HB_BUFS + SB_COUNT];
	int rc = host_tree(b, err, err_size);

	if (rc < 0)
		return rc;

	want[HB_BOUNDS] = 24 * n;
	want[HB_CL] = sizeof(hploc_cluster) * n;
	want[HB_REC] = sizeof(hploc_rec) * n;
	want[HB_IDX] = want[HB_COUNT] = want[HB_MEET] = 4 * n;
	want[HB_ROOT] = 4;
	cl_sort_sizes(b->n, want + HB_BUFS);
	if ((rc = cl_bufs_fit(b->dev, want, HB_BUFS + SB_COUNT, err, err_size)) < 0 ||
	    (rc = cl_bufs_size(b->dev, b->b, want, HB_BUFS, err, err_size)) < 0)
		return rc;
	return cl_bufs_size(b->dev, b->sort->b, want + HB_BUFS, SB_COUNT, err, err_size);
}

static int upload(cl_hploc *b, cl_events *ev, char *err, size_t err_size)
{
	cl_uint none = NONE_WORD;
	double t0 = cl_now_ms();
	int rc = bvhlab_cl_check(clEnqueueWriteBuffer(b->dev->cl.queue, b->b[HB_BOUNDS].mem,
	                                              CL_TRUE, 0, 24 * (size_t)b->n,
	                                              b->in->prim_bounds, 0, NULL, NULL),
	                         "clEnqueueWriteBuffer", err, err_size);

	b->ms[CL_PHASE_UPLOAD] += cl_now_ms() - t0;
	if (rc < 0)
		return rc;
	return bvhlab_cl_check(clEnqueueFillBuffer(b->dev->cl.queue, b->b[HB_MEET].mem, &none,
	                                           sizeof(none), 0, 4 * (size_t)b->n, 0, NULL,
	                                           cl_events_next(ev)),
	                       "clEnqueueFillBuffer", err, err_size);
}

/* The one launch: every leaf's climb. */
static int climb(cl_hploc *b, cl_events *ev, char *err, size_t err_size)
{
	cl_dev *d = b->dev;
	cl_uint n = b->n, r = b->radius, th = b->threshold, collapse = b->collapse;
	cl_uint max_leaf = b->max_leaf;
	cl_mem order = b->sort->b[SB_VALS0 + b->sort->sorted].mem;
	cl_mem keys = b->sort->b[SB_KEYS0 + b->sort->sorted].mem;
	cl_arg a[] = { CL_ARG(b->b[HB_BOUNDS].mem), CL_ARG(order), CL_ARG(keys), CL_ARG(n),
	               CL_ARG(r), CL_ARG(th), CL_ARG(collapse), CL_ARG(max_leaf),
	               CL_ARG(b->c_trav), CL_ARG(b->c_isect), CL_ARG(b->b[HB_CL].mem),
	               CL_ARG(b->b[HB_IDX].mem), CL_ARG(b->b[HB_COUNT].mem),
	               CL_ARG(b->b[HB_MEET].mem), CL_ARG(b->b[HB_REC].mem),
	               CL_ARG(b->b[HB_ROOT].mem) };

	return cl_launch(d, d->k[K_CLIMB], n, a, sizeof(a) / sizeof(a[0]), ev, err, err_size);
}

static int download(cl_hploc *b, char *err, size_t err_size)
{
	cl_command_queue q = b->dev->cl.queue;
	double t0 = cl_now_ms();
	int rc = bvhlab_cl_check(clEnqueueReadBuffer(q, b->b[HB_REC].mem, CL_TRUE, 0,
	                                             sizeof(hploc_rec) * (size_t)b->n, b->rec, 0,
	                                             NULL, NULL),
	                         "clEnqueueReadBuffer", err, err_size);

	if (rc == 0)
		rc = bvhlab_cl_check(clEnqueueReadBuffer(q, b->b[HB_ROOT].mem, CL_TRUE, 0, 4,
		                                         &b->root, 0, NULL, NULL),
		                     "clEnqueueReadBuffer", err, err_size);
	b->ms[CL_PHASE_DOWNLOAD] = cl_now_ms() - t0;
	return rc;
}

static int device_run(cl_hploc *b, char *err, size_t err_size)
{
	cl_events ev = { .count = 0 };
	double up = 0;
	int rc;

	if ((rc = size_buffers(b, err, err_size)) == 0 &&
	    (rc = upload(b, &ev, err, err_size)) == 0 &&
	    (rc = cl_sort_run(b->dev, b->sort, b->in, b->bits, &ev, &up, err, err_size)) == 0 &&
	    (rc = climb(b, &ev, err, err_size)) == 0)
		rc = download(b, err, err_size);
	b->ms[CL_PHASE_UPLOAD] += up;
	clFinish(b->dev->cl.queue);
	b->ms[CL_PHASE_DEVICE] = cl_events_ms(&ev);
	return rc;
}

/* ---- build --------------------------------------------------------------- */

/* The merge tree into the output, timed as the phase convert. */
static void convert(cl_hploc *b, bvhlab_build_output *out)
{
	double t0 = cl_now_ms();
	hploc_tree tree = { b->n, b->rec, b->root, b->in->prim_bounds };

	hploc_emit_top(&tree, out, 0, NULL, &out->node_count); /* all on this thread */
	out->index_count = b->n;
	b->ms[CL_PHASE_CONVERT] = cl_now_ms() - t0;
}

static int run(void *p, bvhlab_build_output *out, char *err, size_t err_size)
{
	cl_hploc *b = p;
	int rc = device_run(b, err, err_size);

	if (rc == 0)
		convert(b, out);
	return rc;
}

CL_PLUGIN(cl_hploc, run, .name = "cl_hploc",
	.summary = "H-PLOC on an OpenCL device (Benthin et al. 2024): the hploc plugin's tree, "
	           "the hierarchy in one kernel launch")
