/*
 * End-point overlap, sampled (see include/bvhlab/epo.h). For each sample
 * point p on triangle t: the sum of c(n) over every node whose box holds p,
 * minus the c(n) of the nodes on the path from the root to a leaf holding
 * t (they hold p too, and t is in their subtrees). What remains is the
 * cost of boxes p lies in by overlap alone.
 */
#include <errno.h>
#include <math.h>
#include <stdlib.h>

#include <bvhlab/epo.h>
#include <bvhlab/trace.h>

#include "tree/tree_view.h"
#include "util/util.h"

#define NONE UINT32_MAX

struct epo_walk {
	const bvhlab_tree *tree;
	const bvhlab_scene *scene;
	const uint32_t *parents;
	uint32_t *stack; /* [node_count]: a node is pushed at most once per walk */
	double *cdf;     /* [triangle_count]: running sum of triangle areas */
};

/* The SAH's weights (tree.h): a leaf's references, an inner node's
 * traversal cost (1 for a binary node). */
static double cost(const bvhlab_node *n)
{
	return tree_is_leaf(n) ? (double)tree_leaf_count(n) : tree_trav_cost(n);
}

static bool holds(const bvhlab_node *n, const float p[3])
{
	for (int k = 0; k < 3; k++)
		if (!(p[k] >= n->lo[k] && p[k] <= n->hi[k]))
			return false;
	return true;
}

static bool leaf_has(const bvhlab_tree *tree, const bvhlab_node *n, uint32_t prim)
{
	uint32_t end = tree_leaf_first(n) + tree_leaf_count(n);

	for (uint32_t i = tree_leaf_first(n); i < end && i < tree->index_count; i++)
		if (tree->prim_index[i] == prim)
			return true;
	return false;
}

/* The overlap cost of one point p on triangle prim. */
static double point_cost(const struct epo_walk *w, const float p[3], uint32_t prim)
{
	const bvhlab_node *nodes = w->tree->nodes;
	uint32_t sp = 0, own = NONE;
	double sum = 0;
	w->stack[sp++] = 0;
	while (sp) {
		uint32_t i = w->stack[--sp];
		const bvhlab_node *n = &nodes[i];
		if (!holds(n, p))
			continue;
		sum += cost(n);
		if (tree_is_leaf(n)) {
			if (own == NONE && leaf_has(w->tree, n, prim))
				own = i;
			continue;
		}
		for (uint32_t k = 0; k < tree_child_count(n); k++)
			w->stack[sp++] = tree_child(n, k);
	}
	for (uint32_t i = own; i != NONE; i = w->parents[i])
		sum -= cost(&nodes[i]);
	return sum;
}

static const float *vertex(const bvhlab_scene *s, uint32_t prim, int j)
{
	return s->vertices + 3 * (size_t)s->indices[3 * (size_t)prim + j];
}

static double tri_area(const bvhlab_scene *s, uint32_t prim)
{
	const float *a = vertex(s, prim, 0), *b = vertex(s, prim, 1), *c = vertex(s, prim, 2);
	double e[3], f[3];
	for (int k = 0; k < 3; k++) {
		e[k] = (double)b[k] - a[k];
		f[k] = (double)c[k] - a[k];
	}
	double x = e[1] * f[2] - e[2] * f[1], y = e[2] * f[0] - e[0] * f[2],
	       z = e[0] * f[1] - e[1] * f[0];
	return 0.5 * sqrt(x * x + y * y + z * z);
}

static double uniform(uint64_t *state)
{
	return (double)(util_splitmix64(state) >> 11) * (1.0 / 9007199254740992.0);
}

/* First triangle whose running area sum exceeds u (never one of area 0). */
static uint32_t pick(const double *cdf, uint32_t n, double u)
{
	uint32_t lo = 0, hi = n - 1;
	while (lo < hi) {
		uint32_t mid = lo + (hi - lo) / 2;
		if (cdf[mid] > u)
			hi = mid;
		else
			lo = mid + 1;
	}
	return lo;
}

/* A uniform point on the triangle, in double, then clamped to the
 * triangle's float box: rounding must not carry it out of its own leaf. */
static void sample_point(const bvhlab_scene *s, uint32_t prim, uint64_t *state, float p[3])
{
	const float *a = vertex(s, prim, 0), *b = vertex(s, prim, 1), *c = vertex(s, prim, 2);
	double r1 = sqrt(uniform(state)), r2 = uniform(state);
	double wa = 1 - r1, wb = r1 * (1 - r2), wc = r1 * r2;
	for (int k = 0; k < 3; k++) {
		float lo = fminf(a[k], fminf(b[k], c[k])), hi = fmaxf(a[k], fmaxf(b[k], c[k]));
		float x = (float)(wa * a[k] + wb * b[k] + wc * c[k]);
		p[k] = x < lo ? lo : x > hi ? hi : x;
	}
}

static double estimate(struct epo_walk *w, uint32_t samples, uint64_t seed)
{
	uint32_t n = w->scene->triangle_count;
	double total = w->cdf[n - 1], sum = 0;
	uint64_t state = seed;
	for (uint32_t i = 0; i < samples; i++) {
		uint32_t prim = pick(w->cdf, n, uniform(&state) * total);
		float p[3];
		sample_point(w->scene, prim, &state, p);
		sum += point_cost(w, p, prim);
	}
	return sum / samples;
}

int bvhlab_tree_epo(const bvhlab_tree *tree, const bvhlab_scene *scene, uint32_t samples,
                    uint64_t seed, double *epo)
{
	struct epo_walk w = {.tree = tree, .scene = scene};
	uint32_t n = scene->triangle_count;
	*epo = 0;
	if (samples == 0)
		return -EINVAL;
	if (tree->node_count == 0 || n == 0)
		return 0;
	int r = bvhlab_tree_parents(tree, (uint32_t **)&w.parents);
	w.stack = malloc((size_t)tree->node_count * sizeof(*w.stack) + sizeof(*w.stack));
	w.cdf = malloc((size_t)n * sizeof(*w.cdf));
	if (r == 0 && (!w.stack || !w.cdf))
		r = -ENOMEM;
	for (uint32_t i = 0; r == 0 && i < n; i++)
		w.cdf[i] = (i ? w.cdf[i - 1] : 0) + tri_area(scene, i);
	if (r == 0 && w.cdf[n - 1] > 0)
		*epo = estimate(&w, samples, seed);
	free((void *)w.parents);
	free(w.stack);
	free(w.cdf);
	return r;
}
