/*
 * Counts the threads a build starts and the CPUs each may run on, for the
 * peer plugins' tests (test-peers.c). The test executable defines
 * pthread_create itself and is linked with --export-dynamic, so the
 * std::threads the libraries start inside the plugin (libstdc++ calls
 * pthread_create) come through here first; this wrapper notes the new
 * thread's affinity mask from inside it and hands over to the real
 * pthread_create (dlsym RTLD_NEXT: glibc's, or a sanitizer's interceptor).
 * Include it in one file only.
 */
#ifndef BVHLAB_TEST_PEER_THREADS_H
#define BVHLAB_TEST_PEER_THREADS_H

#include <dlfcn.h>
#include <errno.h>
#include <pthread.h>
#include <sched.h>
#include <stdatomic.h>
#include <stdlib.h>

typedef int (*pthread_create_fn)(pthread_t *, const pthread_attr_t *, void *(*)(void *),
                                 void *);

/* What the threads started since peer_threads_reset() did. */
static atomic_uint peer_started;  /* threads started */
static atomic_uint peer_most_cpus; /* the most CPUs one of them was allowed */

/* Every thread started, never reset (test-exec-affinity.c reads the
 * executor's workers' masks after a call through these). */
#define PEER_MAX_TIDS 64
static pthread_t peer_tids[PEER_MAX_TIDS];
static atomic_uint peer_tid_count;

void peer_threads_reset(void);
void peer_threads_reset(void)
{
	atomic_store(&peer_started, 0);
	atomic_store(&peer_most_cpus, 0);
}

typedef struct trampoline {
	void *(*fn)(void *);
	void *arg;
} trampoline;

static void *peer_thread_start(void *p)
{
	trampoline t = *(trampoline *)p;
	cpu_set_t set;
	unsigned k = atomic_fetch_add(&peer_tid_count, 1);
	free(p);
	if (k < PEER_MAX_TIDS)
		peer_tids[k] = pthread_self();
	if (sched_getaffinity(0, sizeof(set), &set) == 0) {
		unsigned n = (unsigned)CPU_COUNT(&set), most = atomic_load(&peer_most_cpus);
		while (n > most && !atomic_compare_exchange_weak(&peer_most_cpus, &most, n))
			;
	}
	return t.fn(t.arg);
}

int pthread_create(pthread_t *thread, const pthread_attr_t *attr, void *(*fn)(void *),
                   void *arg);
int pthread_create(pthread_t *thread, const pthread_attr_t *attr, void *(*fn)(void *),
                   void *arg)
{
	static pthread_create_fn real;
	if (!real)
		*(void **)&real = dlsym(RTLD_NEXT, "pthread_create");
	if (!real)
		return EAGAIN;
	trampoline *t = malloc(sizeof(*t));
	if (!t)
		return EAGAIN;
	*t = (trampoline){fn, arg};
	atomic_fetch_add(&peer_started, 1);
	int rc = real(thread, attr, peer_thread_start, t);
	if (rc != 0) {
		atomic_fetch_sub(&peer_started, 1);
		free(t);
	}
	return rc;
}

#endif
