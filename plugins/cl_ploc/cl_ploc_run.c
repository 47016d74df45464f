/*
 * cl_ploc's device run: every buffer sized first, the uploads, the sort
 * (plugins/common/cl), the first clusters, then the iterations until one
 * cluster is left: nearest, count_chunks, prefix and write_chunks per
 * iteration, the host reading back only the number of clusters left (it
 * sizes the next launches). Then the merge tree is downloaded, the root's
 * record taken from the last cluster.
 */
#include <errno.h>
#include <string.h>

#include "cl_ploc.h"

enum { K_FIRST = CL_SORT_KERNELS, K_NEAREST, K_COUNT, K_PREFIX, K_WRITE, K_NEAREST_BLOCKS };

/* Clusters per work-item of the nearest-neighbour search on a CPU device
 * (nearest_blocks: each distance once, read in order). */
#define CPU_NN_BLOCK 256u

/* Chunks of the count and write kernels: one work-item each, in order. */
#define MIN_CHUNK 64u
#define CHUNKS 512u

static int size_buffers(cl_ploc *b, char *err, size_t err_size)
{
	size_t n = b->n, want[PB_COUNT + SB_COUNT];

	want[PB_BOUNDS] = 24 * n;
	want[PB_CL0] = want[PB_CL1] = CLUSTER_BYTES * n;
	want[PB_NN] = 4 * n;
	want[PB_COUNTS] = 8 * (size_t)CHUNKS + 8;
	want[PB_STATE] = 16;
	want[PB_TREE] = 32 * (2 * n - 1);
	want[PB_DESC] = 4 * (2 * n - 1);
	cl_sort_sizes(b->n, want + PB_COUNT);
	/* Both sets at once against the device's memory, then each made. */
	int rc = cl_bufs_fit(b->dev, want, PB_COUNT + SB_COUNT, err, err_size);

	if (rc == 0)
		rc = cl_bufs_size(b->dev, b->b, want, PB_COUNT, err, err_size);
	return rc < 0 ? rc : cl_bufs_size(b->dev, b->sort->b, want + PB_COUNT, SB_COUNT, err,
	                                  err_size);
}

static int write_buf(cl_ploc *b, int which, size_t bytes, const void *from, char *err,
                     size_t err_size)
{
	return bvhlab_cl_check(clEnqueueWriteBuffer(b->dev->cl.queue, b->b[which].mem, CL_TRUE,
	                                            0, bytes, from, 0, NULL, NULL),
	                       "clEnqueueWriteBuffer", err, err_size);
}

static int read_buf(cl_ploc *b, int which, size_t offset, size_t bytes, void *to, char *err,
                    size_t err_size)
{
	return bvhlab_cl_check(clEnqueueReadBuffer(b->dev->cl.queue, b->b[which].mem, CL_TRUE,
	                                           offset, bytes, to, 0, NULL, NULL),
	                       "clEnqueueReadBuffer", err, err_size);
}

/* Every cluster's nearest neighbour: one work-item each (nearest), or by
 * blocks (nearest_blocks; the same result). bound: at least the count. */
static int nearest(cl_ploc *b, cl_mem c, cl_uint bound, cl_uint cur, cl_events *ev,
                   char *err, size_t err_size)
{
	cl_dev *d = b->dev;
	cl_uint r = b->radius;
	cl_uint block = b->nn_block ? b->nn_block
	                            : d->cl.type & CL_DEVICE_TYPE_CPU ? CPU_NN_BLOCK : 1;
	cl_mem state = b->b[PB_STATE].mem;
	cl_arg na[] = { CL_ARG(c), CL_ARG(state), CL_ARG(cur), CL_ARG(r), CL_ARG(b->b[PB_NN].mem) };
	cl_arg ba[] = { CL_ARG(c), CL_ARG(state), CL_ARG(cur), CL_ARG(r), CL_ARG(block),
	                CL_ARG(b->b[PB_NN].mem) };

	if (block == 1)
		return cl_launch(d, d->k[K_NEAREST], bound, na, 5, ev, err, err_size);
	return cl_launch(d, d->k[K_NEAREST_BLOCKS], (bound + block - 1) / block, ba, 6, ev, err,
	                 err_size);
}

/* One iteration of parity cur (clusters in buffer PB_CL0 + cur), queued
 * for at most `bound` clusters. */
static int iteration(cl_ploc *b, cl_uint bound, cl_uint cur, cl_events *ev, char *err,
                     size_t err_size)
{
	cl_dev *d = b->dev;
	cl_uint chunk, chunks = cl_chunks(bound, CHUNKS, MIN_CHUNK, &chunk);
	cl_uint collapse = b->collapse, max_leaf = b->max_leaf;
	cl_mem c = b->b[PB_CL0 + cur].mem, to = b->b[PB_CL1 - cur].mem;
	cl_mem state = b->b[PB_STATE].mem, counts = b->b[PB_COUNTS].mem, nn = b->b[PB_NN].mem;
	cl_arg ca[] = { CL_ARG(nn), CL_ARG(state), CL_ARG(cur), CL_ARG(chunk), CL_ARG(chunks),
	                CL_ARG(counts) };
	cl_arg pa[] = { CL_ARG(counts), CL_ARG(chunks), CL_ARG(state), CL_ARG(cur) };
	cl_arg wa[] = { CL_ARG(c), CL_ARG(nn), CL_ARG(state), CL_ARG(cur), CL_ARG(chunk),
	                CL_ARG(chunks), CL_ARG(counts), CL_ARG(to), CL_ARG(b->b[PB_TREE].mem),
	                CL_ARG(b->b[PB_DESC].mem), CL_ARG(collapse), CL_ARG(max_leaf),
	                CL_ARG(b->c_trav), CL_ARG(b->c_isect) };
	int rc;

	if ((rc = nearest(b, c, bound, cur, ev, err, err_size)) < 0 ||
	    (rc = cl_launch(d, d->k[K_COUNT], chunks, ca, 6, ev, err, err_size)) < 0 ||
	    (rc = cl_launch(d, d->k[K_PREFIX], 1, pa, 4, ev, err, err_size)) < 0)
		return rc;
	return cl_launch(d, d->k[K_WRITE], chunks, wa, 14, ev, err, err_size);
}

static int first_clusters(cl_ploc *b, cl_events *ev, char *err, size_t err_size)
{
	cl_uint n = b->n, state[4] = { b->n, 0, 2 * b->n - 1, 0 };
	cl_mem order = b->sort->b[SB_VALS0 + b->sort->sorted].mem;
	cl_arg fa[] = { CL_ARG(b->b[PB_BOUNDS].mem), CL_ARG(order), CL_ARG(n),
	                CL_ARG(b->c_isect), CL_ARG(b->b[PB_CL0].mem) };
	int rc = write_buf(b, PB_STATE, sizeof(state), state, err, err_size);

	return rc < 0 ? rc : cl_launch(b->dev, b->dev->k[K_FIRST], n, fa, 5, ev, err, err_size);
}

static int upload(cl_ploc *b, char *err, size_t err_size)
{
	double t0 = cl_now_ms();
	int rc = write_buf(b, PB_BOUNDS, 24 * (size_t)b->n, b->in->prim_bounds, err, err_size);

	b->ms[0] += cl_now_ms() - t0;
	return rc;
}

/* The merge tree, and the root's record from the last cluster (at `last`). */
static int download(cl_ploc *b, int last, char *err, size_t err_size)
{
	size_t records = 2 * (size_t)b->n - 1;
	uint32_t root[10]; /* a cluster: lo, first, hi, info, cost, desc */
	int rc;

	if ((rc = read_buf(b, PB_TREE, 0, 32 * records, b->tree, err, err_size)) < 0 ||
	    (rc = read_buf(b, PB_DESC, 0, 4 * records, b->desc, err, err_size)) < 0 ||
	    (rc = read_buf(b, last, 0, CLUSTER_BYTES, root, err, err_size)) < 0)
		return rc;
	memcpy(&b->tree[0], root, 32);
	b->desc[0] = root[9];
	return 0;
}

/* Iterations queued between reads of the count: one while there are many
 * clusters (an iteration's work hides the read), then a batch (the last
 * few dozen iterations are short, and a read per iteration would cost
 * more than they do). */
#define BATCH_BELOW 65536u
#define BATCH 8u

/* The iterations until one cluster is left; *cur gets its parity. */
static int iterations(cl_ploc *b, cl_uint *cur, cl_events *ev, char *err, size_t err_size)
{
	uint32_t bound = b->n;
	int rc;

	for (*cur = 0, b->iterations = 0; bound > 1;) {
		uint32_t before = bound, batch = bound > BATCH_BELOW ? 1 : BATCH;
		for (uint32_t k = 0; k < batch; k++, b->iterations++, *cur ^= 1)
			if ((rc = iteration(b, bound, *cur, ev, err, err_size)) < 0)
				return rc;
		if ((rc = read_buf(b, PB_STATE, 4 * *cur, 4, &bound, err, err_size)) < 0)
			return rc;
		/* Every iteration merges its least pair; anything else is a bug,
		 * not a reason to loop for ever. */
		if (bound >= before || bound == 0)
			return bvhlab_cl_fail(-EIO, err, err_size, "cl_ploc: %u iterations left %u "
			                      "of %u clusters", batch, bound, before);
	}
	return 0;
}

int cl_ploc_run(cl_ploc *b, char *err, size_t err_size)
{
	cl_events ev = { .count = 0 };
	cl_uint cur = 0;
	int rc;
	double up = 0, t0;

	if ((rc = size_buffers(b, err, err_size)) < 0 || (rc = upload(b, err, err_size)) < 0 ||
	    (rc = cl_sort_run(b->dev, b->sort, b->in, b->bits, &ev, &up, err, err_size)) < 0 ||
	    (rc = first_clusters(b, &ev, err, err_size)) < 0)
		goto out;
	b->ms[0] += up;
	if ((rc = iterations(b, &cur, &ev, err, err_size)) < 0)
		goto out;
	t0 = cl_now_ms();
	rc = download(b, PB_CL0 + (int)cur, err, err_size);
	b->ms[2] = cl_now_ms() - t0;
out:
	clFinish(b->dev->cl.queue);
	b->ms[1] = cl_events_ms(&ev);
	return rc;
}
