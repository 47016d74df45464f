/*
 * Tasks started one at a time (team_spawn, team_join) on the host's
 * executor, and the pinning of the calling thread (see team.h).
 */
#include <errno.h>

#include "team.h"

void team_host_init(team_host *th, const bvhlab_host *host, bvhlab_build_ctx *ctx)
{
	th->host = host;
	th->ctx = ctx;
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

/* A host without an executor (before ABI 1.6) gets the work done on the
 * calling thread, as when the pool has no thread to give. */
int team_spawn(team_host *th, team_thread *t, void (*fn)(void *arg), void *arg)
{
	t->th = th;
	t->started = false;
	if (!BVHLAB_HOST_HAS(th->host, join))
		return -ENOTSUP;
	int rc = th->host->spawn(th->ctx, &t->task, fn, arg);
	t->started = rc == 0;
	return rc;
}

void team_join(team_thread *t)
{
	if (t->started)
		t->th->host->join(t->th->ctx, &t->task);
	t->started = false;
}
