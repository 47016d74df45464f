/*
 * One level of lookahead for the top splits of the sbvh plugin.
 *
 * The greedy SAH prices a split as if its children were leaves. On a
 * composite scene that misleads it where it matters most, at the top: on
 * configs/composite.json's courtyard the second split's object split sets
 * the ground (terrain and room floor, 120,160 triangles under a box as
 * wide as the scene) apart from the objects standing on it (greedy cost
 * 271,454 against 281,174 for a spatial split across both); the objects'
 * box then lies inside the ground's, and every ray among them also walks
 * the ground's subtree. Taking the spatial split there instead gives SAH
 * 16.60 against 17.85 for the whole tree.
 *
 * So, for jobs of at least `lookahead` references, when both an object
 * and a spatial split exist, each is priced by what its children would
 * cost split once more: 1 + (A_L c_L + A_R c_R) / A, where c is a child's
 * best object-split cost in its own area's units. The children are made
 * from every STEP-th reference only (the same sample on every thread
 * count: the job's references keep their order), and their bins' counts
 * scaled back by STEP; A_L and A_R are the split's own binned boxes.
 *
 * The spatial split is taken when either cost says so: the lookahead only
 * adds spatial splits the greedy cost turned down, never removes one it
 * chose. Its children are priced by object splits alone, which underrates
 * a spatial split whose children would split spatially again; letting it
 * overrule the greedy choice both ways gave the courtyard 17.15, adding
 * only gives 16.60.
 */
#include <math.h>
#include <stdlib.h>

#include <bvhlab/aabb.h>

#include "sbvh.h"

#define STEP 8

/* A sampled child: its references and the bounds of their boxes and
 * centres. */
struct sample {
	sbvh_ref *refs;
	uint32_t n;
	sbvh_job box;
};

static void add(struct sample *c, const sbvh_ref *r)
{
	c->refs[c->n++] = *r;
	sbvh_job_grow(&c->box, r);
}

/* A child's best object split cost, in units of its own area (a leaf's
 * when nothing splits it). */
static double child_cost(const sbvh_build *B, struct sample *c, sbvh_bins *bins)
{
	sbvh_split s;

	if (c->n < 2)
		return (double)c->n * STEP;
	sbvh_bin_object_refs(c->refs, B->opt.bins, c->box.clo, c->box.chi, 0, c->n, bins);
	for (int k = 0; k < 3; k++)
		for (uint32_t j = 0; j < B->opt.bins; j++)
			bins->count[k][j] *= STEP;
	sbvh_choose_object(B, &c->box, bins, &s);
	return fmin(s.cost, (double)c->n * STEP);
}

static double two_level(const sbvh_build *B, const sbvh_job *job, const sbvh_split *s,
                        struct sample c[2], sbvh_bins *bins)
{
	const sbvh_ref *refs = B->refs[job->buf];
	double a = bvhlab_box_area(job->lo, job->hi);

	for (int i = 0; i < 2; i++) {
		c[i].n = 0;
		sbvh_job_empty(&c[i].box);
	}
	for (uint32_t i = job->begin; i < job->end; i += STEP) {
		sbvh_ref l, r;
		unsigned side = sbvh_place(B, s, &refs[i], &l, &r);
		if (side & 1)
			add(&c[0], &l);
		if (side & 2)
			add(&c[1], &r);
	}
	return 1.0 + (bvhlab_box_area(s->llo, s->lhi) * child_cost(B, &c[0], bins) +
	              bvhlab_box_area(s->rlo, s->rhi) * child_cost(B, &c[1], bins)) / a;
}

const sbvh_split *sbvh_lookahead(const sbvh_build *B, const sbvh_job *job,
                                 const sbvh_split *obj, const sbvh_split *sp, sbvh_bins *bins)
{
	uint32_t cap = (job->end - job->begin) / STEP + 1;
	struct sample c[2] = { { .refs = malloc(cap * sizeof(sbvh_ref)) },
		               { .refs = malloc(cap * sizeof(sbvh_ref)) } };
	const sbvh_split *pick = sp->cost < obj->cost ? sp : obj;

	if (c[0].refs && c[1].refs) {
		double co = two_level(B, job, obj, c, bins), cs = two_level(B, job, sp, c, bins);
		pick = cs < co ? sp : pick;
	}
	free(c[0].refs);
	free(c[1].refs);
	return pick;
}
