/*
 * Validation's rays and the ray batches run where a build's threads run:
 * on the calling thread's CPU set, one core each when pinning is on, and
 * count CPUs as builds do (bvhlab_hardware_threads, not every online CPU).
 * As test-peers does for the peers' threads, this program sees the
 * threads through its own pthread_create (peer_threads.h) and reads their
 * affinity masks after each call; the executor keeps its workers, so the
 * same thread serves calls made from different CPU sets and must follow.
 *   1. caller narrowed to one CPU: a large validation starts no thread (a
 *      one-core set is one thread; it counted sysconf's online CPUs);
 *   2. a 2-thread ray batch there: its worker is on that CPU only;
 *   3. caller back on its whole set: the batch's worker is on the set;
 *   4. pinning on: the worker is bound to the plan's CPU for worker 1, and
 *      the caller gets its whole set back after;
 *   5. where the set has two cores or more, a large validation uses them,
 *      on the set.
 * Skipped (77) on a machine that gives the test one CPU.
 */
#include <sched.h>
#include <stdlib.h>

#include <bvhlab/bvhlab.h>

#include "machine/machine.h"
#include "peer_threads.h"
#include "testutil.h"

#define FIXTURE_SEED 40
#include "scene_fixture.h"

#define RAYS 1024

static bvhlab_scene *scene;
static bvhlab_tree tree;

/* Every thread started so far is on `want` (exactly). */
static void check_workers(const char *what, const cpu_set_t *want)
{
	unsigned n = atomic_load(&peer_tid_count);
	CHECK(n >= 1);
	for (unsigned k = 0; k < n && k < PEER_MAX_TIDS; k++) {
		cpu_set_t got;
		CHECK_INT(pthread_getaffinity_np(peer_tids[k], sizeof(got), &got), 0);
		if (!CPU_EQUAL(&got, want)) {
			fprintf(stderr, "%s: worker %u on %d CPUs, want %d\n", what, k, CPU_COUNT(&got),
			        CPU_COUNT(want));
			CHECK(!"worker on the caller's set");
		}
	}
}

static void validate(void)
{
	uint64_t mismatches = 1;
	bvhlab_error err = { { 0 } };
	CHECK_INT(bvhlab_validate_rays(&tree, scene, RAYS, 7, &mismatches, &err), 0);
	CHECK(mismatches == 0);
}

static void trace(uint32_t threads)
{
	bvhlab_ray *rays = calloc(RAYS, sizeof(*rays));
	bvhlab_hit *hits = calloc(RAYS, sizeof(*hits));
	bvhlab_trace_stats stats = { 0 };
	for (uint32_t i = 0; i < RAYS; i++) {
		rays[i] = (bvhlab_ray){ .org = { -5, 0.001f * (float)i, 0.5f }, .dir = { 1, 0, 0 },
		                        .tmin = 0, .tmax = 1e30f };
	}
	CHECK_INT(bvhlab_trace_batch(&tree, scene, rays, RAYS, false, threads, hits, NULL, &stats,
	                             NULL), 0);
	CHECK(stats.rays == RAYS);
	free(rays);
	free(hits);
}

static void set_mask(const cpu_set_t *set)
{
	CHECK_INT(sched_setaffinity(0, sizeof(*set), set), 0);
}

static void build_tree(void)
{
	bvhlab_plugin *p = NULL;
	bvhlab_options opts;
	bvhlab_error err = { { 0 } };
	bvhlab_prims prims;
	CHECK(plugin_loads("sah_seq", &p));
	CHECK_INT(bvhlab_options_init(&opts, bvhlab_plugin_builder(p)), 0);
	CHECK_INT(bvhlab_prims_init(&prims, scene, &err), 0);
	CHECK_INT(bvhlab_build(p, &opts, &prims.input, 1, &tree, &err), 0);
	bvhlab_prims_finish(&prims);
	bvhlab_options_finish(&opts);
	bvhlab_plugin_close(p);
}

int main(void)
{
	cpu_set_t all, one, now;
	CHECK_INT(sched_getaffinity(0, sizeof(all), &all), 0);
	if (CPU_COUNT(&all) < 2) {
		printf("one CPU: nothing to narrow\n");
		return 77;
	}
	/* Rays x triangles well past validation's threshold for threads. */
	scene = generate("soup", 20000, 0, 0);
	build_tree();
	CPU_ZERO(&one);
	for (int c = 0; c < CPU_SETSIZE && CPU_COUNT(&one) == 0; c++)
		if (CPU_ISSET(c, &all))
			CPU_SET(c, &one);

	set_mask(&one);
	validate();
	CHECK_INT(atomic_load(&peer_tid_count), 0);
	trace(2);
	check_workers("batch on one CPU", &one);

	set_mask(&all);
	trace(2);
	check_workers("batch on the whole set", &all);

	struct pin_plan plan;
	CHECK_INT(pin_plan_init(&plan), 0);
	cpu_set_t bound;
	CPU_ZERO(&bound);
	CPU_SET(plan.cpu[1 % plan.count], &bound);
	bvhlab_set_pinning(true);
	trace(2);
	bvhlab_set_pinning(false);
	check_workers("pinned batch", &bound);
	CHECK_INT(sched_getaffinity(0, sizeof(now), &now), 0);
	CHECK(CPU_EQUAL(&now, &all));

	if (bvhlab_hardware_threads() >= 2) {
		validate();
		check_workers("validation on the whole set", &all);
	} else {
		printf("one physical core: validation's threads not checked on the whole set\n");
	}
	printf("%u worker(s) served every call\n", atomic_load(&peer_tid_count));
	pin_plan_finish(&plan);
	bvhlab_tree_finish(&tree);
	bvhlab_scene_destroy(scene);
	return test_finish();
}
