/*
 * CPU topology through hwloc: packages, physical cores and caches, what the
 * calling thread may use of them, and the pinning behind host->pin_thread.
 *
 * hwloc reads sysfs once (milliseconds) into a snapshot of CPU sets; every
 * query then intersects the snapshot with the calling thread's affinity
 * mask. hwloc's default topology already leaves out CPUs a cgroup cpuset
 * forbids, and intersecting with sched_getaffinity at query time (rather
 * than baking the mask into the snapshot) makes taskset and a later
 * sched_setaffinity count too.
 */
#include <errno.h>
#include <pthread.h>
#include <sched.h>
#include <stdatomic.h>
#include <stdlib.h>
#include <string.h>
#include <unistd.h>

#include <hwloc.h>

#include <bvhlab/machine.h>

#include "machine/machine.h"

/* One kind of object (package, core, a cache level): each instance's CPUs. */
struct objset {
	uint32_t count;
	cpu_set_t *cpus; /* [count] */
	uint64_t size;   /* caches: bytes of one instance */
};

enum { SET_PACKAGE, SET_CORE, SET_L1D, SET_L2, SET_L3, SET_KINDS };

/* Loaded once, kept for the process's lifetime (reachable, never leaked). */
static struct {
	bool loaded;
	cpu_set_t pus; /* every CPU hwloc reports as allowed */
	struct objset sets[SET_KINDS];
} snap;
static pthread_once_t snap_once = PTHREAD_ONCE_INIT;
static atomic_bool pinning_on;

static void to_cpuset(hwloc_const_bitmap_t b, cpu_set_t *out)
{
	CPU_ZERO(out);
	for (int i = hwloc_bitmap_first(b); i >= 0; i = hwloc_bitmap_next(b, i))
		if (i < CPU_SETSIZE)
			CPU_SET(i, out);
}

static int collect(hwloc_topology_t t, hwloc_obj_type_t type, struct objset *set)
{
	int n = hwloc_get_nbobjs_by_type(t, type);
	if (n <= 0)
		return 0;
	set->cpus = calloc((size_t)n, sizeof(*set->cpus));
	if (!set->cpus)
		return -ENOMEM;
	for (int i = 0; i < n; i++) {
		hwloc_obj_t obj = hwloc_get_obj_by_type(t, type, (unsigned)i);
		to_cpuset(obj->cpuset, &set->cpus[i]);
		if (hwloc_obj_type_is_cache(type) && obj->attr)
			set->size = obj->attr->cache.size;
	}
	set->count = (uint32_t)n;
	return 0;
}

static int collect_all(hwloc_topology_t t)
{
	static const hwloc_obj_type_t types[SET_KINDS] = {
		HWLOC_OBJ_PACKAGE, HWLOC_OBJ_CORE, HWLOC_OBJ_L1CACHE, HWLOC_OBJ_L2CACHE,
		HWLOC_OBJ_L3CACHE};
	to_cpuset(hwloc_topology_get_topology_cpuset(t), &snap.pus);
	for (int k = 0; k < SET_KINDS; k++)
		if (collect(t, types[k], &snap.sets[k]) < 0)
			return -ENOMEM;
	/* Some virtual machines expose no cores: each CPU is then its own. */
	if (snap.sets[SET_CORE].count == 0)
		return collect(t, HWLOC_OBJ_PU, &snap.sets[SET_CORE]);
	return 0;
}

static void load_snapshot(void)
{
	hwloc_topology_t t;
	if (hwloc_topology_init(&t) < 0)
		return;
	if (hwloc_topology_load(t) == 0 && collect_all(t) == 0 && CPU_COUNT(&snap.pus) > 0 &&
	    snap.sets[SET_CORE].count > 0)
		snap.loaded = true;
	hwloc_topology_destroy(t);
	if (!snap.loaded)
		for (int k = 0; k < SET_KINDS; k++) {
			free(snap.sets[k].cpus);
			memset(&snap.sets[k], 0, sizeof(snap.sets[k]));
		}
}

/* The CPUs the calling thread may use; false when hwloc is unavailable. */
static bool allowed_mask(cpu_set_t *mask)
{
	pthread_once(&snap_once, load_snapshot);
	if (sched_getaffinity(0, sizeof(*mask), mask) < 0 || CPU_COUNT(mask) == 0) {
		long n = sysconf(_SC_NPROCESSORS_ONLN);
		CPU_ZERO(mask);
		for (long i = 0; i < (n > 0 ? n : 1) && i < CPU_SETSIZE; i++)
			CPU_SET(i, mask);
	}
	if (!snap.loaded)
		return false;
	cpu_set_t both;
	CPU_AND(&both, mask, &snap.pus);
	/* A mask outside hwloc's set (CPU hot-plug since loading): trust the mask. */
	if (CPU_COUNT(&both) > 0)
		*mask = both;
	return true;
}

static uint32_t count_touching(const struct objset *set, const cpu_set_t *mask)
{
	uint32_t n = 0;
	for (uint32_t i = 0; i < set->count; i++) {
		cpu_set_t both;
		CPU_AND(&both, &set->cpus[i], mask);
		n += CPU_COUNT(&both) > 0;
	}
	return n;
}

int machine_topology_read(struct machine_topology *t)
{
	cpu_set_t mask;
	memset(t, 0, sizeof(*t));
	t->from_hwloc = allowed_mask(&mask);
	t->logical_cpus = (uint32_t)CPU_COUNT(&mask);
	if (!t->from_hwloc) {
		t->packages = 1;
		t->physical_cores = t->logical_cpus;
		return -ENODEV;
	}
	t->packages = count_touching(&snap.sets[SET_PACKAGE], &mask);
	t->physical_cores = count_touching(&snap.sets[SET_CORE], &mask);
	for (int k = 0; k < MACHINE_CACHE_LEVELS; k++) {
		const struct objset *c = &snap.sets[SET_L1D + k];
		t->caches[k].instances = count_touching(c, &mask);
		t->caches[k].size = c->size;
	}
	if (t->packages == 0)
		t->packages = 1;
	if (t->physical_cores == 0)
		t->physical_cores = t->logical_cpus;
	return 0;
}

const char *machine_cache_name(int level)
{
	static const char *names[MACHINE_CACHE_LEVELS] = {"L1d", "L2", "L3"};
	return level >= 0 && level < MACHINE_CACHE_LEVELS ? names[level] : "?";
}

uint32_t bvhlab_hardware_threads(void)
{
	/* Physical cores, not logical CPUs: SMT siblings share one core's
	 * execution units, so a thread per sibling mostly adds contention to a
	 * memory-bound build and blurs the scaling curves. */
	struct machine_topology t;
	machine_topology_read(&t);
	return t.physical_cores > 0 ? t.physical_cores : 1;
}

/* ---- pinning ------------------------------------------------------------- */

void bvhlab_set_pinning(bool on)
{
	atomic_store(&pinning_on, on);
}

bool machine_pinning(void)
{
	return atomic_load(&pinning_on);
}

static int lowest_cpu(const cpu_set_t *set)
{
	for (int i = 0; i < CPU_SETSIZE; i++)
		if (CPU_ISSET(i, set))
			return i;
	return -1;
}

/* Without hwloc every allowed CPU counts as a core of its own. */
static void plan_from_mask(struct pin_plan *plan, const cpu_set_t *mask)
{
	for (int i = 0; i < CPU_SETSIZE; i++)
		if (CPU_ISSET(i, mask))
			plan->cpu[plan->count++] = i;
}

int pin_plan_init(struct pin_plan *plan)
{
	cpu_set_t mask;
	bool hw = allowed_mask(&mask);
	uint32_t max = hw ? snap.sets[SET_CORE].count : (uint32_t)CPU_COUNT(&mask);
	plan->count = 0;
	plan->cpu = malloc((max > 0 ? max : 1) * sizeof(*plan->cpu));
	if (!plan->cpu)
		return -ENOMEM;
	if (!hw) {
		plan_from_mask(plan, &mask);
		return plan->count > 0 ? 0 : -ENODEV;
	}
	for (uint32_t i = 0; i < snap.sets[SET_CORE].count; i++) {
		cpu_set_t both;
		CPU_AND(&both, &snap.sets[SET_CORE].cpus[i], &mask);
		int cpu = lowest_cpu(&both);
		if (cpu >= 0)
			plan->cpu[plan->count++] = cpu;
	}
	if (plan->count == 0)
		plan_from_mask(plan, &mask);
	return plan->count > 0 ? 0 : -ENODEV;
}

void pin_plan_finish(struct pin_plan *plan)
{
	free(plan->cpu);
	plan->cpu = NULL;
	plan->count = 0;
}

int pin_plan_apply(const struct pin_plan *plan, uint32_t worker)
{
	if (plan->count == 0)
		return -ENODEV;
	/* One CPU rather than the core's siblings: the scheduler then cannot
	 * move the worker between them, which keeps runs comparable. */
	cpu_set_t one;
	CPU_ZERO(&one);
	CPU_SET(plan->cpu[worker % plan->count], &one);
	int r = pthread_setaffinity_np(pthread_self(), sizeof(one), &one);
	return -r;
}
