/*
 * The plugins' thread layer: every thread a plugin starts is started here,
 * with a stack big enough for the SAH kernel, and pins itself through
 * host->pin_thread first thing (a no-op unless the user asked for
 * pinning), so `pin` means the same for every plugin. Two shapes:
 *   - a team: team_run_on runs one function on up to T threads, the
 *     calling thread as member 0, with a barrier (team_sync) between its
 *     phases (lbvh, ploc, sbvh, reinsert, treelet, sah_queue, sah_tasks,
 *     the SAH kernel's input copy);
 *   - spawned threads: team_spawn starts one function on a thread of its
 *     own, team_join waits for it (sah_even, sah_uneven: a thread per
 *     subtree).
 * Members are numbered 0 .. T-1 for pin_thread (a team by member index,
 * spawned threads by a counter in team_host). A static library linked
 * into each plugin that uses it.
 */
#ifndef BVHLAB_TEAM_H
#define BVHLAB_TEAM_H

#include <pthread.h>
#include <stdatomic.h>
#include <stdbool.h>
#include <stdint.h>

#include <bvhlab/builder.h>

#define TEAM_MAX_THREADS 256

/*
 * Every thread's stack: the SAH kernel's binned split keeps ~30 KB of bins
 * on the stack and schedulers may recurse a few levels around it; 8 MiB
 * matches the usual main-thread stack, so nothing is safe there that would
 * fail here.
 */
#define TEAM_STACK (8u << 20)

/* The build the threads work for: where they pin themselves. */
typedef struct team_host {
	const bvhlab_host *host;
	bvhlab_build_ctx *ctx;
	atomic_uint next_worker; /* team_spawn's numbers; 0 is the caller's */
} team_host;

/* Sets th up for one build; the calling thread is worker 0. */
void team_host_init(team_host *th, const bvhlab_host *host, bvhlab_build_ctx *ctx);

/* How many CPUs the build may use (host->hardware_threads). */
uint32_t team_cpus(const team_host *th);

/* host->pin_thread(worker) where the host has it: binds the calling thread
 * to the worker's core when pinning is on, else nothing. */
void team_pin(const team_host *th, uint32_t worker);

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

/*
 * team_run for a build: the CPUs come from the host, and every member
 * pins itself as worker t first (the caller too, as 0). 0 or a negative
 * errno.
 */
int team_run_on(team *tm, const team_host *th, unsigned want,
                void (*fn)(void *arg, unsigned t), void *arg);

/* A thread started by team_spawn. */
typedef struct team_thread {
	team_host *th;
	void (*fn)(void *arg);
	void *arg;
	uint32_t worker;
	pthread_t tid;
	bool started; /* must be joined */
} team_thread;

/*
 * Starts fn(arg) on a new thread that pins itself as the next worker
 * number. 0, or a negative errno with fn not run: the caller then does
 * the work itself (every scheduler stays correct with fewer threads).
 * *t must stay put until team_join.
 */
int team_spawn(team_host *th, team_thread *t, void (*fn)(void *arg), void *arg);

/* Waits for a started thread (nothing for one that did not start); the
 * join makes its writes visible to the caller. */
void team_join(team_thread *t);

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
