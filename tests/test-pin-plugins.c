/*
 * `pin` for every parallel plugin: with pinning on, a build at 2 threads
 * binds its workers, each to the CPU the host's plan gives its worker
 * number, the calling thread and at least one thread of the plugin's own
 * among them; with pinning off nothing is bound. The refinement stages
 * are checked on their own call (the base tree is built first).
 *
 * How it is seen: this program defines pthread_setaffinity_np, which the
 * host's pin_thread and the executor's workers call (libbvhlab is linked in statically, so its call
 * binds to this definition), records the calling thread and the mask,
 * and passes the call on to the C library's. A bound mask holds one CPU;
 * the host's restoring of the caller's mask after the build holds the
 * caller's whole set (on a one-CPU machine that is plan CPU 0, which the
 * calling thread, worker 0, binds to anyway).
 */
#include <dlfcn.h>
#include <errno.h>
#include <pthread.h>
#include <sched.h>
#include <sys/syscall.h>
#include <unistd.h>

#include <bvhlab/bvhlab.h>

#include "machine/machine.h"
#include "testutil.h"

#define FIXTURE_SEED 28
#include "scene_fixture.h"

#define THREADS 2
#define MAX_CALLS 4096

/* ---- the recorder --------------------------------------------------------- */

struct call {
	long tid;
	int cpus; /* CPUs in the mask */
	int cpu;  /* its first */
};

static pthread_mutex_t rec_lock = PTHREAD_MUTEX_INITIALIZER;
static struct call calls[MAX_CALLS];
static unsigned call_count;

typedef int (*setaffinity_fn)(pthread_t, size_t, const cpu_set_t *);

int pthread_setaffinity_np(pthread_t thread, size_t size, const cpu_set_t *set)
{
	static setaffinity_fn real;
	struct call c = { .tid = syscall(SYS_gettid), .cpus = CPU_COUNT_S(size, set), .cpu = -1 };

	for (int i = 0; i < (int)(8 * size) && c.cpu < 0; i++)
		if (CPU_ISSET_S(i, size, set))
			c.cpu = i;
	pthread_mutex_lock(&rec_lock);
	if (!real)
		real = (setaffinity_fn)dlsym(RTLD_NEXT, "pthread_setaffinity_np");
	if (call_count < MAX_CALLS)
		calls[call_count++] = c;
	pthread_mutex_unlock(&rec_lock);
	return real ? real(thread, size, set) : ENOSYS;
}

static void rec_reset(void)
{
	pthread_mutex_lock(&rec_lock);
	call_count = 0;
	pthread_mutex_unlock(&rec_lock);
}

/* ---- the checks ----------------------------------------------------------- */

static struct pin_plan plan;

/* What the record says: threads that bound themselves, and the CPUs. */
struct seen {
	unsigned threads, calls;
	bool cpu_bound[CPU_SETSIZE];
	bool caller_bound;
};

static void summarise(struct seen *s)
{
	long tids[MAX_CALLS];
	long me = syscall(SYS_gettid);

	memset(s, 0, sizeof(*s));
	s->calls = call_count;
	for (unsigned k = 0; k < call_count; k++) {
		unsigned j = 0;
		if (calls[k].cpus != 1)
			continue;
		s->cpu_bound[calls[k].cpu] = true;
		s->caller_bound |= calls[k].tid == me;
		while (j < s->threads && tids[j] != calls[k].tid)
			j++;
		if (j == s->threads)
			tids[s->threads++] = calls[k].tid;
	}
}

/* Pinned: the CPUs bound are those of workers 0 .. THREADS-1, no other,
 * by the caller and at least one other thread. */
static void check_pinned(const char *what, const struct seen *s)
{
	bool want[CPU_SETSIZE] = { false };

	for (uint32_t w = 0; w < THREADS; w++)
		want[plan.cpu[w % plan.count]] = true;
	if (memcmp(want, s->cpu_bound, sizeof(want)) != 0 || !s->caller_bound ||
	    s->threads < 2) {
		fprintf(stderr, "%s, pin on: %u threads bound (caller %s), CPUs not the plan's "
		        "for workers 0..%d, or too few\n", what, s->threads,
		        s->caller_bound ? "too" : "not", THREADS - 1);
		CHECK(!"every worker pinned");
	}
}

static void check_free(const char *what, const struct seen *s)
{
	if (s->calls != 0) {
		fprintf(stderr, "%s, pin off: %u affinity calls\n", what, s->calls);
		CHECK(!"nothing pinned");
	}
}

/* ---- the builds ------------------------------------------------------------ */

/* Builds (or refines, when base names the builder of the tree to refine)
 * with pinning as asked; the record covers only `name`'s own call. */
static void run_one(const char *name, const char *base, const bvhlab_build_input *in, bool pin)
{
	bvhlab_plugin *p = NULL, *b = NULL;
	bvhlab_options opts;
	bvhlab_error err = { { 0 } };
	bvhlab_tree tree = { 0 };
	struct seen s;
	int rc;

	if (!plugin_loads(name, &p) || (base && !plugin_loads(base, &b)))
		goto out;
	bvhlab_set_pinning(pin);
	if (base) {
		CHECK_INT(bvhlab_options_init(&opts, bvhlab_plugin_builder(b)), 0);
		CHECK_INT(bvhlab_build(b, &opts, in, 1, &tree, &err), 0);
		bvhlab_options_finish(&opts);
	}
	CHECK_INT(bvhlab_options_init(&opts, bvhlab_plugin_builder(p)), 0);
	rec_reset();
	rc = base ? bvhlab_refine(p, &opts, in, THREADS, &tree, &err)
	          : bvhlab_build(p, &opts, in, THREADS, &tree, &err);
	if (rc < 0)
		fprintf(stderr, "%s: %s\n", name, err.message);
	CHECK_INT(rc, 0);
	summarise(&s);
	if (pin)
		check_pinned(name, &s);
	else
		check_free(name, &s);
	printf("%-10s pin %-3s: %u threads bound, %u affinity calls\n", name, pin ? "on" : "off",
	       s.threads, s.calls);
	bvhlab_options_finish(&opts);
out:
	bvhlab_set_pinning(false);
	bvhlab_tree_finish(&tree);
	bvhlab_plugin_close(p);
	bvhlab_plugin_close(b);
}

int main(void)
{
	static const char *const builders[] = {
		"sah_even", "sah_uneven", "sah_queue", "sah_tasks", "lbvh", "ploc", "hploc",
		"hlbvh", "sbvh",
	};
	static const char *const stages[] = { "reinsert", "treelet" };
	/* Large enough that every plugin starts its second thread (sah_queue
	 * and sah_tasks want 4096 primitives a thread, lbvh, ploc, hploc and hlbvh
	 * 512). */
	bvhlab_scene *scene = generate("soup", 10000, 0, 0);
	bvhlab_prims prims;
	bvhlab_error err = { { 0 } };

	CHECK_INT(pin_plan_init(&plan), 0);
	CHECK_INT(bvhlab_prims_init(&prims, scene, &err), 0);
	for (int pin = 0; pin < 2; pin++) {
		for (size_t k = 0; k < sizeof(builders) / sizeof(builders[0]); k++)
			run_one(builders[k], NULL, &prims.input, pin);
		for (size_t k = 0; k < sizeof(stages) / sizeof(stages[0]); k++)
			run_one(stages[k], "lbvh", &prims.input, pin);
	}
	bvhlab_prims_finish(&prims);
	bvhlab_scene_destroy(scene);
	pin_plan_finish(&plan);
	return test_finish();
}
