/*
 * The executor's operations over ranges (see exec.h): for_each hands out
 * blocks from one counter. reduce, scan, partition and sort split the
 * range into a fixed number of shares, each with its own result slot, and
 * hand the shares out the same way: their results (bar a non-associative
 * join) do not depend on which thread did which share, nor on how many
 * threads the pool could give.
 */
#include <errno.h>
#include <stdlib.h>
#include <string.h>

#include "exec/exec.h"

/* ---- for_each ------------------------------------------------------------- */

struct each {
	void (*fn)(void *arg, uint32_t lo, uint32_t hi, uint32_t member);
	void *arg;
	uint32_t count, grain;
	atomic_uint next; /* blocks handed out */
};

static void each_member(void *arg, uint32_t t)
{
	struct each *e = arg;
	uint64_t lo;
	while ((lo = (uint64_t)atomic_fetch_add_explicit(&e->next, 1, memory_order_relaxed) *
	             e->grain) < e->count) {
		uint64_t hi = lo + e->grain < e->count ? lo + e->grain : e->count;
		e->fn(e->arg, (uint32_t)lo, (uint32_t)hi, t);
	}
}

int exec_for_each(const struct exec_place *p, uint32_t threads, uint32_t count,
                  uint32_t grain,
                  void (*fn)(void *arg, uint32_t lo, uint32_t hi, uint32_t member),
                  void *arg)
{
	if (count == 0)
		return 0;
	if (!fn)
		return -EINVAL;
	threads = threads < 1 ? 1 : threads > EXEC_MAX_MEMBERS ? EXEC_MAX_MEMBERS : threads;
	if (grain == 0)
		grain = count / threads > 0 ? count / threads : 1;
	uint32_t blocks = (uint32_t)(((uint64_t)count + grain - 1) / grain);
	struct each e = {.fn = fn, .arg = arg, .count = count, .grain = grain};
	atomic_init(&e.next, 0);
	exec_run_some(p, threads < blocks ? threads : blocks, each_member, &e);
	return 0;
}

/* ---- reduce ----------------------------------------------------------------- */

struct reduction {
	void (*fn)(void *arg, uint32_t lo, uint32_t hi, void *acc);
	void *arg;
	unsigned char *parts; /* [shares][size] */
	size_t size;
	uint32_t count, shares;
};

/* Shares [a, b) of the reduction: the shares are handed out as the
 * items of a for_each, one at a time. */
static void reduce_shares(void *arg, uint32_t a, uint32_t b, uint32_t member)
{
	struct reduction *r = arg;
	(void)member;
	for (uint32_t k = a; k < b; k++) {
		uint32_t lo, hi;
		exec_share(r->count, r->shares, k, &lo, &hi);
		r->fn(r->arg, lo, hi, r->parts + (size_t)k * r->size);
	}
}

int exec_reduce(const struct exec_place *p, uint32_t threads, uint32_t count, void *acc,
                size_t size, void (*fn)(void *arg, uint32_t lo, uint32_t hi, void *acc),
                void (*join)(void *arg, void *acc, const void *part), void *arg)
{
	unsigned char stack[4096];
	uint32_t n = exec_shares(threads, count);
	if (n == 1 || size == 0) {
		fn(arg, 0, count, acc);
		return 0;
	}
	struct reduction r = {.fn = fn, .arg = arg, .size = size, .count = count, .shares = n};
	r.parts = (size_t)n * size <= sizeof(stack) ? stack : malloc((size_t)n * size);
	if (!r.parts)
		return -ENOMEM;
	for (uint32_t k = 0; k < n; k++)
		memcpy(r.parts + (size_t)k * size, acc, size);
	exec_for_each(p, n, n, 1, reduce_shares, &r);
	memcpy(acc, r.parts, size);
	for (uint32_t k = 1; k < n; k++)
		join(arg, acc, r.parts + (size_t)k * size);
	if (r.parts != stack)
		free(r.parts);
	return 0;
}
