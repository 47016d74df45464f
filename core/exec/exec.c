/*
 * The executor's pool, teams and spawned tasks (see exec.h).
 *
 * A worker is a parked thread with a slot for one job; idle workers wait
 * on a stack. A team or a task takes idle workers (starting new ones only
 * when none is idle), fills their slots and wakes them; each worker goes
 * back on the stack before it reports its job done, so the next team of
 * the same size finds it idle again and the pool stays as large as the
 * most threads ever busy at once.
 */
#include <errno.h>
#include <stdlib.h>
#include <string.h>

#include <bvhlab/machine.h>

#include "exec/exec.h"

/* Workers at most: far above any team, a cap only on runaway spawning. */
#define MAX_WORKERS 4096

struct job {
	exec_member_fn fn;
	void *arg;
	uint32_t member; /* the member's (or task's) worker number */
	const struct exec_place *place;
	struct exec_latch *latch;
};

struct worker {
	pthread_t tid;
	pthread_mutex_t lock;
	pthread_cond_t wake;
	bool has_job;
	bool stop; /* leave worker_main: the process is ending */
	struct job job;
	cpu_set_t mask;          /* its affinity now: set again only on a change */
	struct worker *next_idle;
	struct worker *next_all; /* keeps every worker reachable */
};

static struct {
	pthread_mutex_t lock;
	struct worker *idle;
	struct worker *all;
	uint32_t count;
} pool = {.lock = PTHREAD_MUTEX_INITIALIZER};

static pthread_once_t fork_once = PTHREAD_ONCE_INIT;

/* A forked child (isolate.c) has none of the parent's threads: its pool
 * starts empty (the parent's workers' records stay, unused). */
static void forget_workers(void)
{
	pthread_mutex_init(&pool.lock, NULL);
	pool.idle = NULL;
	pool.count = 0;
}

static void stop_workers(void);

/* Once, at the pool's first use: atexit runs stop_workers before the
 * handlers registered earlier (LeakSanitizer's among them). */
static void register_fork(void)
{
	pthread_atfork(NULL, NULL, forget_workers);
	atexit(stop_workers);
}

/*
 * At exit() the idle workers are stopped and joined, so the process
 * ends with no thread of ours parked: LeakSanitizer's scan at exit
 * crashed on the parked pool ("Tracer caught signal 11", test-rays
 * under ASan). Only idle workers are taken: every task is joined before
 * its build returns, and a forked child's list is empty (forget_workers).
 */
static void stop_workers(void)
{
	pthread_mutex_lock(&pool.lock);
	struct worker *w = pool.idle;
	pool.idle = NULL;
	pthread_mutex_unlock(&pool.lock);
	for (; w; w = w->next_idle) {
		pthread_mutex_lock(&w->lock);
		w->stop = true;
		pthread_cond_signal(&w->wake);
		pthread_mutex_unlock(&w->lock);
		pthread_join(w->tid, NULL);
	}
}

/* ---- places ---------------------------------------------------------------- */

int exec_place_begin(struct exec_place *p)
{
	memset(p, 0, sizeof(*p));
	atomic_init(&p->next_worker, 1);
	int r = -pthread_getaffinity_np(pthread_self(), sizeof(p->mask), &p->mask);
	if (r == 0 && machine_pinning()) {
		r = pin_plan_init(&p->plan);
		p->pinning = r == 0;
	}
	if (r < 0)
		pin_plan_finish(&p->plan);
	return r;
}

void exec_place_end(struct exec_place *p)
{
	if (p->pinning)
		pthread_setaffinity_np(pthread_self(), sizeof(p->mask), &p->mask);
	pin_plan_finish(&p->plan);
	p->pinning = false;
}

uint32_t exec_place_cpus(const struct exec_place *p)
{
	/* A pinned caller's own mask holds one CPU; the plan holds the set the
	 * place began with, which is what the answer must describe. */
	return p->pinning ? p->plan.count : bvhlab_hardware_threads();
}

int exec_place_pin(const struct exec_place *p, uint32_t worker)
{
	return p->pinning ? pin_plan_apply(&p->plan, worker) : 0;
}

/* The worker's mask for member `member` of the place. */
static void place_mask(const struct exec_place *p, uint32_t member, cpu_set_t *out)
{
	if (!p->pinning) {
		*out = p->mask;
		return;
	}
	CPU_ZERO(out);
	CPU_SET(p->plan.cpu[member % p->plan.count], out);
}

/* ---- latches ------------------------------------------------------------- */

static void latch_init(struct exec_latch *l, uint32_t count)
{
	pthread_mutex_init(&l->lock, NULL);
	pthread_cond_init(&l->done, NULL);
	l->left = count;
}

/* Signalled under the lock: the waiter cannot leave (and free the latch)
 * before this thread has let go of it. */
static void latch_count_down(struct exec_latch *l)
{
	pthread_mutex_lock(&l->lock);
	if (--l->left == 0)
		pthread_cond_broadcast(&l->done);
	pthread_mutex_unlock(&l->lock);
}

static void latch_wait(struct exec_latch *l)
{
	pthread_mutex_lock(&l->lock);
	while (l->left > 0)
		pthread_cond_wait(&l->done, &l->lock);
	pthread_mutex_unlock(&l->lock);
	pthread_cond_destroy(&l->done);
	pthread_mutex_destroy(&l->lock);
}

/* ---- workers ------------------------------------------------------------- */

static void take_place(struct worker *w, const struct job *job)
{
	cpu_set_t want;
	place_mask(job->place, job->member, &want);
	/* Bound again at every job when pinning, as pin_thread binds every
	 * member; an unpinned worker only when its set changes. A failed call
	 * leaves the worker where it was: it still does its work. */
	if ((job->place->pinning || !CPU_EQUAL(&want, &w->mask)) &&
	    pthread_setaffinity_np(pthread_self(), sizeof(want), &want) == 0)
		w->mask = want;
}

static void go_idle(struct worker *w)
{
	pthread_mutex_lock(&pool.lock);
	w->next_idle = pool.idle;
	pool.idle = w;
	pthread_mutex_unlock(&pool.lock);
}

static void *worker_main(void *p)
{
	struct worker *w = p;
	for (;;) {
		pthread_mutex_lock(&w->lock);
		while (!w->has_job && !w->stop)
			pthread_cond_wait(&w->wake, &w->lock);
		if (w->stop) {
			pthread_mutex_unlock(&w->lock);
			return NULL;
		}
		struct job job = w->job;
		w->has_job = false;
		pthread_mutex_unlock(&w->lock);
		take_place(w, &job);
		job.fn(job.arg, job.member);
		go_idle(w);
		latch_count_down(job.latch);
	}
	return NULL;
}

static struct worker *start_worker(void)
{
	struct worker *w = calloc(1, sizeof(*w));
	pthread_attr_t attr;
	if (!w)
		return NULL;
	pthread_mutex_init(&w->lock, NULL);
	pthread_cond_init(&w->wake, NULL);
	bool started = false;
	if (pthread_attr_init(&attr) == 0) {
		started = pthread_attr_setstacksize(&attr, EXEC_STACK) == 0 &&
		          pthread_create(&w->tid, &attr, worker_main, w) == 0;
		pthread_attr_destroy(&attr);
	}
	/* An unread mask only costs one setaffinity at the first job. */
	if (started && pthread_getaffinity_np(w->tid, sizeof(w->mask), &w->mask) != 0)
		CPU_ZERO(&w->mask);
	if (started) {
		pthread_mutex_lock(&pool.lock);
		w->next_all = pool.all;
		pool.all = w;
		pthread_mutex_unlock(&pool.lock);
		return w;
	}
	pthread_cond_destroy(&w->wake);
	pthread_mutex_destroy(&w->lock);
	free(w);
	return NULL;
}

/* An idle worker, or a new one; NULL when neither can be had. */
static struct worker *acquire(void)
{
	pthread_once(&fork_once, register_fork);
	pthread_mutex_lock(&pool.lock);
	struct worker *w = pool.idle;
	bool room = pool.count < MAX_WORKERS;
	if (w)
		pool.idle = w->next_idle;
	else if (room)
		pool.count++; /* reserved now, so racing callers respect the cap */
	pthread_mutex_unlock(&pool.lock);
	if (w || !room)
		return w;
	if (!(w = start_worker())) {
		pthread_mutex_lock(&pool.lock);
		pool.count--;
		pthread_mutex_unlock(&pool.lock);
	}
	return w;
}

static void hand(struct worker *w, const struct job *job)
{
	pthread_mutex_lock(&w->lock);
	w->job = *job;
	w->has_job = true;
	pthread_cond_signal(&w->wake);
	pthread_mutex_unlock(&w->lock);
}

/* ---- teams and tasks --------------------------------------------------------- */

int exec_run(const struct exec_place *p, uint32_t members, exec_member_fn fn, void *arg)
{
	struct worker *w[EXEC_MAX_MEMBERS];
	struct exec_latch latch;
	uint32_t got = 1;
	if (members > EXEC_MAX_MEMBERS)
		return -EAGAIN;
	members = members ? members : 1; /* 0 members: the caller's alone */
	for (; got < members && (w[got] = acquire()) != NULL; got++)
		;
	if (got < members) {
		while (got > 1)
			go_idle(w[--got]);
		return -EAGAIN;
	}
	latch_init(&latch, members - 1);
	for (uint32_t t = 1; t < members; t++)
		hand(w[t], &(struct job){fn, arg, t, p, &latch});
	exec_place_pin(p, 0);
	fn(arg, 0);
	latch_wait(&latch);
	return 0;
}

uint32_t exec_run_some(const struct exec_place *p, uint32_t want, exec_member_fn fn,
                       void *arg)
{
	want = want < 1 ? 1 : want > EXEC_MAX_MEMBERS ? EXEC_MAX_MEMBERS : want;
	while (want > 1 && exec_run(p, want, fn, arg) == -EAGAIN)
		want /= 2;
	if (want <= 1) {
		exec_place_pin(p, 0);
		fn(arg, 0);
		return 1;
	}
	return want;
}

static void task_main(void *arg, uint32_t member)
{
	struct exec_task *t = arg;
	(void)member;
	t->fn(t->arg);
}

int exec_spawn(struct exec_place *p, struct exec_task *t, void (*fn)(void *arg), void *arg)
{
	struct worker *w = acquire();
	*t = (struct exec_task){.fn = fn, .arg = arg};
	if (!w)
		return -EAGAIN;
	latch_init(&t->latch, 1);
	t->started = true;
	uint32_t number = atomic_fetch_add_explicit(&p->next_worker, 1, memory_order_relaxed);
	hand(w, &(struct job){task_main, t, number, p, &t->latch});
	return 0;
}

void exec_join(struct exec_task *t)
{
	if (t->started)
		latch_wait(&t->latch);
	t->started = false;
}
