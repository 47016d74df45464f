/*
 * Morton codes and their radix sort on the device (kernels in
 * morton_sort.cl), giving the order plugins/common/morton gives: its
 * cells (morton_cells_init) and its spread (morton_spread.h), then stable
 * passes over the 8-bit digits in which some code differs from the first
 * (the rest would move nothing): every one over all keys (a GPU), or, on
 * a CPU device, the two top ones over all keys and the rest inside each
 * bucket of those 16 bits, a work-item each, in cache (cl_sort.shape).
 */
#include <errno.h>
#include <stdbool.h>

#include "cl_dev.h"
#include "morton.h"

enum { K_CODES, K_VARYING, K_HIST, K_SCAN, K_SCATTER, K_RANGES, K_BUCKETS };

/* morton_sort.cl's BUCKETS: the buckets of the two top varying digits.
 * Fewer primitives than that take the passes (a small sort, and the
 * buckets' ranges, 512 KiB, would be most of its memory). */
#define BUCKETS 65536u

/* Chunks of the sort: one work-item each; a few hundred keep the scan's
 * counts small (256 per chunk) and every core busy. */
#define MIN_CHUNK 256u
#define CHUNKS 512u

void cl_sort_sizes(uint32_t n, size_t want[SB_COUNT])
{
	uint32_t chunk, chunks = cl_chunks(n, CHUNKS, MIN_CHUNK, &chunk);

	want[SB_CENTROIDS] = 12 * (size_t)n;
	want[SB_KEYS0] = want[SB_KEYS1] = 8 * (size_t)n;
	want[SB_VALS0] = want[SB_VALS1] = 4 * (size_t)n;
	want[SB_HIST] = 256 * 4 * (size_t)chunks;
	want[SB_PART] = 8 * (size_t)chunks;
	want[SB_RANGE] = n >= BUCKETS ? 2 * 4 * (size_t)BUCKETS : 0;
}

static int codes(cl_dev *d, cl_sort *s, const bvhlab_build_input *in, unsigned bits,
                 cl_events *ev, char *err, size_t err_size)
{
	morton_cells q;
	uint32_t n = in->prim_count;

	morton_cells_init(&q, &in->centroid_bounds, bits);
	cl_mem centroids = s->centroids ? s->centroids : s->b[SB_CENTROIDS].mem;
	cl_arg args[] = {
		CL_ARG(centroids), CL_ARG(n), CL_ARG(q.lo[0]), CL_ARG(q.lo[1]),
		CL_ARG(q.lo[2]), CL_ARG(q.scale[0]), CL_ARG(q.scale[1]), CL_ARG(q.scale[2]),
		CL_ARG(q.top), CL_ARG(s->b[SB_KEYS0].mem), CL_ARG(s->b[SB_VALS0].mem),
	};
	return cl_launch(d, d->k[K_CODES], n, args, 11, ev, err, err_size);
}

/* The bits in which some code differs from the first one's. */
static int varying(cl_dev *d, cl_sort *s, uint32_t n, uint64_t *bits, cl_events *ev,
                   char *err, size_t err_size)
{
	uint32_t chunk, chunks = cl_chunks(n, CHUNKS, MIN_CHUNK, &chunk);
	uint64_t part[CHUNKS + 1];
	cl_arg args[] = {
		CL_ARG(s->b[SB_KEYS0].mem), CL_ARG(n), CL_ARG(chunk), CL_ARG(s->b[SB_PART].mem),
	};
	int rc = cl_launch(d, d->k[K_VARYING], chunks, args, 4, ev, err, err_size);

	if (rc < 0)
		return rc;
	rc = bvhlab_cl_check(clEnqueueReadBuffer(d->cl.queue, s->b[SB_PART].mem, CL_TRUE, 0,
	                                         8 * (size_t)chunks, part, 0, NULL,
	                                         cl_events_next(ev)),
	                     "reading the varying bits", err, err_size);
	*bits = 0;
	for (uint32_t c = 0; c < chunks; c++)
		*bits |= part[c];
	return rc;
}

/* One stable pass on the digit at `shift`, from buffers `from` to 1 - from. */
static int pass(cl_dev *d, cl_sort *s, uint32_t n, uint32_t shift, unsigned from,
                cl_events *ev, char *err, size_t err_size)
{
	uint32_t chunk, chunks = cl_chunks(n, CHUNKS, MIN_CHUNK, &chunk), total = 256 * chunks;
	cl_mem kin = s->b[SB_KEYS0 + from].mem, kout = s->b[SB_KEYS0 + 1 - from].mem;
	cl_mem vin = s->b[SB_VALS0 + from].mem, vout = s->b[SB_VALS0 + 1 - from].mem;
	cl_mem hist = s->b[SB_HIST].mem;
	cl_arg h[] = { CL_ARG(kin), CL_ARG(n), CL_ARG(chunk), CL_ARG(chunks), CL_ARG(shift),
	               CL_ARG(hist) };
	cl_arg sc[] = { CL_ARG(hist), CL_ARG(total) };
	cl_arg x[] = { CL_ARG(kin), CL_ARG(vin), CL_ARG(kout), CL_ARG(vout), CL_ARG(n),
	               CL_ARG(chunk), CL_ARG(chunks), CL_ARG(shift), CL_ARG(hist) };
	int rc;

	if ((rc = cl_launch(d, d->k[K_HIST], chunks, h, 6, ev, err, err_size)) < 0 ||
	    (rc = cl_launch(d, d->k[K_SCAN], 1, sc, 2, ev, err, err_size)) < 0)
		return rc;
	return cl_launch(d, d->k[K_SCATTER], chunks, x, 9, ev, err, err_size);
}

/* With the keys sorted on the digits at s1 and s2 (in buffers `from`),
 * each bucket of those 16 bits sorted on the lower varying digits
 * (`digits`, a bit per digit), a work-item each. */
static int buckets(cl_dev *d, cl_sort *s, uint32_t n, uint32_t s1, uint32_t s2,
                   uint32_t digits, unsigned from, cl_events *ev, char *err, size_t err_size)
{
	cl_mem range = s->b[SB_RANGE].mem;
	cl_uint zero = 0;
	cl_arg r[] = { CL_ARG(s->b[SB_KEYS0 + from].mem), CL_ARG(n), CL_ARG(s1), CL_ARG(s2),
	               CL_ARG(range) };
	cl_arg a[] = { CL_ARG(s->b[SB_KEYS0 + from].mem), CL_ARG(s->b[SB_VALS0 + from].mem),
	               CL_ARG(s->b[SB_KEYS0 + 1 - from].mem),
	               CL_ARG(s->b[SB_VALS0 + 1 - from].mem), CL_ARG(range), CL_ARG(digits) };
	int rc = bvhlab_cl_check(clEnqueueFillBuffer(d->cl.queue, range, &zero, sizeof(zero), 0,
	                                             2 * 4 * (size_t)BUCKETS, 0, NULL,
	                                             cl_events_next(ev)),
	                         "clEnqueueFillBuffer", err, err_size);

	if (rc < 0 || (rc = cl_launch(d, d->k[K_RANGES], n, r, 5, ev, err, err_size)) < 0)
		return rc;
	return cl_launch(d, d->k[K_BUCKETS], BUCKETS, a, 6, ev, err, err_size);
}

/* The passes: on every varying digit over all keys, or on the two top
 * ones, then inside their buckets. */
static int passes(cl_dev *d, cl_sort *s, uint32_t n, uint64_t vary, cl_events *ev, char *err,
                  size_t err_size)
{
	uint32_t digits = 0, top[2] = { 0, 0 }, tops = 0;
	bool by_buckets = n >= BUCKETS && (s->shape == CL_SORT_BUCKETS ||
	                                   (s->shape == CL_SORT_AUTO &&
	                                    (d->cl.type & CL_DEVICE_TYPE_CPU)));
	int rc;

	for (uint32_t k = 8; k-- > 0;)
		if ((vary >> (8 * k)) & 0xff) {
			digits |= 1u << k;
			if (tops < 2)
				top[tops++] = k;
		}
	/* With buckets, the top two passes first (the second digit, then
	 * the first: LSD order), then the rest inside the buckets. */
	uint32_t over_all = by_buckets && tops == 2 ? 1u << top[0] | 1u << top[1] : digits;
	for (uint32_t k = 0; k < 8; k++) {
		if (!((over_all >> k) & 1))
			continue;
		if ((rc = pass(d, s, n, 8 * k, s->sorted, ev, err, err_size)) < 0)
			return rc;
		s->sorted = 1 - s->sorted;
	}
	if (!(digits & ~over_all))
		return 0;
	rc = buckets(d, s, n, 8 * top[0], 8 * top[1], digits & ~over_all, s->sorted, ev, err,
	             err_size);
	s->sorted ^= (unsigned)__builtin_popcount(digits & ~over_all) & 1;
	return rc;
}

int cl_sort_run(cl_dev *d, cl_sort *s, const bvhlab_build_input *in, unsigned bits,
                cl_events *ev, double *ms_upload, char *err, size_t err_size)
{
	uint32_t n = in->prim_count;
	uint64_t vary = 0;
	double t0 = cl_now_ms();
	int rc = s->centroids ? 0 :
	         bvhlab_cl_check(clEnqueueWriteBuffer(d->cl.queue, s->b[SB_CENTROIDS].mem,
	                                              CL_TRUE, 0, 12 * (size_t)n, in->centroids,
	                                              0, NULL, NULL),
	                         "uploading the centroids", err, err_size);

	*ms_upload = cl_now_ms() - t0;
	s->sorted = 0;
	if (rc < 0 || (rc = codes(d, s, in, bits, ev, err, err_size)) < 0 ||
	    (rc = varying(d, s, n, &vary, ev, err, err_size)) < 0)
		return rc;
	return passes(d, s, n, vary, ev, err, err_size);
}
