/*
 * cl_lbvh's compaction of a collapsed tree, on the device
 * (cl_lbvh_compact.cl: lbvh_collapse.c's moves, so the same node order):
 * the internal nodes in chunks, a work-item each, their counts, the plan
 * (one work-item), the movers numbered, the links, the moves; F, the
 * count of internal nodes that stay inner, is read back with the tree.
 */
#include "cl_lbvh.h"

/* Chunks of the internal nodes: at most CL_LBVH_CHUNKS, each at least
 * MIN_CHUNK nodes (a few hundred keep every core busy, as the sort's). */
#define MIN_CHUNK 256u

int cl_lbvh_compact(cl_lbvh *b, cl_events *ev, char *err, size_t err_size)
{
	cl_dev *d = b->dev;
	cl_uint m = b->n - 1, chunk, chunks = cl_chunks(m, CL_LBVH_CHUNKS, MIN_CHUNK, &chunk);
	cl_mem inner = b->b[LB_INNER].mem, plan = b->b[LB_PLAN].mem;
	/* visits[] is done with once bounds has run: the movers' numbers */
	cl_mem movers = b->b[LB_VISITS].mem, parent = b->b[LB_PARENT].mem;
	cl_mem nodes = b->host[LB_NODES] ? b->host[LB_NODES] : b->b[LB_NODES].mem;
	cl_arg c[] = { CL_ARG(inner), CL_ARG(m), CL_ARG(chunk), CL_ARG(chunks), CL_ARG(plan),
	               CL_ARG(movers), CL_ARG(parent), CL_ARG(nodes) };
	int rc;

	b->plan_f = 4 * 3 * (size_t)chunks;
	if ((rc = cl_launch(d, d->k[K_COUNTS], chunks, c, 5, ev, err, err_size)) < 0 ||
	    (rc = cl_launch(d, d->k[K_PLAN], 1, c, 5, ev, err, err_size)) < 0 ||
	    (rc = cl_launch(d, d->k[K_MOVERS], chunks, c, 6, ev, err, err_size)) < 0 ||
	    (rc = cl_launch(d, d->k[K_LINKS], chunks, c, 8, ev, err, err_size)) < 0)
		return rc;
	return cl_launch(d, d->k[K_MOVES], chunks, c, 8, ev, err, err_size);
}
