/*
 * The process's executor: one pool of worker threads, started as they are
 * first needed and kept for the life of the process, under every parallel
 * part of bvhlab: the builders (through the host table, ABI 1.6, and
 * plugins/common/team), the ray batches, validation's rays and refit.
 *
 * Where the threads of a call run is a place (struct exec_place), taken
 * from the calling thread when a build, a ray batch or a validation
 * begins: the run's CPU set (its affinity mask, which taskset, a cgroup
 * cpuset or the caller narrow) and, when pinning is on (bvhlab_set_pinning),
 * the pin plan over that set's physical cores. A worker given a task takes
 * the place's affinity first (member t of a team, or a spawned task's
 * number, bound to the plan's CPU t when pinning; the whole set otherwise),
 * so a worker that last served another run with another set never runs
 * outside this one's.
 *
 * Nothing is allocated per task: a team's and a task's bookkeeping live in
 * the caller's frame, and a worker is created only when none is idle.
 * exec.c is the pool, teams and spawned tasks; exec_ops.c for_each and
 * reduce; exec_scan.c scan, partition and sort.
 */
#ifndef BVHLAB_CORE_EXEC_H
#define BVHLAB_CORE_EXEC_H

#include <pthread.h>
#include <sched.h>
#include <stdatomic.h>
#include <stdbool.h>
#include <stddef.h>
#include <stdint.h>

#include "machine/machine.h"

/* Members of one team at most (the caller included). */
#define EXEC_MAX_MEMBERS 256

/*
 * Every worker's stack: the SAH kernel's binned split keeps ~30 KB of bins
 * on the stack and schedulers may recurse a few levels around it; 8 MiB
 * matches the usual main-thread stack, so nothing is safe there that would
 * fail on a worker.
 */
#define EXEC_STACK (8u << 20)

struct exec_place {
	cpu_set_t mask;          /* the calling thread's mask at exec_place_begin */
	bool pinning;            /* plan is set: workers are bound one CPU each */
	struct pin_plan plan;
	atomic_uint next_worker; /* numbers of spawned tasks (a team's are 0 .. n-1) */
};

/* The place of the calling thread (and the pin plan when pinning is on).
 * 0, or a negative errno when the mask or the plan cannot be had. */
int exec_place_begin(struct exec_place *p);
/* Gives the calling thread its mask back when pinning bound it; frees the
 * plan. Safe on a place whose begin failed. */
void exec_place_end(struct exec_place *p);
/* The CPUs the place offers, as a thread count: its physical cores. */
uint32_t exec_place_cpus(const struct exec_place *p);
/* Binds the calling thread as worker `worker` when the place pins (the
 * plan's CPU worker % count); nothing otherwise. 0 or a negative errno. */
int exec_place_pin(const struct exec_place *p, uint32_t worker);

typedef void (*exec_member_fn)(void *arg, uint32_t member);

/*
 * Runs fn(arg, t) for t = 0 .. members - 1 at the same time, the calling
 * thread as member 0 (pinned as worker 0 when the place pins), and returns
 * when all have returned; their writes are then visible to the caller.
 * All members run at once, so they may wait for each other (a barrier).
 * 0, or -EAGAIN with nothing run when that many threads cannot be had.
 * 0 members is the caller alone, as 1.
 */
int exec_run(const struct exec_place *p, uint32_t members, exec_member_fn fn, void *arg);

/* exec_run with as many of `want` members as can be had (halving on
 * -EAGAIN, down to the caller alone); returns the team size used. */
uint32_t exec_run_some(const struct exec_place *p, uint32_t want, exec_member_fn fn,
                       void *arg);

/* The completion of a team or a task, in the waiter's frame. */
struct exec_latch {
	pthread_mutex_t lock;
	pthread_cond_t done;
	uint32_t left;
};

/* A task started by exec_spawn; the caller's, until exec_join. */
struct exec_task {
	struct exec_latch latch;
	void (*fn)(void *arg);
	void *arg;
	bool started; /* on a worker, to be joined */
};

/*
 * Starts fn(arg) on a worker that first takes the place's affinity as the
 * place's next spawned number. 0, or -EAGAIN with fn not run (the caller
 * then does the work itself). *t must stay put until exec_join.
 */
int exec_spawn(struct exec_place *p, struct exec_task *t, void (*fn)(void *arg), void *arg);

/* Waits for a started task (nothing for one that did not start); its
 * writes are then visible to the caller. */
void exec_join(struct exec_task *t);

/* ---- operations over [0, count) (exec_ops.c, exec_scan.c) --------------- */

/* Items per member below which an operation stays on fewer threads. */
#define EXEC_MIN_ITEMS 4096

/* The shares reduce, scan, partition and sort split `count` items into:
 * one per thread asked for, EXEC_MIN_ITEMS each at least. */
static inline uint32_t exec_shares(uint32_t threads, uint32_t count)
{
	uint32_t most = count / EXEC_MIN_ITEMS;
	threads = threads < most ? threads : most;
	return threads < 1 ? 1 : threads > EXEC_MAX_MEMBERS ? EXEC_MAX_MEMBERS : threads;
}

/* The [lo, hi) of share k of n over `count` items. */
static inline void exec_share(uint32_t count, uint32_t n, uint32_t k, uint32_t *lo,
                              uint32_t *hi)
{
	*lo = (uint32_t)((uint64_t)count * k / n);
	*hi = (uint32_t)((uint64_t)count * (k + 1) / n);
}

/*
 * fn(arg, lo, hi, member) over ranges that cover [0, count) once, none
 * longer than grain (0: count / threads), handed to whichever of up to
 * `threads` members asks first. 0, or -EINVAL for count > 0 without fn.
 */
int exec_for_each(const struct exec_place *p, uint32_t threads, uint32_t count,
                  uint32_t grain,
                  void (*fn)(void *arg, uint32_t lo, uint32_t hi, uint32_t member),
                  void *arg);

/*
 * Each of up to `threads` members reduces a fixed, contiguous share of
 * [0, count) with fn into its own copy of *acc (which must hold the
 * identity of join, `size` bytes), then the copies are joined into *acc in
 * member order: the result depends on the thread count only as far as
 * join is not associative. 0 or -ENOMEM.
 */
int exec_reduce(const struct exec_place *p, uint32_t threads, uint32_t count, void *acc,
                size_t size, void (*fn)(void *arg, uint32_t lo, uint32_t hi, void *acc),
                void (*join)(void *arg, void *acc, const void *part), void *arg);

/* Exclusive prefix sums of in[0 .. count) into out (may be in); *total the
 * sum of all (uint32 arithmetic, wrapping as a sequential loop would).
 * The same for every thread count. */
int exec_scan(const struct exec_place *p, uint32_t threads, const uint32_t *in, uint32_t *out,
              uint32_t count, uint32_t *total);

/* Stable partition of in[0 .. count) into out (not in): the values pred
 * holds for first, in order, then the others; *kept how many held. The
 * same for every thread count. 0 or -EINVAL (out == in). */
int exec_partition(const struct exec_place *p, uint32_t threads, const uint32_t *in,
                   uint32_t *out, uint32_t count, bool (*pred)(void *arg, uint32_t v),
                   void *arg, uint32_t *kept);

/* Sorts keys[0 .. count), each below 2^key_bits (key_bits 1 to 64: the
 * passes it takes), ascending, carrying values (may be NULL) along;
 * stable, so the same for every thread count. 0, -EINVAL or -ENOMEM (its
 * scratch). */
int exec_sort(const struct exec_place *p, uint32_t threads, uint64_t *keys, uint32_t *values,
              uint32_t count, uint32_t key_bits);

#endif
