/*
 * cl_lbvh's compaction of a collapsed tree, on the host: lbvh_collapse.c's
 * (the same moves, so the same node order), one thread. The pairs of the
 * F internal nodes that stay inner below F stay; the pairs below F of
 * nodes that did not stay inner are holes, as many as the inner nodes from
 * F on (the movers), and the k-th mover's pair moves into the k-th hole.
 * Every mover's parent slot is pointed at the new place first (that slot
 * may itself lie in a pair that moves), then the pairs move.
 */
#include <string.h>

#include "cl_lbvh.h"

/* The next hole at or after h (below f), the next mover at or after m. */
static uint32_t next_hole(const uint8_t *inner, uint32_t h, uint32_t f)
{
	while (h < f && inner[h])
		h++;
	return h;
}

static uint32_t next_mover(const uint8_t *inner, uint32_t m, uint32_t n)
{
	while (m < n - 1 && !inner[m])
		m++;
	return m;
}

uint32_t cl_lbvh_compact(bvhlab_node *nodes, const uint8_t *inner, const uint32_t *parent,
                         uint32_t n)
{
	uint32_t f = 0, h, m;

	for (uint32_t i = 0; i < n - 1; i++)
		f += inner[i];
	for (h = next_hole(inner, 0, f), m = next_mover(inner, f, n); h < f;
	     h = next_hole(inner, h + 1, f), m = next_mover(inner, m + 1, n))
		nodes[1 + parent[m]].first = 1 + 2 * h;
	for (h = next_hole(inner, 0, f), m = next_mover(inner, f, n); h < f;
	     h = next_hole(inner, h + 1, f), m = next_mover(inner, m + 1, n))
		memcpy(&nodes[1 + 2 * (size_t)h], &nodes[1 + 2 * (size_t)m], 2 * sizeof(bvhlab_node));
	return 1 + 2 * f;
}
