/*
 * cl_lbvh's compaction of the collapsed tree on the device (after
 * cl_lbvh.cl): lbvh_collapse.c's moves, so the same node order. With F
 * internal nodes staying inner (inner[]), the pairs of those below F stay;
 * the pairs below F of nodes that did not stay inner are holes, as many as
 * the inner nodes from F on (the movers), and the k-th mover's pair moves
 * into the k-th hole. Every mover's parent slot is pointed at the new
 * place first (compact_links: that slot may lie in a pair that moves),
 * then the pairs move (compact_moves), a kernel later.
 *
 * The internal nodes [0, m) in chunks of `chunk`, a work-item each:
 * compact_counts counts each chunk's inner nodes, compact_plan (one
 * work-item) F and each chunk's first hole and mover numbers, then every
 * chunk numbers its own movers and holes in order. plan[]: counts at 0,
 * first holes at chunks, first movers at 2 * chunks, F at 3 * chunks.
 */
__kernel void compact_counts(__global const uchar *inner, uint m, uint chunk, uint chunks,
	__global uint *plan)
{
	uint c = get_global_id(0), count = 0;
	if (c >= chunks)
		return;
	size_t lo = (size_t)c * chunk, hi = min((size_t)m, lo + chunk);
	for (size_t i = lo; i < hi; i++)
		count += inner[i];
	plan[c] = count;
}

__kernel void compact_plan(__global const uchar *inner, uint m, uint chunk, uint chunks,
	__global uint *plan)
{
	uint f = 0, holes = 0, movers = 0;
	if (get_global_id(0) != 0)
		return;
	for (uint c = 0; c < chunks; c++)
		f += plan[c];
	for (uint c = 0; c < chunks; c++) {
		uint lo = c * chunk, hi = min(m, lo + chunk), below = 0;
		/* inner nodes of the chunk below F: all of them, none, or
		 * counted in the one chunk F falls inside */
		if (hi <= f)
			below = plan[c];
		else
			for (uint i = lo; i < f; i++)
				below += inner[i];
		plan[chunks + c] = holes;
		plan[2 * chunks + c] = movers;
		holes += (min(hi, f) > lo ? min(hi, f) - lo : 0) - below;
		movers += plan[c] - below;
	}
	plan[3 * chunks] = f;
}

/* The chunk's movers, numbered: mover_at[k] is the k-th. */
__kernel void compact_movers(__global const uchar *inner, uint m, uint chunk, uint chunks,
	__global const uint *plan, __global uint *mover_at)
{
	uint c = get_global_id(0);
	if (c >= chunks)
		return;
	uint f = plan[3 * chunks], k = plan[2 * chunks + c];
	size_t lo = max((size_t)c * chunk, (size_t)f), hi = min((size_t)m, (size_t)c * chunk + chunk);
	for (size_t i = lo; i < hi; i++)
		if (inner[i])
			mover_at[k++] = (uint)i;
}

/* Each hole of the chunk with its mover: the mover's parent slot pointed
 * at the hole (links) or the mover's pair moved into it. */
static void holes(__global const uchar *inner, uint m, uint chunk, uint chunks,
	__global const uint *plan, __global const uint *mover_at, __global const uint *parent,
	__global node *nodes, bool move)
{
	uint c = get_global_id(0);
	if (c >= chunks)
		return;
	uint f = plan[3 * chunks], k = plan[chunks + c];
	size_t lo = (size_t)c * chunk, hi = min((size_t)f, lo + chunk);
	for (size_t h = lo; h < hi; h++) {
		if (inner[h])
			continue;
		size_t mv = mover_at[k++];
		if (!move) {
			nodes[1 + (size_t)parent[mv]].first = (uint)(1 + 2 * h);
			continue;
		}
		nodes[1 + 2 * h] = nodes[1 + 2 * mv];
		nodes[2 + 2 * h] = nodes[2 + 2 * mv];
	}
}

__kernel void compact_links(__global const uchar *inner, uint m, uint chunk, uint chunks,
	__global const uint *plan, __global const uint *mover_at, __global const uint *parent,
	__global node *nodes)
{
	holes(inner, m, chunk, chunks, plan, mover_at, parent, nodes, false);
}

__kernel void compact_moves(__global const uchar *inner, uint m, uint chunk, uint chunks,
	__global const uint *plan, __global const uint *mover_at, __global const uint *parent,
	__global node *nodes)
{
	holes(inner, m, chunk, chunks, plan, mover_at, parent, nodes, true);
}
