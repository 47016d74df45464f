/*
 * A team of threads running one function together, with a barrier
 * between its phases: what lbvh and ploc run their phases on. The calling
 * thread is member 0; members are started once per build and joined at
 * its end. A static library linked into each plugin that uses it.
 */
#ifndef BVHLAB_TEAM_H
#define BVHLAB_TEAM_H

#include <pthread.h>
#include <stdatomic.h>
#include <stdbool.h>
#include <stdint.h>

#define TEAM_MAX_THREADS 256

typedef struct team {
	unsigned threads;      /* team size T, set by team_run() */
	atomic_uint arrived;   /* threads at the barrier this round */
	atomic_uint round;     /* rounds completed */
	unsigned spins;        /* polls before sleeping; 0 when oversubscribed */
	pthread_mutex_t lock;  /* guards the sleep on `wake` */
	pthread_cond_t wake;
} team;

/* Waits for the whole team: everything written before by any member is
 * visible to every member after. */
void team_sync(team *tm);

/*
 * Sets up the barrier alone, for a caller that starts and joins its own
 * threads (sah_tasks): `threads` members meet at team_sync; they poll
 * before sleeping only while threads <= cpus. 0 or a negative errno.
 */
int team_barrier_init(team *tm, unsigned threads, uint32_t cpus);
void team_barrier_finish(team *tm);

/*
 * Runs fn(arg, t) on up to `want` threads, t = 0 .. threads - 1, the
 * calling thread as 0, and returns when all have returned. A thread that
 * cannot be started only makes the team smaller, so fn must not depend
 * on the size for its result. `cpus` is how many CPUs the build may use
 * (barriers poll only while every member has one). 0 or a negative errno.
 */
int team_run(team *tm, unsigned want, uint32_t cpus, void (*fn)(void *arg, unsigned t),
             void *arg);

/* The [lo, hi) share of member t of `count` items. */
static inline void team_chunk(unsigned threads, unsigned t, uint32_t count, uint32_t *lo,
                              uint32_t *hi)
{
	*lo = (uint32_t)((uint64_t)count * t / threads);
	*hi = (uint32_t)((uint64_t)count * (t + 1) / threads);
}

/*
 * Hands out the next block of `size` of `count` items, [lo, hi), to
 * whichever thread asks first; false when none is left. For work whose
 * result does not depend on who does which part: a thread that runs
 * slowly (another process on its CPU) then holds the team up at the next
 * barrier by one block, not by a whole share.
 */
static inline bool team_next_block(atomic_uint *next, uint32_t count, uint32_t size,
                                   uint32_t *lo, uint32_t *hi)
{
	uint64_t first = (uint64_t)atomic_fetch_add_explicit(next, 1, memory_order_relaxed) * size;

	if (first >= count)
		return false;
	*lo = (uint32_t)first;
	*hi = count - *lo < size ? count : *lo + size;
	return true;
}

#endif /* BVHLAB_TEAM_H */
