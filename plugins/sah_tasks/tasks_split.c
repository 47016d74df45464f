/*
 * Team binning and stable parallel partition of one large node (see
 * tasks_split.h). The float operations that decide the split repeat the
 * kernel's (sah_binned.c) one for one: a centroid's bin, the per-bin
 * unions and the cost sweep; any change there must be mirrored here, and
 * tests/test-sah-tasks.c compares the trees with sah_seq's to catch it.
 */
#include <errno.h>
#include <float.h>
#include <math.h>
#include <stdlib.h>

#include "sah_simd.h"
#include "tasks_split.h"

int tasks_split_init(tasks_split *s, sah_builder *b, uint32_t parts)
{
	s->b = b;
	s->parts = parts;
	s->temp = malloc((size_t)b->prim_count * sizeof(sah_prim));
	s->bins = malloc(parts * sizeof(tasks_bins));
	s->left = malloc(parts * sizeof(uint32_t));
	s->cbox = malloc(2 * parts * sizeof(bvhlab_aabb));
	if (s->temp && s->bins && s->left && s->cbox)
		return 0;
	tasks_split_free(s);
	return -ENOMEM;
}

void tasks_split_free(tasks_split *s)
{
	free(s->temp);
	free(s->bins);
	free(s->left);
	free(s->cbox);
	s->temp = NULL;
	s->bins = NULL;
	s->left = NULL;
	s->cbox = NULL;
}

/* Chunk `part` of [begin, end): P contiguous chunks, sizes differing by 1. */
static void chunk(const tasks_split *s, uint32_t part, uint32_t *from, uint32_t *to)
{
	uint64_t n = s->job.end - s->job.begin;

	*from = s->job.begin + (uint32_t)(n * part / s->parts);
	*to = s->job.begin + (uint32_t)(n * (part + 1) / s->parts);
}

/* Same scale rule as the kernel's setup(), including the overflow cap. */
void tasks_split_begin(tasks_split *s, const sah_job *job)
{
	s->job = *job;
	s->nb = s->b->opt.bins;
	s->axis = -1;
	for (int a = 0; a < 3; a++) {
		float extent = job->cbox.hi[a] - job->cbox.lo[a];
		float scale = (float)s->nb / extent;
		s->lo[a] = job->cbox.lo[a];
		s->scale[a] = extent > 0 ? (scale <= FLT_MAX ? scale : FLT_MAX) : 0;
	}
}

/* The kernel's fill(): the three axes' bins of a primitive, same operations. */
static inline void bins_of(const tasks_split *s, const sah_prim *p, v4 *lo, v4 *hi,
                           int32_t k[4])
{
	const v4 half = v4_set1(0.5f), top = v4_set1((float)(s->nb - 1)), zero = v4_set1(0);
	const v4 base = v4_set3(s->lo[0], s->lo[1], s->lo[2]);
	const v4 scale = v4_set3(s->scale[0], s->scale[1], s->scale[2]);

	*lo = v4_load3(p->lo);
	*hi = v4_load3(p->hi);
	v4 f = v4_mul(v4_sub(v4_mul(v4_add(*lo, *hi), half), base), scale);
	v4_trunc(v4_max(v4_min(f, top), zero), k);
}

void tasks_bin(tasks_split *s, uint32_t part)
{
	tasks_bins *g = &s->bins[part];
	const sah_prim *prims = s->b->prims[0];
	const v4 inf = v4_set1(INFINITY), ninf = v4_set1(-INFINITY);
	uint32_t from, to;
	int32_t k[4];

	for (int a = 0; a < 3; a++) {
		for (uint32_t j = 0; j < s->nb; j++) {
			g->count[a][j] = 0;
			v4_store(g->lo[a][j], inf);
			v4_store(g->hi[a][j], ninf);
		}
	}
	chunk(s, part, &from, &to);
	for (uint32_t i = from; i < to; i++) {
		v4 lo, hi;
		bins_of(s, &prims[i], &lo, &hi, k);
		for (int a = 0; a < 3; a++) {
			g->count[a][k[a]]++;
			v4_store(g->lo[a][k[a]], v4_min(v4_load(g->lo[a][k[a]]), lo));
			v4_store(g->hi[a][k[a]], v4_max(v4_load(g->hi[a][k[a]]), hi));
		}
	}
}

/* Folds every part's bins into bins[0], in part order. */
static void reduce(tasks_split *s)
{
	tasks_bins *g = &s->bins[0];

	for (uint32_t t = 1; t < s->parts; t++) {
		const tasks_bins *h = &s->bins[t];
		for (int a = 0; a < 3; a++) {
			for (uint32_t j = 0; j < s->nb; j++) {
				g->count[a][j] += h->count[a][j];
				v4_store(g->lo[a][j], v4_min(v4_load(g->lo[a][j]), v4_load(h->lo[a][j])));
				v4_store(g->hi[a][j], v4_max(v4_load(g->hi[a][j]), v4_load(h->hi[a][j])));
			}
		}
	}
}

/* The kernel's evaluate_axis(): only boundaries right after a non-empty
 * bin, right-to-left sums first, strict < so the first minimum wins. */
static float evaluate_axis(const tasks_split *s, int a, float best, uint32_t *split)
{
	const tasks_bins *g = &s->bins[0];
	uint32_t used[SAH_MAX_BINS], m = 0, n = 0;
	float right[SAH_MAX_BINS];
	v4 lo = v4_set1(INFINITY), hi = v4_set1(-INFINITY);

	for (uint32_t j = 0; j < s->nb; j++)
		if (g->count[a][j])
			used[m++] = j;
	for (uint32_t j = m - 1; j > 0; j--) {
		uint32_t k = used[j];
		lo = v4_min(lo, v4_load(g->lo[a][k]));
		hi = v4_max(hi, v4_load(g->hi[a][k]));
		n += g->count[a][k];
		right[j] = v4_half_area(lo, hi) * (float)n;
	}
	lo = v4_set1(INFINITY);
	hi = v4_set1(-INFINITY);
	n = 0;
	for (uint32_t j = 0; j + 1 < m; j++) {
		uint32_t k = used[j];
		lo = v4_min(lo, v4_load(g->lo[a][k]));
		hi = v4_max(hi, v4_load(g->hi[a][k]));
		n += g->count[a][k];
		float cost = v4_half_area(lo, hi) * (float)n + right[j + 1];
		if (cost < best) {
			best = cost;
			*split = k + 1;
		}
	}
	return best;
}

/* The node is larger than max_leaf (the scheduler's threshold sees to it),
 * so the kernel's leaf rule cannot make it a leaf: any candidate splits. */
bool tasks_choose(tasks_split *s)
{
	float best = INFINITY;
	uint32_t split = 0;

	reduce(s);
	for (int a = 0; a < 3; a++) {
		float cost = s->scale[a] > 0 ? evaluate_axis(s, a, best, &split) : best;
		if (cost < best) {
			best = cost;
			s->axis = a;
		}
	}
	s->split = split;
	return s->axis >= 0;
}

static inline bool goes_left(const tasks_split *s, const sah_prim *p)
{
	v4 lo, hi;
	int32_t k[4];

	bins_of(s, p, &lo, &hi, k);
	return (uint32_t)k[s->axis] < s->split;
}

void tasks_count(tasks_split *s, uint32_t part)
{
	const sah_prim *prims = s->b->prims[0];
	uint32_t from, to, n = 0;

	chunk(s, part, &from, &to);
	for (uint32_t i = from; i < to; i++)
		n += goes_left(s, &prims[i]);
	s->left[part] = n;
}

void tasks_counted(tasks_split *s)
{
	uint32_t total = 0;

	for (uint32_t t = 0; t < s->parts; t++)
		total += s->left[t];
	s->mid = s->job.begin + total;
}

/* Chunk t's lefts follow those of chunks < t, its rights likewise after
 * mid: both sides keep their input order, whatever P is. */
void tasks_scatter(tasks_split *s, uint32_t part)
{
	const sah_prim *prims = s->b->prims[0];
	uint32_t from, to, l = s->job.begin, r;

	chunk(s, part, &from, &to);
	for (uint32_t t = 0; t < part; t++)
		l += s->left[t];
	r = s->mid + (from - s->job.begin) - (l - s->job.begin);
	for (uint32_t i = from; i < to; i++) {
		const sah_prim *p = &prims[i];
		if (goes_left(s, p))
			s->temp[l++] = *p;
		else
			s->temp[r++] = *p;
	}
}

static void centroid_bounds(const sah_prim *src, sah_prim *dst, uint32_t from, uint32_t to,
                            bvhlab_aabb *cbox)
{
	const v4 half = v4_set1(0.5f);
	v4 clo = v4_set1(INFINITY), chi = v4_set1(-INFINITY);

	for (uint32_t i = from; i < to; i++) {
		v4 cen = v4_mul(v4_add(v4_load3(src[i].lo), v4_load3(src[i].hi)), half);
		dst[i] = src[i];
		clo = v4_min(clo, cen);
		chi = v4_max(chi, cen);
	}
	v4_store3(cbox->lo, clo);
	v4_store3(cbox->hi, chi);
}

/* Copies chunk `part` of temp back and gathers its centroid bounds, split
 * at mid, for the children's cbox. */
void tasks_copy(tasks_split *s, uint32_t part)
{
	uint32_t from, to, cut;

	chunk(s, part, &from, &to);
	cut = s->mid < from ? from : s->mid > to ? to : s->mid;
	centroid_bounds(s->temp, s->b->prims[0], from, cut, &s->cbox[2 * part]);
	centroid_bounds(s->temp, s->b->prims[0], cut, to, &s->cbox[2 * part + 1]);
}

static void bins_box(const tasks_split *s, uint32_t from, uint32_t to, bvhlab_aabb *box)
{
	const tasks_bins *g = &s->bins[0];
	v4 lo = v4_set1(INFINITY), hi = v4_set1(-INFINITY);

	for (uint32_t j = from; j < to; j++) {
		if (!g->count[s->axis][j])
			continue;
		lo = v4_min(lo, v4_load(g->lo[s->axis][j]));
		hi = v4_max(hi, v4_load(g->hi[s->axis][j]));
	}
	v4_store3(box->lo, lo);
	v4_store3(box->hi, hi);
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
		merge_cbox(s, c, &child[c].cbox);
	}
	bins_box(s, 0, s->split, &child[0].box);
	bins_box(s, s->split, s->nb, &child[1].box);
}
