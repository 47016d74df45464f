/*
 * The plugins' thread layer, a thin one over the host's executor (ABI 1.6,
 * core/exec): the threads are the process's pool, placed on the run's CPU
 * set and pinned by the host (`pin` means the same for every plugin), so
 * nothing here starts a thread. Two shapes:
 *   - a team: team_run_on runs one function on up to T threads at once,
 *     the calling thread as member 0, with a barrier (team_sync) between
 *     its phases (lbvh, ploc, sbvh, reinsert, treelet, refit, sah_queue,
 *     sah_tasks, the SAH kernel's input copy);
 *   - spawned tasks: team_spawn starts one function on a thread of the
 *     pool, team_join waits for it (sah_even, sah_uneven: a task per
 *     subtree).
 * With a host older than 1.6 the caller does all the work alone, which
 * every user allows. A static library linked into each plugin that uses it.
 */
#ifndef BVHLAB_TEAM_H
#define BVHLAB_TEAM_H

#include <pthread.h>
#include <stdatomic.h>
#include <stdbool.h>
#include <stdint.h>

#include <bvhlab/builder.h>

#define TEAM_MAX_THREADS 256

/* The build the threads work for: whose executor runs them. */
typedef struct team_host {
	const bvhlab_host *host;
	bvhlab_build_ctx *ctx;
} team_host;

/* Sets th up for one build. */
void team_host_init(team_host *th, const bvhlab_host *host, bvhlab_build_ctx *ctx);

/* How many CPUs the build may use (host->hardware_threads). */
uint32_t team_cpus(const team_host *th);

/* host->pin_thread(worker) where the host has it: binds the calling thread
 * to the worker's core when pinning is on, else nothing. Only the caller
 * of a scheduler that spawns tasks needs it (as worker 0): the executor
 * places a team's members and the tasks itself. */
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
 * Runs fn(arg, t) on up to `want` threads at once, t = 0 .. threads - 1,
 * the calling thread as 0, and returns when all have returned (their
 * writes are then visible). The team may be smaller than asked (the pool
 * could not give that many, or the host has no executor), so fn must not
 * depend on the size for its result; tm->threads is the size while it
 * runs. Barriers poll only while every member has a CPU of the build's.
 * 0 or a negative errno.
 */
int team_run_on(team *tm, const team_host *th, unsigned want,
                void (*fn)(void *arg, uint32_t t), void *arg);

/* A task started by team_spawn. */
typedef struct team_thread {
	const team_host *th;
	bvhlab_task task; /* the host's record */
	bool started;     /* must be joined */
} team_thread;

/*
 * Starts fn(arg) on a thread of the host's pool, placed as the build's
 * next worker. 0, or a negative errno with fn not run: the caller then
 * does the work itself (every scheduler stays correct with fewer threads).
 * *t must stay put until team_join.
 */
int team_spawn(team_host *th, team_thread *t, void (*fn)(void *arg), void *arg);

/* Waits for a started task (nothing for one that did not start); the
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
