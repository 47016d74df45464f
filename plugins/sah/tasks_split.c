/*
 * Team binning and stable parallel partition of one large node (see
 * tasks_split.h). Every float operation that decides the split is the
 * kernel's own (sah_grid / sah_bins in sah_bins.h): each part fills its
 * bins, the caller merges them and the kernel chooses.
 * tests/test-sah-tasks.c compares the trees with sah_seq's.
 */
#include <errno.h>
#include <math.h>
#include <stdlib.h>

#include "sah_simd.h"
#include "tasks_split.h"

int tasks_split_init(tasks_split *s, sah_builder *b, uint32_t parts)
{
	s->b = b;
	s->parts = parts;
	s->bins = malloc(parts * sizeof(sah_bins));
	s->total = malloc(sizeof(sah_bins));
	s->left = malloc(parts * sizeof(uint32_t));
	s->cbox = malloc(2 * parts * sizeof(bvhlab_aabb));
	if (s->bins && s->total && s->left && s->cbox)
		return 0;
	tasks_split_free(s);
	return -ENOMEM;
}

void tasks_split_free(tasks_split *s)
{
	free(s->bins);
	free(s->total);
	free(s->left);
	free(s->cbox);
	*s = (tasks_split){0};
}

/* Chunk `part` of [begin, end): P contiguous chunks, sizes differing by 1. */
static void chunk(const tasks_split *s, uint32_t part, uint32_t *from, uint32_t *to)
{
	uint64_t n = s->job.end - s->job.begin;

	*from = s->job.begin + (uint32_t)(n * part / s->parts);
	*to = s->job.begin + (uint32_t)(n * (part + 1) / s->parts);
}

void tasks_split_begin(tasks_split *s, const sah_job *job)
{
	s->job = *job;
	s->src = sah_job_prims(s->b, job);
	s->dst = job->alt ? s->b->prims[0] : s->b->alt;
	s->axis = -1;
	sah_grid_init(&s->grid, job, s->b->opt.bins);
}

void tasks_bin(tasks_split *s, uint32_t part)
{
	uint32_t from, to;

	chunk(s, part, &from, &to);
	sah_bins_fill(&s->bins[part], &s->grid, s->src, from, to, s->b->opt.simd);
}

static void left_counts(tasks_split *s);

/* Folds the parts' bins in part order into the total (the parts' own stay,
 * for their left counts) and lets the kernel choose. The node is larger
 * than max_leaf (the scheduler's threshold sees to it), so the kernel's
 * leaf rule cannot make it a leaf: any candidate splits. */
bool tasks_choose(tasks_split *s)
{
	float cost;

	*s->total = s->bins[0];
	for (uint32_t t = 1; t < s->parts; t++)
		sah_bins_merge(s->total, &s->bins[t], s->grid.nb);
	s->axis = sah_bins_choose(s->total, &s->grid, &s->split, &cost);
	if (s->axis >= 0)
		left_counts(s);
	return s->axis >= 0;
}

static inline bool goes_left(const tasks_split *s, const sah_prim *p)
{
	return sah_grid_bin(&s->grid, s->axis, p) < s->split;
}

/* Chunk t binned exactly the primitives it will scatter, so its bins
 * below the split count its lefts: no counting pass over the node. */
static void left_counts(tasks_split *s)
{
	uint32_t total = 0;

	for (uint32_t t = 0; t < s->parts; t++) {
		uint32_t n = 0;
		for (uint32_t j = 0; j < s->split; j++)
			n += s->bins[t].count[s->axis][j];
		s->left[t] = n;
		total += n;
	}
	s->mid = s->job.begin + total;
}

/* Chunk t's lefts follow those of chunks < t, its rights likewise after
 * mid: both sides keep their input order, whatever P is. The side is an
 * arithmetic select (a branch would mispredict at every run boundary),
 * and the children's centroid bounds are gathered on the way. */
void tasks_scatter(tasks_split *s, uint32_t part)
{
	const sah_prim *prims = s->src;
	const v4 half = v4_set1(0.5f);
	v4 clo[2] = { v4_set1(INFINITY), v4_set1(INFINITY) };
	v4 chi[2] = { v4_set1(-INFINITY), v4_set1(-INFINITY) };
	uint32_t from, to, l = s->job.begin, r;

	chunk(s, part, &from, &to);
	for (uint32_t t = 0; t < part; t++)
		l += s->left[t];
	r = s->mid + (from - s->job.begin) - (l - s->job.begin);
	for (uint32_t i = from; i < to; i++) {
		const sah_prim *p = &prims[i];
		uint32_t right = !goes_left(s, p), mask = 0u - right;
		v4 cen = v4_mul(v4_add(v4_load3(p->lo), v4_load3(p->hi)), half);
		s->dst[(r & mask) | (l & ~mask)] = *p;
		r += right;
		l += right ^ 1;
		clo[right] = v4_min(clo[right], cen);
		chi[right] = v4_max(chi[right], cen);
	}
	for (int c = 0; c < 2; c++) {
		v4_store3(s->cbox[2 * part + c].lo, clo[c]);
		v4_store3(s->cbox[2 * part + c].hi, chi[c]);
	}
}

static void write_box(bvhlab_node *node, const bvhlab_aabb *box)
{
	for (int k = 0; k < 3; k++) {
		node->lo[k] = box->lo[k];
		node->hi[k] = box->hi[k];
	}
}

static void merge_cbox(const tasks_split *s, int side, bvhlab_aabb *out)
{
	for (int k = 0; k < 3; k++) {
		out->lo[k] = INFINITY;
		out->hi[k] = -INFINITY;
	}
	for (uint32_t t = 0; t < s->parts; t++) {
		const bvhlab_aabb *c = &s->cbox[2 * t + side];
		for (int k = 0; k < 3; k++) {
			out->lo[k] = c->lo[k] < out->lo[k] ? c->lo[k] : out->lo[k];
			out->hi[k] = c->hi[k] > out->hi[k] ? c->hi[k] : out->hi[k];
		}
	}
}

/* As the kernel's sah_write_inner: relaxed slot allocation, the team's
 * barriers order the rest. */
void tasks_split_end(tasks_split *s, sah_job child[2])
{
	const sah_job *job = &s->job;
	bvhlab_node *node = &s->b->nodes[job->node];
	uint32_t first = atomic_fetch_add_explicit(&s->b->node_counter, 2, memory_order_relaxed);

	write_box(node, &job->box);
	node->first = first;
	node->count = 0;
	for (int c = 0; c < 2; c++) {
		child[c].node = first + (uint32_t)c;
		child[c].begin = c ? s->mid : job->begin;
		child[c].end = c ? job->end : s->mid;
		child[c].depth = job->depth + 1;
		child[c].alt = !job->alt;
		merge_cbox(s, c, &child[c].cbox);
	}
	sah_bins_box(s->total, s->axis, 0, s->split, &child[0].box);
	sah_bins_box(s->total, s->axis, s->split, s->grid.nb, &child[1].box);
}
