/*
 * CPU topology (hwloc): counts that make sense, an affinity mask that
 * narrows them, threads = 0 resolving to physical cores, and pinning, both
 * directly and through host->pin_thread in a build (the pin_probe plugin
 * checks from inside its workers). The mask checks come first, while the
 * process has one thread.
 */
#include <errno.h>
#include <pthread.h>
#include <sched.h>

#include <bvhlab/bvhlab.h>

#include "machine/machine.h"
#include "testutil.h"

static cpu_set_t original;

static void test_counts(void)
{
	struct machine_topology t;
	CHECK_INT(machine_topology_read(&t), 0);
	CHECK(t.from_hwloc);
	CHECK(t.physical_cores >= 1);
	CHECK(t.physical_cores <= t.logical_cpus);
	CHECK(t.packages >= 1 && t.packages <= t.physical_cores);
	CHECK_INT(t.logical_cpus, CPU_COUNT(&original));
	CHECK_INT(bvhlab_hardware_threads(), t.physical_cores);
	for (int k = 0; k < MACHINE_CACHE_LEVELS; k++)
		CHECK(t.caches[k].size == 0 || t.caches[k].instances >= 1);
	printf("topology: %u packages, %u cores, %u CPUs\n", t.packages, t.physical_cores,
	       t.logical_cpus);
}

static int first_cpu(const cpu_set_t *set)
{
	for (int i = 0; i < CPU_SETSIZE; i++)
		if (CPU_ISSET(i, set))
			return i;
	return -1;
}

/* taskset to one CPU: every count drops to 1, and comes back after. */
static void test_restricted(void)
{
	struct machine_topology t, again;
	cpu_set_t one;
	CPU_ZERO(&one);
	CPU_SET(first_cpu(&original), &one);
	CHECK_INT(sched_setaffinity(0, sizeof(one), &one), 0);
	CHECK_INT(machine_topology_read(&t), 0);
	CHECK_INT(t.logical_cpus, 1);
	CHECK_INT(t.physical_cores, 1);
	CHECK_INT(t.packages, 1);
	CHECK_INT(bvhlab_hardware_threads(), 1);
	for (int k = 0; k < MACHINE_CACHE_LEVELS; k++)
		CHECK(t.caches[k].size == 0 || t.caches[k].instances == 1);
	CHECK_INT(sched_setaffinity(0, sizeof(original), &original), 0);
	machine_topology_read(&again);
	CHECK_INT(again.logical_cpus, CPU_COUNT(&original));
}

struct pin_job {
	const struct pin_plan *plan;
	uint32_t worker;
	int rc, cpu;
};

static void *pin_and_look(void *arg)
{
	struct pin_job *j = arg;
	j->rc = pin_plan_apply(j->plan, j->worker);
	j->cpu = sched_getcpu();
	return NULL;
}

/* One CPU per core, all allowed, distinct; a thread pinned there runs there. */
static void test_plan(void)
{
	struct pin_plan plan;
	CHECK_INT(pin_plan_init(&plan), 0);
	CHECK_INT(plan.count, bvhlab_hardware_threads());
	for (uint32_t k = 0; k < plan.count; k++) {
		CHECK(CPU_ISSET(plan.cpu[k], &original));
		for (uint32_t j = 0; j < k; j++)
			CHECK(plan.cpu[j] != plan.cpu[k]);
	}
	for (uint32_t k = 0; k <= plan.count; k++) {
		struct pin_job job = {.plan = &plan, .worker = k};
		pthread_t tid;
		CHECK_INT(pthread_create(&tid, NULL, pin_and_look, &job), 0);
		pthread_join(tid, NULL);
		CHECK_INT(job.rc, 0);
		CHECK_INT(job.cpu, plan.cpu[k % plan.count]);
	}
	pin_plan_finish(&plan);
}

static int probe(bvhlab_plugin *p, const bvhlab_prims *prims, const char *expect,
                 uint32_t threads, bvhlab_error *err)
{
	bvhlab_options opts;
	bvhlab_tree tree = {0};
	char assignment[64];
	snprintf(assignment, sizeof(assignment), "expect=%s", expect);
	if (bvhlab_options_init(&opts, bvhlab_plugin_builder(p)) < 0)
		return -ENOMEM;
	int rc = bvhlab_options_parse(&opts, assignment, err);
	if (rc == 0)
		rc = bvhlab_build(p, &opts, &prims->input, threads, &tree, err);
	bvhlab_tree_finish(&tree);
	bvhlab_options_finish(&opts);
	return rc;
}

static bool mask_is_original(void)
{
	cpu_set_t now;
	pthread_getaffinity_np(pthread_self(), sizeof(now), &now);
	return CPU_EQUAL(&now, &original);
}

/* Through a build: off is a no-op, on pins, and the caller gets its mask back. */
static void test_build(void)
{
	bvhlab_gen_params gp;
	bvhlab_scene *scene = NULL;
	bvhlab_prims prims = {0};
	bvhlab_plugin *p = NULL;
	bvhlab_error err = {{0}};
	uint32_t cores = bvhlab_hardware_threads();
	bvhlab_gen_params_init(&gp);
	gp.frequency = 2;
	if (bvhlab_scene_generate("icosphere", &gp, &scene, &err) < 0 ||
	    bvhlab_prims_init(&prims, scene, &err) < 0 ||
	    bvhlab_plugin_open(BVHLAB_TEST_BUILDDIR "/pin_probe.so", &p, &err) < 0) {
		fprintf(stderr, "setup: %s\n", err.message);
		test_failures++;
		goto out;
	}
	CHECK_INT(probe(p, &prims, "free", 2, &err), 0);
	bvhlab_set_pinning(true);
	CHECK_INT(probe(p, &prims, "pinned", 2, &err), 0);
	CHECK(mask_is_original());
	CHECK_INT(probe(p, &prims, "pinned", cores + 1, &err), 0);
	if (CPU_COUNT(&original) > 1)
		CHECK_INT(probe(p, &prims, "free", 2, &err), -EIO);
	CHECK(mask_is_original());
	bvhlab_set_pinning(false);
	CHECK_INT(probe(p, &prims, "free", 0, &err), 0);
out:
	if (test_failures)
		fprintf(stderr, "last error: %s\n", err.message);
	bvhlab_plugin_close(p);
	bvhlab_prims_finish(&prims);
	bvhlab_scene_destroy(scene);
}

/* The CPUs others used over an interval: the machine's busy time less this
 * process's, over the wall time; nothing to say over too short an interval
 * or without /proc/stat; never negative (ticks against microseconds). */
static void test_other_load(void)
{
	struct machine_cpu_mark a = {.wall_s = 10, .machine_s = 100, .own_s = 5, .ok = true};
	struct machine_cpu_mark b = {.wall_s = 12, .machine_s = 103, .own_s = 7, .ok = true};
	CHECK(machine_other_load(&a, &b) == 0.5);
	b.own_s = 9;
	CHECK(machine_other_load(&a, &b) == 0);
	b.wall_s = 10.01;
	CHECK(machine_other_load(&a, &b) == -1);
	b.wall_s = 12;
	b.ok = false;
	CHECK(machine_other_load(&a, &b) == -1);
	machine_cpu_mark(&a);
	CHECK(a.ok && a.machine_s > 0 && a.own_s > 0 && a.wall_s > 0);
}

int main(void)
{
	if (sched_getaffinity(0, sizeof(original), &original) < 0) {
		perror("sched_getaffinity");
		return 1;
	}
	test_counts();
	test_restricted();
	test_plan();
	test_build();
	test_other_load();
	return test_finish();
}
