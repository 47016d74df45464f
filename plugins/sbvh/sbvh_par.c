/*
 * The sbvh plugin's schedule: jobs of at least parallel_min references are
 * split by every thread together (each bins, counts and partitions its
 * share of the references; bins merge by box union and count sums, and
 * shares are written at prefix-summed offsets, so the result is what one
 * thread would write), breadth first; the smaller jobs left over are then
 * built as whole subtrees, largest first, one per thread at a time. Every
 * phase runs on a team of the thread layer (team.h), which pins it.
 *
 * The same jobs take the same path whatever the thread count (a single
 * thread runs the team path with one share), so the tree is the same.
 */
#include <errno.h>
#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "sbvh.h"
#include "team_list.h"

enum phase { PH_OBJECT, PH_SPATIAL, PH_COUNT, PH_WRITE };

typedef struct member {
	struct crew *crew;
	uint32_t t;
	uint32_t begin, end;   /* its share of the job's references */
	uint32_t nl, nr;       /* PH_COUNT */
	uint32_t lout, rout;   /* PH_WRITE: where its share goes */
	sbvh_job l, r;         /* PH_WRITE: boxes of what it wrote */
	sbvh_bins bins;
} member;

typedef struct crew {
	sbvh_build *B;
	const sbvh_job *job;
	const sbvh_split *split;
	enum phase phase;
	member *m;             /* [B->threads] */
	team team;             /* the threads of one phase */
} crew;

static unsigned side_of(const crew *tm, uint32_t i, sbvh_ref *l, sbvh_ref *r)
{
	const sbvh_ref *ref = &tm->B->refs[tm->job->buf][i];

	if (tm->split->kind == SPLIT_MEDIAN) {
		*l = *r = *ref;
		return i < tm->job->begin + (tm->job->end - tm->job->begin) / 2 ? 1u : 2u;
	}
	return sbvh_place(tm->B, tm->split, ref, l, r);
}

static void count_share(member *m)
{
	sbvh_ref l, r;

	m->nl = m->nr = 0;
	for (uint32_t i = m->begin; i < m->end; i++) {
		unsigned side = side_of(m->crew, i, &l, &r);
		m->nl += (side & 1) != 0;
		m->nr += (side & 2) != 0;
	}
}

static void write_share(member *m)
{
	sbvh_ref *out = m->crew->B->refs[!m->crew->job->buf], l, r;
	uint32_t li = m->lout, ri = m->rout;

	sbvh_job_empty(&m->l);
	sbvh_job_empty(&m->r);
	for (uint32_t i = m->begin; i < m->end; i++) {
		unsigned side = side_of(m->crew, i, &l, &r);
		if (side & 1) {
			out[li++] = l;
			sbvh_job_grow(&m->l, &l);
		}
		if (side & 2) {
			out[ri++] = r;
			sbvh_job_grow(&m->r, &r);
		}
	}
}

static void run_share(member *m)
{
	crew *tm = m->crew;

	switch (tm->phase) {
	case PH_OBJECT:
		sbvh_bin_object(tm->B, tm->job, tm->job->clo, tm->job->chi, m->begin, m->end,
		                &m->bins);
		break;
	case PH_SPATIAL:
		sbvh_bin_spatial(tm->B, tm->job, m->begin, m->end, &m->bins);
		break;
	case PH_COUNT:
		count_share(m);
		break;
	case PH_WRITE:
		write_share(m);
		break;
	}
}

/* Thread t runs shares t, t + size, ...: a team smaller than B->threads (a
 * thread that could not start) still runs every share. */
static void share_member(void *arg, unsigned t)
{
	crew *tm = arg;

	for (uint32_t s = t; s < tm->B->threads; s += tm->team.threads)
		run_share(&tm->m[s]);
}

/* Every share of the phase, on a team of the thread layer; the caller is
 * member 0. Without a team (no barrier to be had) the caller runs them all. */
static void run_phase(crew *tm, enum phase phase)
{
	tm->phase = phase;
	if (team_run_on(&tm->team, &tm->B->th, tm->B->threads, share_member, tm) < 0) {
		for (uint32_t s = 0; s < tm->B->threads; s++)
			run_share(&tm->m[s]);
	}
}

/* A share's boxes into the child's. */
static void unite_job(sbvh_job *to, const sbvh_job *from)
{
	for (int k = 0; k < 3; k++) {
		to->lo[k] = from->lo[k] < to->lo[k] ? from->lo[k] : to->lo[k];
		to->hi[k] = from->hi[k] > to->hi[k] ? from->hi[k] : to->hi[k];
		to->clo[k] = from->clo[k] < to->clo[k] ? from->clo[k] : to->clo[k];
		to->chi[k] = from->chi[k] > to->chi[k] ? from->chi[k] : to->chi[k];
	}
}

static void merge_bins(crew *tm)
{
	for (uint32_t t = 1; t < tm->B->threads; t++)
		sbvh_bins_merge(&tm->m[0].bins, &tm->m[t].bins, tm->B->opt.bins);
}

/* Counts every share under split s; false when the result overflows the
 * job's region. */
static bool count_all(crew *tm, const sbvh_split *s, uint32_t *nl, uint32_t *nr)
{
	uint64_t l = 0, r = 0;

	tm->split = s;
	run_phase(tm, PH_COUNT);
	for (uint32_t t = 0; t < tm->B->threads; t++)
		l += tm->m[t].nl, r += tm->m[t].nr;
	*nl = (uint32_t)l;
	*nr = (uint32_t)r;
	return l + r <= tm->job->rend - tm->job->rbegin;
}

static void decide(crew *tm, sbvh_split *obj, sbvh_split *best)
{
	run_phase(tm, PH_OBJECT);
	merge_bins(tm);
	sbvh_choose_object(tm->B, tm->job, &tm->m[0].bins, obj);
	*best = *obj;
	bool ahead = tm->job->end - tm->job->begin >= tm->B->opt.lookahead &&
	             obj->kind == SPLIT_OBJECT && sbvh_job_has_room(tm->job);
	if (ahead || sbvh_want_spatial(tm->B, tm->job, obj)) {
		sbvh_split sp = *obj;
		if (ahead) { /* the best spatial split whatever the object split's
		              * overlap and cost, for sbvh_lookahead to weigh */
			sp.kind = SPLIT_LEAF;
			sp.cost = INFINITY;
		}
		run_phase(tm, PH_SPATIAL);
		merge_bins(tm);
		sbvh_choose_spatial(tm->B, tm->job, &tm->m[0].bins, &sp);
		if (!ahead)
			*best = sp;
		else if (sp.kind == SPLIT_SPATIAL)
			*best = *sbvh_lookahead(tm->B, tm->job, obj, &sp, &tm->m[0].bins);
	}
	sbvh_choose_final(tm->B, tm->job, best);
	sbvh_choose_final(tm->B, tm->job, obj);
}

/* Splits a big job with the whole team; false if it became a leaf. */
static bool crew_split(crew *tm, const sbvh_job *job, sbvh_job *left, sbvh_job *right)
{
	uint32_t T = tm->B->threads, n = job->end - job->begin, nl, nr;
	sbvh_split obj, best;

	tm->job = job;
	for (uint32_t t = 0; t < T; t++) {
		tm->m[t].begin = job->begin + (uint32_t)((uint64_t)n * t / T);
		tm->m[t].end = job->begin + (uint32_t)((uint64_t)n * (t + 1) / T);
	}
	decide(tm, &obj, &best);
	if (best.kind != SPLIT_LEAF && !count_all(tm, &best, &nl, &nr)) {
		best = obj;
		if (best.kind != SPLIT_LEAF)
			count_all(tm, &best, &nl, &nr);
	}
	if (best.kind == SPLIT_LEAF) {
		sbvh_write_leaf(tm->B, job);
		return false;
	}
	if (best.kind == SPLIT_SPATIAL)
		atomic_fetch_add_explicit(&tm->B->spatial, 1, memory_order_relaxed);
	sbvh_make_children(tm->B, job, nl, nr, left, right);
	for (uint32_t t = 0, lo = left->begin, ro = right->begin; t < T; t++) {
		tm->m[t].lout = lo;
		tm->m[t].rout = ro;
		lo += tm->m[t].nl;
		ro += tm->m[t].nr;
	}
	run_phase(tm, PH_WRITE);
	for (uint32_t t = 0; t < T; t++) {
		unite_job(left, &tm->m[t].l);
		unite_job(right, &tm->m[t].r);
	}
	return true;
}

/* Largest first, so a big subtree does not start last. */
static int by_size(const void *a, const void *b)
{
	const sbvh_job *x = a, *y = b;
	uint32_t nx = x->end - x->begin, ny = y->end - y->begin;

	return (nx < ny) - (nx > ny);
}

/* The big jobs, breadth first with the whole team; the rest into `small`. */
static int top_phase(crew *tm, const sbvh_job *root, team_list *small)
{
	team_list big = TEAM_LIST(sbvh_job);
	size_t next = 0;
	int rc = team_list_push(&big, root);

	while (rc == 0 && next < big.n) {
		sbvh_job job = *TEAM_LIST_AT(&big, sbvh_job, next++), child[2];
		if (!crew_split(tm, &job, &child[0], &child[1]))
			continue;
		for (int c = 0; c < 2 && rc == 0; c++) {
			bool large = child[c].end - child[c].begin >= tm->B->opt.parallel_min;
			rc = team_list_push(large ? &big : small, &child[c]);
		}
	}
	team_list_free(&big);
	return rc;
}

typedef struct worker {
	sbvh_build *B;
	team_list *small;
	int rc;
	sbvh_bins bins;
} worker;

static void run_worker(void *arg, unsigned t)
{
	worker *w = (worker *)arg + t;
	size_t i;

	while (w->rc == 0 && team_list_claim(w->small, &i))
		w->rc = sbvh_build_subtree(w->B, TEAM_LIST_AT(w->small, sbvh_job, i), &w->bins);
}

/* The small jobs, claimed largest first by a team of the thread layer
 * (the caller alone when no team is to be had). */
static int task_phase(sbvh_build *B, team_list *small)
{
	uint32_t T = B->threads;
	worker *w = calloc(T, sizeof(*w));
	team tm;
	int rc = 0;

	if (!w)
		return -ENOMEM;
	team_list_order(small, by_size);
	for (uint32_t t = 0; t < T; t++)
		w[t] = (worker){ .B = B, .small = small };
	if (team_run_on(&tm, &B->th, T, run_worker, w) < 0)
		run_worker(w, 0);
	for (uint32_t t = 0; t < T; t++)
		rc = rc ? rc : w[t].rc;
	free(w);
	return rc;
}

int sbvh_build_all(sbvh_build *B, const sbvh_job *root)
{
	crew tm = { .B = B, .m = calloc(B->threads, sizeof(member)) };
	team_list small = TEAM_LIST(sbvh_job);
	int rc = tm.m ? 0 : -ENOMEM;

	for (uint32_t t = 0; rc == 0 && t < B->threads; t++)
		tm.m[t] = (member){ .crew = &tm, .t = t };
	if (rc == 0)
		rc = top_phase(&tm, root, &small);
	if (rc == 0)
		rc = task_phase(B, &small);
	free(tm.m);
	team_list_free(&small);
	return rc;
}
