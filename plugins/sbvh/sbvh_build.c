/*
 * The sbvh plugin's per-job work: deciding a split, partitioning the
 * references into the other buffer (cutting those a spatial split
 * crosses), writing leaves, and building whole subtrees on one thread
 * with an explicit stack (SAH trees with spatial splits can be deep).
 */
#include <errno.h>
#include <math.h>
#include <stdlib.h>
#include <string.h>

#include <bvhlab/aabb.h>

#include "sbvh.h"

void sbvh_choose_object(const sbvh_build *B, const sbvh_job *job, const sbvh_bins *bins,
                        sbvh_split *obj)
{
	memset(obj, 0, sizeof(*obj));
	obj->kind = SPLIT_LEAF;
	obj->cost = INFINITY;
	sbvh_best_object(B, job, bins, job->clo, job->chi, obj);
}

bool sbvh_want_spatial(const sbvh_build *B, const sbvh_job *job, const sbvh_split *obj)
{
	return job->end - job->begin > 1 && sbvh_job_has_room(job) && sbvh_try_spatial(B, job, obj);
}

void sbvh_choose_spatial(const sbvh_build *B, const sbvh_job *job, const sbvh_bins *bins,
                         sbvh_split *best)
{
	sbvh_best_spatial(B, job, bins, best);
}

void sbvh_choose_final(const sbvh_build *B, const sbvh_job *job, sbvh_split *best)
{
	uint32_t n = job->end - job->begin;

	if (n == 1 || (n <= B->opt.max_leaf && (double)n <= best->cost))
		best->kind = SPLIT_LEAF;
	else if (best->kind == SPLIT_LEAF)
		best->kind = SPLIT_MEDIAN;
}

/* Pieces of one triangle that meet in a leaf become one reference there:
 * the leaf's box already covers them all, and a ray tests it once. */
void sbvh_write_leaf(sbvh_build *B, const sbvh_job *job)
{
	const sbvh_ref *refs = B->refs[job->buf];
	uint32_t prims[SBVH_MAX_LEAF], n = 0;
	bvhlab_node *node = &B->out->nodes[job->node];

	for (uint32_t i = job->begin; i < job->end; i++) {
		uint32_t j = 0;
		while (j < n && prims[j] != refs[i].prim)
			j++;
		if (j == n)
			prims[n++] = refs[i].prim;
	}
	uint32_t slot = atomic_fetch_add_explicit(&B->next_slot, n, memory_order_relaxed);
	memcpy(&B->out->prim_index[slot], prims, n * sizeof(uint32_t));
	memcpy(node->lo, job->lo, sizeof(node->lo));
	memcpy(node->hi, job->hi, sizeof(node->hi));
	node->first = slot;
	node->count = n;
}

void sbvh_make_children(sbvh_build *B, const sbvh_job *job, uint32_t nl, uint32_t nr,
                        sbvh_job *left, sbvh_job *right)
{
	uint32_t first = atomic_fetch_add_explicit(&B->next_node, 2, memory_order_relaxed);
	uint32_t spare = job->rend - job->rbegin - nl - nr;
	/* The spare room in proportion to the children's references. */
	uint32_t spare_l = (uint32_t)((uint64_t)spare * nl / (nl + nr));
	bvhlab_node *node = &B->out->nodes[job->node];

	memcpy(node->lo, job->lo, sizeof(node->lo));
	memcpy(node->hi, job->hi, sizeof(node->hi));
	node->first = first;
	node->count = 0;
	*left = (sbvh_job){ .begin = job->rbegin, .end = job->rbegin + nl, .rbegin = job->rbegin,
	                    .rend = job->rbegin + nl + spare_l, .node = first, .buf = !job->buf };
	*right = (sbvh_job){ .begin = job->rend - nr, .end = job->rend,
	                     .rbegin = job->rbegin + nl + spare_l, .rend = job->rend,
	                     .node = first + 1, .buf = !job->buf };
	sbvh_job_empty(left);
	sbvh_job_empty(right);
}

/* Empty box and centre bounds, no references yet. */
static void child_init(sbvh_job *j)
{
	sbvh_job_empty(j);
	j->begin = j->end = 0;
}

/*
 * Partitions the job's references into the other buffer under split s:
 * left ones upwards from rbegin, right ones downwards from rend (no count
 * pass: a cut reference is clipped once); l->end and r->end get the
 * counts. False when a spatial split's duplicates would not fit the
 * job's region; what was written is scratch then.
 */
static bool partition(const sbvh_build *B, const sbvh_job *job, const sbvh_split *s,
                      sbvh_job *l, sbvh_job *r)
{
	const sbvh_ref *in = B->refs[job->buf];
	sbvh_ref *out = B->refs[!job->buf], lref, rref;
	uint32_t li = job->rbegin, ri = job->rend, half = job->begin + (job->end - job->begin) / 2;

	child_init(l);
	child_init(r);
	for (uint32_t i = job->begin; i < job->end; i++) {
		unsigned side;
		if (s->kind == SPLIT_MEDIAN) {
			side = i < half ? 1u : 2u;
			lref = rref = in[i];
		} else {
			side = sbvh_place(B, s, &in[i], &lref, &rref);
		}
		if (li + ((side & 1) != 0) + ((side & 2) != 0) > ri)
			return false;
		if (side & 1) {
			out[li++] = lref;
			sbvh_job_grow(l, &lref);
		}
		if (side & 2) {
			out[--ri] = rref;
			sbvh_job_grow(r, &rref);
		}
	}
	l->end = li - job->rbegin;
	r->end = job->rend - ri;
	return true;
}

/* Decides job's split with one thread's bins. */
static void decide(const sbvh_build *B, const sbvh_job *job, sbvh_bins *bins,
                   sbvh_split *obj, sbvh_split *best)
{
	sbvh_bin_object(B, job, job->clo, job->chi, job->begin, job->end, bins);
	sbvh_choose_object(B, job, bins, obj);
	*best = *obj;
	if (sbvh_want_spatial(B, job, obj)) {
		sbvh_bin_spatial(B, job, job->begin, job->end, bins);
		sbvh_choose_spatial(B, job, bins, best);
	}
	sbvh_choose_final(B, job, best);
	sbvh_choose_final(B, job, obj);
}

/* Copies a partition's boxes into the children made for it. */
static void take_boxes(sbvh_job *to, const sbvh_job *from)
{
	memcpy(to->lo, from->lo, sizeof(to->lo));
	memcpy(to->hi, from->hi, sizeof(to->hi));
	memcpy(to->clo, from->clo, sizeof(to->clo));
	memcpy(to->chi, from->chi, sizeof(to->chi));
}

/* Splits one job into two children, or writes it as a leaf (false). */
static bool split_job(sbvh_build *B, const sbvh_job *job, sbvh_bins *bins, sbvh_job *left,
                      sbvh_job *right)
{
	sbvh_split obj, best;
	sbvh_job l, r;

	decide(B, job, bins, &obj, &best);
	if (best.kind != SPLIT_LEAF && !partition(B, job, &best, &l, &r)) {
		/* The spatial split's duplicates do not fit: the object split
		 * (or median) never duplicates, so it does. */
		best = obj;
		if (best.kind != SPLIT_LEAF)
			partition(B, job, &best, &l, &r);
	}
	if (best.kind == SPLIT_LEAF) {
		sbvh_write_leaf(B, job);
		return false;
	}
	if (best.kind == SPLIT_SPATIAL)
		atomic_fetch_add_explicit(&B->spatial, 1, memory_order_relaxed);
	sbvh_make_children(B, job, l.end, r.end, left, right);
	take_boxes(left, &l);
	take_boxes(right, &r);
	return true;
}

int sbvh_build_subtree(sbvh_build *B, const sbvh_job *job, sbvh_bins *scratch)
{
	sbvh_job *stack = malloc(64 * sizeof(*stack)), left, right;
	uint32_t sp = 0, cap = 64;

	if (!stack)
		return -ENOMEM;
	stack[sp++] = *job;
	while (sp > 0) {
		sbvh_job j = stack[--sp];
		if (!split_job(B, &j, scratch, &left, &right))
			continue;
		if (sp + 2 > cap) {
			sbvh_job *grown = realloc(stack, 2 * cap * sizeof(*stack));
			if (!grown) {
				free(stack);
				return -ENOMEM;
			}
			stack = grown;
			cap *= 2;
		}
		stack[sp++] = right;
		stack[sp++] = left;
	}
	free(stack);
	return 0;
}
