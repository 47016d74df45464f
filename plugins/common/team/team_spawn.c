/*
 * Threads started one at a time (team_spawn, team_join) and the pinning
 * every thread of the layer does first thing (see team.h).
 */
#include <errno.h>

#include "team.h"

void team_host_init(team_host *th, const bvhlab_host *host, bvhlab_build_ctx *ctx)
{
	th->host = host;
	th->ctx = ctx;
	atomic_init(&th->next_worker, 1);
}

uint32_t team_cpus(const team_host *th)
{
	return th->host->hardware_threads(th->ctx);
}

/* A failed pin leaves the thread where it was: it still does its work. */
void team_pin(const team_host *th, uint32_t worker)
{
	if (BVHLAB_HOST_HAS(th->host, pin_thread))
		th->host->pin_thread(th->ctx, worker);
}

static void *spawned_main(void *arg)
{
	team_thread *t = arg;

	team_pin(t->th, t->worker);
	t->fn(t->arg);
	return NULL;
}

int team_spawn(team_host *th, team_thread *t, void (*fn)(void *arg), void *arg)
{
	pthread_attr_t attr;
	int rc = pthread_attr_init(&attr);

	*t = (team_thread){ .th = th, .fn = fn, .arg = arg };
	if (rc != 0)
		return -rc;
	rc = pthread_attr_setstacksize(&attr, TEAM_STACK);
	/* A thread that fails to start leaves a gap in the numbers (rare, and
	 * handing the number back could give it out twice). */
	t->worker = atomic_fetch_add_explicit(&th->next_worker, 1, memory_order_relaxed);
	if (rc == 0)
		rc = pthread_create(&t->tid, &attr, spawned_main, t);
	pthread_attr_destroy(&attr);
	t->started = rc == 0;
	return -rc;
}

void team_join(team_thread *t)
{
	if (t->started)
		pthread_join(t->tid, NULL);
	t->started = false;
}
