/*
 * collapse's sah method (collapse.h): the SAH-optimal binary-to-wide
 * conversion of Ylitie, Karras and Laine (HPG 2017, section 4), by dynamic
 * programming bottom-up over the binary tree.
 *
 * For a binary node n, F(n, j) is the least cost of standing for n's
 * subtree by a forest of exactly j wide subtrees (j = 1..width):
 *   F(n, 1)  = min(leaf(n), inner(n))
 *   leaf(n)  = SA(n) * c_isect * refs(n)   when refs(n) <= max_leaf (or n
 *              is a binary leaf, which cannot be cut), else infinite
 *   inner(n) = min over k = 2..width of F(n, k) + SA(n) * (c_node + c_trav * k / 2)
 *   F(n, j)  = min over i = 1..j-1 of F(left, i) + F(right, j - i), j >= 2
 *              (infinite for a binary leaf)
 * The wide node's cost depends on how many children it has, so unlike the
 * paper's fixed per-node cost the k of inner(n) is chosen here, where the
 * paper takes the forest of at most `width`. F(root, 1) is the whole wide
 * tree's cost; the choices made are kept per node and j to rebuild it.
 * O(n * width^2) time, width doubles and bytes per binary node.
 */
#include <errno.h>
#include <math.h>
#include <stdlib.h>

#include <bvhlab/aabb.h>

#include "collapse.h"

struct dp {
	struct collapse *c;
	const struct collapse_params *p;
	double *cost;  /* [count * width]: F(n, j) at n * width + j - 1 */
	uint32_t *refs; /* [count] references under n */
	bool area_one; /* the root has no area: every node counts 1 (tree.h) */
};

/* F(n, j) for j >= 2 from the children's, and the inner node's best k. */
static double distribute(struct dp *d, uint32_t n, double area, uint8_t *ch, double *f)
{
	const uint32_t w = d->c->width, l = d->c->bin[n].first;
	const double *fl = d->cost + (size_t)l * w, *fr = d->cost + (size_t)(l + 1) * w;
	double inner = INFINITY;
	for (uint32_t j = 2; j <= w; j++) {
		for (uint32_t i = 1; i < j; i++) {
			double v = fl[i - 1] + fr[j - i - 1];
			if (v < f[j - 1])
				f[j - 1] = v, ch[j - 1] = (uint8_t)i;
		}
		double v = f[j - 1] + area * (d->p->c_node + d->p->c_trav * 0.5 * j);
		if (v < inner)
			inner = v, ch[0] = (uint8_t)j;
	}
	return inner;
}

static void plan_node(struct dp *d, uint32_t n)
{
	const uint32_t w = d->c->width;
	const bvhlab_node *b = &d->c->bin[n];
	double *f = d->cost + (size_t)n * w;
	uint8_t *ch = d->c->choice + (size_t)n * w;
	double area = d->area_one ? 1.0 : bvhlab_box_area(b->lo, b->hi);
	for (uint32_t j = 0; j < w; j++)
		f[j] = INFINITY, ch[j] = 0;
	if (b->count != 0) {
		d->refs[n] = b->count;
		f[0] = area * d->p->c_isect * b->count;
		return;
	}
	uint64_t refs = (uint64_t)d->refs[b->first] + d->refs[b->first + 1];
	d->refs[n] = refs > UINT32_MAX ? UINT32_MAX : (uint32_t)refs;
	f[0] = distribute(d, n, area, ch, f);
	double leaf = area * d->p->c_isect * (double)refs;
	if (refs <= d->p->max_leaf && leaf <= f[0])
		f[0] = leaf, ch[0] = 0;
}

/* The binary nodes parents first (breadth first from the root), so that
 * the plan can run children first without recursion (a degenerate tree is
 * as deep as it has leaves): how many, or -EINVAL for links that are not
 * a binary tree. */
static int64_t parents_first(const bvhlab_node *bin, uint32_t count, uint32_t *order)
{
	uint32_t head = 0, tail = 0;
	order[tail++] = 0;
	while (head < tail) {
		const bvhlab_node *b = &bin[order[head++]];
		if (b->count != 0)
			continue;
		if (tail + 2 > count) /* a cycle (collapse.c checked the links) */
			return -EINVAL;
		order[tail++] = b->first;
		order[tail++] = b->first + 1;
	}
	return tail;
}

int collapse_sah_plan(struct collapse *c, const struct collapse_params *p)
{
	struct dp d = { .c = c, .p = p };
	uint32_t *order = malloc((size_t)c->count * sizeof(*order));
	d.cost = malloc((size_t)c->count * c->width * sizeof(*d.cost));
	d.refs = malloc((size_t)c->count * sizeof(*d.refs));
	c->choice = malloc((size_t)c->count * c->width);
	int64_t reached = order && d.cost && d.refs && c->choice ? 0 : -ENOMEM;
	if (reached == 0)
		reached = parents_first(c->bin, c->count, order);
	d.area_one = !(bvhlab_box_area(c->bin[0].lo, c->bin[0].hi) > 0.0);
	for (int64_t k = reached; k-- > 0;)
		plan_node(&d, order[k]);
	free(order);
	free(d.cost);
	free(d.refs);
	return reached < 0 ? (int)reached : 0;
}

uint32_t collapse_sah_forest(const struct collapse *c, uint32_t n, uint32_t j, uint32_t *list)
{
	if (j == 1) {
		list[0] = n;
		return 1;
	}
	uint32_t i = c->choice[(size_t)n * c->width + j - 1], l = c->bin[n].first;
	uint32_t m = collapse_sah_forest(c, l, i, list);
	return m + collapse_sah_forest(c, l + 1, j - i, list + m);
}
