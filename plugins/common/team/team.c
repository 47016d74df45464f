/* The thread team and its barrier (see team.h), on the host's executor;
 * spawned tasks are team_spawn.c. */
#include <errno.h>

#include "team.h"

/* Polls of a waiting thread before it sleeps: some tens of microseconds,
 * more than the usual skew between threads at a phase end, less than the
 * cost of putting a thread to sleep and waking it again, which in a VM is
 * itself tens of microseconds, paid at every barrier. */
#define BARRIER_SPINS 1024

static inline void cpu_relax(void)
{
#if defined(__x86_64__) || defined(__i386__)
	__builtin_ia32_pause();
#endif
}

/*
 * The last thread to arrive opens the next round. Its acq_rel fetch_add
 * reads the counter's release sequence, so it has acquired everyone's
 * writes; its release store of `round` passes them all on to every thread
 * that sees the new round. The others poll, then sleep on the condition
 * variable, whose mutex the last thread takes before it bumps the round,
 * so that no wake-up is lost.
 */
void team_sync(team *tm)
{
	unsigned round = atomic_load_explicit(&tm->round, memory_order_relaxed);

	if (atomic_fetch_add_explicit(&tm->arrived, 1, memory_order_acq_rel) + 1 == tm->threads) {
		atomic_store_explicit(&tm->arrived, 0, memory_order_relaxed);
		pthread_mutex_lock(&tm->lock);
		atomic_store_explicit(&tm->round, round + 1, memory_order_release);
		pthread_cond_broadcast(&tm->wake);
		pthread_mutex_unlock(&tm->lock);
		return;
	}
	for (unsigned k = 0; k < tm->spins; k++) {
		if (atomic_load_explicit(&tm->round, memory_order_acquire) != round)
			return;
		cpu_relax();
	}
	pthread_mutex_lock(&tm->lock);
	while (atomic_load_explicit(&tm->round, memory_order_acquire) == round)
		pthread_cond_wait(&tm->wake, &tm->lock);
	pthread_mutex_unlock(&tm->lock);
}

static void set_size(team *tm, unsigned threads, uint32_t cpus)
{
	tm->threads = threads;
	/* Polling only pays while every thread has a CPU of its own. */
	tm->spins = threads <= cpus ? BARRIER_SPINS : 0;
}

static int team_barrier_init(team *tm, unsigned threads, uint32_t cpus)
{
	int rc;

	atomic_init(&tm->arrived, 0);
	atomic_init(&tm->round, 0);
	set_size(tm, threads, cpus);
	if ((rc = pthread_mutex_init(&tm->lock, NULL)) != 0)
		return -rc;
	if ((rc = pthread_cond_init(&tm->wake, NULL)) != 0) {
		pthread_mutex_destroy(&tm->lock);
		return -rc;
	}
	return 0;
}

static void team_barrier_finish(team *tm)
{
	pthread_cond_destroy(&tm->wake);
	pthread_mutex_destroy(&tm->lock);
}

/*
 * The host's executor runs the members (ABI 1.6: its pool's threads, placed
 * and pinned by the host), all at once as the barrier needs. A team it
 * cannot give whole is asked for again at half the size; a host without
 * an executor runs the caller alone, which every team function allows.
 */
int team_run_on(team *tm, const team_host *th, unsigned want,
                void (*fn)(void *arg, unsigned t), void *arg)
{
	uint32_t cpus = team_cpus(th);
	bool pool = BVHLAB_HOST_HAS(th->host, join);
	int rc;

	want = want > TEAM_MAX_THREADS ? TEAM_MAX_THREADS : want ? want : 1;
	if ((rc = team_barrier_init(tm, want, cpus)) < 0)
		return rc;
	for (; pool && want > 1; want /= 2) {
		set_size(tm, want, cpus);
		if ((rc = th->host->run(th->ctx, want, fn, arg)) != -EAGAIN)
			break;
	}
	if (!pool || want <= 1) {
		set_size(tm, 1, cpus);
		team_pin(th, 0);
		fn(arg, 0);
		rc = 0;
	}
	team_barrier_finish(tm);
	return rc < 0 ? rc : 0;
}
