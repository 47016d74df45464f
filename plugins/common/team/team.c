/* The thread team and its barrier (see team.h); spawned threads and
 * pinning are team_spawn.c. */
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

/* Holds the started threads until the team size is known. */
struct gate {
	pthread_mutex_t lock;
	pthread_cond_t cond;
	bool open;
};

struct member {
	struct gate *gate;
	const team_host *th; /* NULL: team_run, no pinning */
	void (*fn)(void *arg, unsigned t);
	void *arg;
	unsigned t;
	pthread_t tid;
};

static void *member_main(void *p)
{
	struct member *m = p;

	if (m->th)
		team_pin(m->th, m->t);
	pthread_mutex_lock(&m->gate->lock);
	while (!m->gate->open)
		pthread_cond_wait(&m->gate->cond, &m->gate->lock);
	pthread_mutex_unlock(&m->gate->lock);
	m->fn(m->arg, m->t);
	return NULL;
}

static void open_gate(struct gate *gate)
{
	pthread_mutex_lock(&gate->lock);
	gate->open = true;
	pthread_cond_broadcast(&gate->cond);
	pthread_mutex_unlock(&gate->lock);
}

static void set_size(team *tm, unsigned threads, uint32_t cpus)
{
	tm->threads = threads;
	/* Polling only pays while every thread has a CPU of its own. */
	tm->spins = threads <= cpus ? BARRIER_SPINS : 0;
}

int team_barrier_init(team *tm, unsigned threads, uint32_t cpus)
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

void team_barrier_finish(team *tm)
{
	pthread_cond_destroy(&tm->wake);
	pthread_mutex_destroy(&tm->lock);
}

static int start_member(struct member *m)
{
	pthread_attr_t attr;
	int rc = pthread_attr_init(&attr);

	if (rc != 0)
		return -rc;
	rc = pthread_attr_setstacksize(&attr, TEAM_STACK);
	if (rc == 0)
		rc = pthread_create(&m->tid, &attr, member_main, m);
	pthread_attr_destroy(&attr);
	return -rc;
}

/* Joining the members is what makes their writes visible to the caller. */
static int run_team(team *tm, const team_host *th, unsigned want, uint32_t cpus,
                    void (*fn)(void *arg, unsigned t), void *arg)
{
	struct member m[TEAM_MAX_THREADS];
	struct gate gate = { PTHREAD_MUTEX_INITIALIZER, PTHREAD_COND_INITIALIZER, false };
	unsigned size = 1;
	int rc;

	want = want > TEAM_MAX_THREADS ? TEAM_MAX_THREADS : want ? want : 1;
	/* The size is set again below, once it is known. */
	if ((rc = team_barrier_init(tm, want, cpus)) < 0)
		return rc;
	for (; size < want; size++) {
		m[size] = (struct member){ .gate = &gate, .th = th, .fn = fn, .arg = arg,
		                           .t = size };
		if (start_member(&m[size]) < 0)
			break;
	}
	set_size(tm, size, cpus);
	if (th)
		team_pin(th, 0);
	open_gate(&gate);
	fn(arg, 0);
	for (unsigned t = 1; t < size; t++)
		pthread_join(m[t].tid, NULL);
	team_barrier_finish(tm);
	return 0;
}

int team_run(team *tm, unsigned want, uint32_t cpus, void (*fn)(void *arg, unsigned t),
             void *arg)
{
	return run_team(tm, NULL, want, cpus, fn, arg);
}

int team_run_on(team *tm, const team_host *th, unsigned want,
                void (*fn)(void *arg, unsigned t), void *arg)
{
	return run_team(tm, th, want, team_cpus(th), fn, arg);
}
