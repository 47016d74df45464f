/*
 * pin_probe's "executor" mode: the host table's executor (ABI 1.6) used
 * from inside a build, each operation's result compared with the same
 * work done on the calling thread; any difference fails the build naming
 * the operation. The data are the input's centroids, quantised.
 */
#include <errno.h>
#include <sched.h>
#include <stdatomic.h>
#include <stdlib.h>
#include <string.h>

#include "exec_probe.h"

struct probe {
	const bvhlab_build_input *in;
	uint32_t *v;       /* [n] a value per primitive */
	uint8_t *hits;     /* [n] for_each's coverage */
	uint32_t threads;
	atomic_uint bad;   /* for_each: a member out of range */
	atomic_uint arrived;
	atomic_uint seen[256];
	uint32_t members;
};

static uint32_t quantise(const bvhlab_build_input *in, uint32_t i)
{
	float x = in->centroids[3 * (size_t)i], lo = in->bounds.lo[0], hi = in->bounds.hi[0];
	return (uint32_t)((x - lo) / (hi > lo ? hi - lo : 1) * 1048575.0f) * 977u + i % 13u;
}

static void cover(void *arg, uint32_t lo, uint32_t hi, uint32_t member)
{
	struct probe *p = arg;
	if (member >= p->threads)
		atomic_fetch_add(&p->bad, 1);
	for (uint32_t i = lo; i < hi; i++)
		p->hits[i]++;
}

static void sum(void *arg, uint32_t lo, uint32_t hi, void *acc)
{
	const struct probe *p = arg;
	for (uint32_t i = lo; i < hi; i++)
		*(uint64_t *)acc += p->v[i];
}

static void join(void *arg, void *acc, const void *part)
{
	(void)arg;
	*(uint64_t *)acc += *(const uint64_t *)part;
}

static bool odd(void *arg, uint32_t v)
{
	(void)arg;
	return v & 1;
}

/* Every member waits for all: a team not all running at once never meets. */
static void meet(void *arg, uint32_t member)
{
	struct probe *p = arg;
	atomic_fetch_add(&p->seen[member & 255], 1);
	atomic_fetch_add(&p->arrived, 1);
	while (atomic_load(&p->arrived) < p->members)
		sched_yield();
}

static void half_sum(void *arg)
{
	struct probe *p = arg;
	uint64_t s = 0;
	sum(p, p->in->prim_count / 2, p->in->prim_count, &s);
	p->v[0] = (uint32_t)s; /* the task's result, read after join */
}

static bool check_ranges(const bvhlab_host *host, bvhlab_build_ctx *ctx, struct probe *p,
                         uint32_t n, uint32_t *a, uint32_t *b)
{
	uint64_t want = 0, got = 0;
	uint32_t total = 0, kept = 0, run = 0, k = 0;
	if (host->for_each(ctx, n, 0, cover, p) < 0 || atomic_load(&p->bad))
		return false;
	for (uint32_t i = 0; i < n; i++)
		if (p->hits[i] != 1)
			return false;
	sum(p, 0, n, &want);
	if (host->reduce(ctx, n, &got, sizeof(got), sum, join, p) < 0 || got != want)
		return false;
	for (uint32_t i = 0; i < n; run += p->v[i++])
		b[i] = run;
	if (host->scan(ctx, p->v, a, n, &total) < 0 || total != run ||
	    memcmp(a, b, n * sizeof(*a)) != 0)
		return false;
	for (int pass = 0; pass < 2; pass++)
		for (uint32_t i = 0; i < n; i++)
			if (odd(NULL, p->v[i]) == (pass == 0))
				b[k++] = p->v[i];
	return host->partition(ctx, p->v, a, n, odd, NULL, &kept) == 0 &&
	       memcmp(a, b, n * sizeof(*a)) == 0;
}

/* Sorted keys (v's low 30 bits) with their positions: ascending, ties in
 * their first order (stable), each key still with its own position. */
static bool check_sort(const bvhlab_host *host, bvhlab_build_ctx *ctx, struct probe *p,
                       uint32_t n, uint32_t *a)
{
	uint64_t *keys = malloc(n * sizeof(*keys));
	bool ok = keys != NULL;
	for (uint32_t i = 0; ok && i < n; i++) {
		keys[i] = p->v[i] & ((1u << 30) - 1);
		a[i] = i;
	}
	ok = ok && host->sort(ctx, keys, a, n, 30) == 0;
	for (uint32_t i = 1; ok && i < n; i++)
		ok = keys[i - 1] < keys[i] || (keys[i - 1] == keys[i] && a[i - 1] < a[i]);
	for (uint32_t i = 0; ok && i < n; i++)
		ok = keys[i] == (p->v[a[i]] & ((1u << 30) - 1));
	free(keys);
	return ok;
}

static const char *check_tasks(const bvhlab_host *host, bvhlab_build_ctx *ctx,
                               struct probe *p, uint32_t n)
{
	uint64_t want = 0;
	bvhlab_task task;
	p->members = p->threads;
	if (host->run(ctx, p->members, meet, p) < 0)
		return "run (refused a team of input->threads)";
	for (uint32_t t = 0; t < p->members && t < 256; t++)
		if (atomic_load(&p->seen[t]) != 1)
			return "run (a member ran other than once)";
	sum(p, n / 2, n, &want);
	if (host->spawn(ctx, &task, half_sum, p) < 0)
		half_sum(p);
	host->join(ctx, &task);
	return p->v[0] == (uint32_t)want ? NULL : "spawn/join";
}

int exec_probe(const bvhlab_host *host, bvhlab_build_ctx *ctx, const bvhlab_build_input *in)
{
	uint32_t n = in->prim_count;
	struct probe p = {.in = in, .threads = in->threads};
	uint32_t *a = malloc((n + 1) * sizeof(*a)), *b = malloc((n + 1) * sizeof(*b));
	const char *bad = NULL;
	p.v = malloc((n + 1) * sizeof(*p.v));
	p.hits = calloc(n + 1, 1);
	if (!BVHLAB_HOST_HAS(host, join))
		bad = "the host has no executor (ABI 1.6)";
	else if (!a || !b || !p.v || !p.hits)
		bad = "(out of memory)";
	for (uint32_t i = 0; !bad && i < n; i++)
		p.v[i] = quantise(in, i);
	if (!bad && !check_ranges(host, ctx, &p, n, a, b))
		bad = "for_each, reduce, scan or partition";
	if (!bad && !check_sort(host, ctx, &p, n, a))
		bad = "sort";
	if (!bad)
		bad = check_tasks(host, ctx, &p, n);
	if (bad)
		host->set_error(ctx, "executor: %s differs from the sequential result", bad);
	free(a);
	free(b);
	free(p.v);
	free(p.hits);
	return bad ? -EIO : 0;
}
