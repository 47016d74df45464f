/*
 * cl_lbvh's device run: every buffer sized first, the uploads, the sort
 * (plugins/common/cl), then karras, bounds, inner_nodes and the
 * compaction (cl_lbvh_compact.c); the kernels
 * queue back to back on the in-order queue and the host waits once. On a
 * CPU device (PoCL) the device's memory is the host's: the input's boxes
 * and centroids and the output's nodes and indices are used where they
 * lie (CL_MEM_USE_HOST_PTR), and the copies in and out, some 100 bytes a
 * primitive, go.
 */
#include <string.h>

#include "cl_lbvh.h"

/* Zero bytes on either side of lcp[] (cl_lbvh.cl's LCP_PAD). */
#define LCP_PAD 32

/* Leaves per work-item of the bounds kernel on a CPU device: a few
 * thousand work-items on a million leaves, each climb mostly in cache and
 * without atomics; on a GPU, one leaf each. */
#define CPU_LEAF_BLOCK 512u

/* The buffer `which` of this build. */
static cl_mem mem(const cl_lbvh *b, int which)
{
	return b->host[which] ? b->host[which] : b->b[which].mem;
}

static int size_buffers(cl_lbvh *b, char *err, size_t err_size)
{
	size_t n = b->n, want[LB_COUNT + SB_COUNT];

	want[LB_BOUNDS] = 24 * n;
	want[LB_PARENT] = 4 * (2 * n - 1);
	want[LB_END] = want[LB_VISITS] = want[LB_COST] = 4 * (n - 1);
	want[LB_NODES] = 32 * (2 * n - 1);
	want[LB_FLAGS] = want[LB_INNER] = n - 1;
	want[LB_LCP] = n - 1 + 2 * LCP_PAD;
	want[LB_INDEX] = 4 * n;
	want[LB_PLAN] = 4 * (3 * (size_t)CL_LBVH_CHUNKS + 1);
	cl_sort_sizes(b->n, want + LB_COUNT);
	/* Both sets at once against the device's memory, then each made. */
	int rc = cl_bufs_fit(b->dev, want, LB_COUNT + SB_COUNT, err, err_size);

	/* Counted above all the same: the host's arrays are the device's
	 * memory too. */
	for (int k = 0; k < LB_COUNT; k++)
		want[k] = b->host[k] ? 0 : want[k];
	want[LB_COUNT + SB_CENTROIDS] = b->centroids ? 0 : want[LB_COUNT + SB_CENTROIDS];
	if (rc == 0)
		rc = cl_bufs_size(b->dev, b->b, want, LB_COUNT, err, err_size);
	return rc < 0 ? rc : cl_bufs_size(b->dev, b->sort->b, want + LB_COUNT, SB_COUNT, err,
	                                  err_size);
}

static int zero(cl_lbvh *b, int which, size_t bytes, cl_events *ev, char *err,
                size_t err_size)
{
	cl_uchar z = 0;

	return bvhlab_cl_check(clEnqueueFillBuffer(b->dev->cl.queue, b->b[which].mem, &z, 1, 0,
	                                           bytes, 0, NULL, cl_events_next(ev)),
	                       "clEnqueueFillBuffer", err, err_size);
}

/* Every internal node's range and split: by Karras's searches, or by
 * lbvh's scans of the prefix lengths (prefixes, then karras_scan). */
static int karras(cl_lbvh *b, cl_mem keys, cl_events *ev, char *err, size_t err_size)
{
	cl_dev *d = b->dev;
	cl_uint n = b->n, items = n - 1 > LCP_PAD ? n - 1 : LCP_PAD;
	bool scan = !strcmp(b->hierarchy, "scan") ||
	            (!strcmp(b->hierarchy, "auto") && (d->cl.type & CL_DEVICE_TYPE_CPU));
	cl_mem lcp = b->b[LB_LCP].mem, parent = b->b[LB_PARENT].mem, end = b->b[LB_END].mem;
	cl_arg ka[] = { CL_ARG(keys), CL_ARG(n), CL_ARG(parent), CL_ARG(end) };
	cl_arg pa[] = { CL_ARG(keys), CL_ARG(n), CL_ARG(lcp) };
	cl_arg sa[] = { CL_ARG(keys), CL_ARG(n), CL_ARG(lcp), CL_ARG(parent), CL_ARG(end) };
	int rc;

	if (!scan)
		return cl_launch(d, d->k[K_KARRAS], n - 1, ka, 4, ev, err, err_size);
	if ((rc = cl_launch(d, d->k[K_PREFIXES], items, pa, 3, ev, err, err_size)) < 0)
		return rc;
	return cl_launch(d, d->k[K_SCAN], n - 1, sa, 5, ev, err, err_size);
}

static int hierarchy(cl_lbvh *b, cl_events *ev, char *err, size_t err_size)
{
	cl_dev *d = b->dev;
	cl_mem keys = b->sort->b[SB_KEYS0 + b->sort->sorted].mem;
	cl_mem order = b->sort->b[SB_VALS0 + b->sort->sorted].mem;
	cl_mem boxes = mem(b, LB_BOUNDS), index = mem(b, LB_INDEX), nodes = mem(b, LB_NODES);
	cl_uint collapse = b->collapse, n = b->n, max_leaf = b->max_leaf;
	cl_uint block = b->leaf_block ? b->leaf_block
	                              : d->cl.type & CL_DEVICE_TYPE_CPU ? CPU_LEAF_BLOCK : 1;
	cl_arg ba[] = { CL_ARG(boxes), CL_ARG(order), CL_ARG(index), CL_ARG(n), CL_ARG(block),
	                CL_ARG(b->b[LB_PARENT].mem), CL_ARG(b->b[LB_END].mem), CL_ARG(nodes),
	                CL_ARG(b->b[LB_VISITS].mem), CL_ARG(b->b[LB_COST].mem),
	                CL_ARG(b->b[LB_FLAGS].mem), CL_ARG(collapse), CL_ARG(max_leaf),
	                CL_ARG(b->c_trav), CL_ARG(b->c_isect) };
	cl_arg ia[] = { CL_ARG(b->b[LB_PARENT].mem), CL_ARG(b->b[LB_END].mem),
	                CL_ARG(b->b[LB_FLAGS].mem), CL_ARG(n), CL_ARG(max_leaf),
	                CL_ARG(b->b[LB_INNER].mem) };
	int rc;

	if ((rc = karras(b, keys, ev, err, err_size)) < 0 ||
	    (rc = zero(b, LB_VISITS, 4 * (size_t)(n - 1), ev, err, err_size)) < 0 ||
	    (rc = zero(b, LB_FLAGS, n - 1, ev, err, err_size)) < 0 ||
	    (rc = cl_launch(d, d->k[K_BOUNDS], (n + block - 1) / block, ba, 15, ev, err,
	                    err_size)) < 0)
		return rc;
	if (!b->collapse)
		return 0;
	if ((rc = cl_launch(d, d->k[K_INNER], n - 1, ia, 6, ev, err, err_size)) < 0)
		return rc;
	return cl_lbvh_compact(b, ev, err, err_size);
}

/* A buffer over the host's array p (CL_MEM_USE_HOST_PTR). */
static int wrap(cl_lbvh *b, cl_mem *to, cl_mem_flags flags, const void *p, size_t bytes,
                char *err, size_t err_size)
{
	cl_int rc = CL_SUCCESS;

	/* The runtime only reads the input's arrays (CL_MEM_READ_ONLY). */
	*to = clCreateBuffer(b->dev->cl.context, flags | CL_MEM_USE_HOST_PTR, bytes, (void *)p,
	                     &rc);
	if (rc != CL_SUCCESS)
		*to = NULL;
	return bvhlab_cl_check(rc, "clCreateBuffer over the host's memory", err, err_size);
}

static int host_buffers(cl_lbvh *b, bvhlab_build_output *out, char *err, size_t err_size)
{
	size_t n = b->n;
	int rc;

	if (!b->zero_copy || !(b->dev->cl.type & CL_DEVICE_TYPE_CPU))
		return 0;
	if ((rc = wrap(b, &b->host[LB_BOUNDS], CL_MEM_READ_ONLY, b->in->prim_bounds, 24 * n, err,
	               err_size)) < 0 ||
	    (rc = wrap(b, &b->centroids, CL_MEM_READ_ONLY, b->in->centroids, 12 * n, err,
	               err_size)) < 0 ||
	    (rc = wrap(b, &b->host[LB_NODES], CL_MEM_READ_WRITE, out->nodes, 32 * (2 * n - 1),
	               err, err_size)) < 0 ||
	    (rc = wrap(b, &b->host[LB_INDEX], CL_MEM_WRITE_ONLY, out->prim_index, 4 * n, err,
	               err_size)) < 0)
		return rc;
	b->sort->centroids = b->centroids;
	return 0;
}

static void host_release(cl_lbvh *b)
{
	for (int k = 0; k < LB_COUNT; k++)
		bvhlab_cl_release_mem(&b->host[k]);
	bvhlab_cl_release_mem(&b->centroids);
	b->sort->centroids = NULL;
}

/* Buffer `which`'s first `bytes` into `to`: read from the device, or, for
 * a buffer over `to` itself, mapped (no copy where the runtime uses the
 * host's array, as PoCL does) and unmapped. */
static int fetch(cl_lbvh *b, int which, size_t bytes, void *to, char *err, size_t err_size)
{
	cl_command_queue q = b->dev->cl.queue;
	cl_int rc = CL_SUCCESS;
	void *p;

	if (!b->host[which])
		return bvhlab_cl_check(clEnqueueReadBuffer(q, b->b[which].mem, CL_TRUE, 0, bytes,
		                                           to, 0, NULL, NULL),
		                       "clEnqueueReadBuffer", err, err_size);
	p = clEnqueueMapBuffer(q, b->host[which], CL_TRUE, CL_MAP_READ, 0, bytes, 0, NULL, NULL,
	                       &rc);
	if (rc != CL_SUCCESS)
		return bvhlab_cl_check(rc, "clEnqueueMapBuffer", err, err_size);
	if (p != to)
		memcpy(to, p, bytes);
	return bvhlab_cl_check(clEnqueueUnmapMemObject(q, b->host[which], p, 0, NULL, NULL),
	                       "clEnqueueUnmapMemObject", err, err_size);
}

/* The tree into out, and its node count. */
static int download(cl_lbvh *b, bvhlab_build_output *out, char *err, size_t err_size)
{
	size_t n = b->n;
	cl_uint f = 0;
	int rc;

	if ((rc = fetch(b, LB_NODES, 32 * (2 * n - 1), out->nodes, err, err_size)) == 0 &&
	    (rc = fetch(b, LB_INDEX, 4 * n, out->prim_index, err, err_size)) == 0 && b->collapse)
		rc = bvhlab_cl_check(clEnqueueReadBuffer(b->dev->cl.queue, b->b[LB_PLAN].mem,
		                                         CL_TRUE, b->plan_f, sizeof(f), &f, 0,
		                                         NULL, NULL),
		                     "clEnqueueReadBuffer", err, err_size);
	out->node_count = b->collapse ? 1 + 2 * f : 2 * b->n - 1;
	out->index_count = b->n;
	/* The host may write the nodes next: the buffers over them go first. */
	if (rc == 0)
		rc = bvhlab_cl_check(clFinish(b->dev->cl.queue), "clFinish", err, err_size);
	host_release(b);
	return rc;
}

static int upload(cl_lbvh *b, char *err, size_t err_size)
{
	double t0 = cl_now_ms();
	int rc = b->host[LB_BOUNDS] ? 0 :
	         bvhlab_cl_check(clEnqueueWriteBuffer(b->dev->cl.queue, b->b[LB_BOUNDS].mem,
	                                              CL_TRUE, 0, 24 * (size_t)b->n,
	                                              b->in->prim_bounds, 0, NULL, NULL),
	                         "uploading the primitive boxes", err, err_size);

	b->ms[0] += cl_now_ms() - t0;
	return rc;
}

int cl_lbvh_run(cl_lbvh *b, bvhlab_build_output *out, char *err, size_t err_size)
{
	cl_events ev = { .count = 0 };
	double t0, up = 0;
	int rc;

	if ((rc = host_buffers(b, out, err, err_size)) < 0 ||
	    (rc = size_buffers(b, err, err_size)) < 0 || (rc = upload(b, err, err_size)) < 0 ||
	    (rc = cl_sort_run(b->dev, b->sort, b->in, b->bits, &ev, &up, err, err_size)) < 0 ||
	    (rc = hierarchy(b, &ev, err, err_size)) < 0 ||
	    (rc = bvhlab_cl_check(clFinish(b->dev->cl.queue), "clFinish", err, err_size)) < 0)
		goto out;
	b->ms[0] += up;
	t0 = cl_now_ms();
	rc = download(b, out, err, err_size);
	b->ms[2] = cl_now_ms() - t0;
	b->ms[3] = 0;
out:
	clFinish(b->dev->cl.queue);
	host_release(b);
	b->ms[1] = cl_events_ms(&ev);
	return rc;
}
