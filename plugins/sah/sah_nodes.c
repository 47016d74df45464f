/*
 * Node writing and the leaf rule (sah_nodes.h), shared by every split
 * search.
 */
#include "sah_box.h"
#include "sah_nodes.h"

static void write_box(bvhlab_node *node, const bvhlab_aabb *box)
{
	for (int k = 0; k < 3; k++) {
		node->lo[k] = box->lo[k];
		node->hi[k] = box->hi[k];
	}
}

void sah_write_leaf(sah_builder *b, const sah_job *job)
{
	bvhlab_node *node = &b->nodes[job->node];
	const sah_prim *prims = sah_job_prims(b, job);

	write_box(node, &job->box);
	node->first = job->begin;
	node->count = job->end - job->begin;
	for (uint32_t i = job->begin; i < job->end; i++)
		b->ids[i] = prims[i].id;
}

void sah_write_node(sah_builder *b, uint32_t node, const bvhlab_aabb *box, uint32_t *first)
{
	bvhlab_node *dst = &b->nodes[node];

	/* Relaxed: only uniqueness matters; the scheduler's hand-over of the
	 * child jobs orders everything else. */
	*first = atomic_fetch_add_explicit(&b->node_counter, 2, memory_order_relaxed);
	write_box(dst, box);
	dst->first = *first;
	dst->count = 0;
}

void sah_write_inner(sah_builder *b, const sah_job *job, uint32_t mid, sah_job child[2])
{
	uint32_t first;

	sah_write_node(b, job->node, &job->box, &first);
	child[0].node = first;
	child[0].begin = job->begin;
	child[0].end = mid;
	child[1].node = first + 1;
	child[1].begin = mid;
	child[1].end = job->end;
	child[0].depth = child[1].depth = job->depth + 1;
	child[0].alt = child[1].alt = job->alt;
}

void sah_place_scratch(sah_builder *b, uint32_t root, const bvhlab_node *scratch, uint32_t used)
{
	uint32_t base = atomic_fetch_add_explicit(&b->node_counter, used - 1,
	                                          memory_order_relaxed) - 1;

	for (uint32_t i = 0; i < used; i++) {
		bvhlab_node n = scratch[i];
		if (n.count == 0)
			n.first += base;
		b->nodes[i ? base + i : root] = n;
	}
}

bool sah_leaf_rule(const sah_options *opt, uint32_t n, const bvhlab_aabb *box, bool found,
                   float best)
{
	if (n > opt->max_leaf)
		return false;
	if (!found)
		return true;
	/* Both costs multiplied by A, so a zero-area node (all primitives
	 * degenerate and coincident) compares without dividing by zero. */
	float area = bvhlab_aabb_half_area(box);
	float leaf = opt->c_isect * (float)n * area;
	float split = opt->c_trav * area + opt->c_isect * best;
	return leaf <= split;
}

bool sah_prefer_leaf(const sah_builder *b, const sah_job *job, bool found, float best)
{
	return sah_leaf_rule(&b->opt, job->end - job->begin, &job->box, found, best);
}
