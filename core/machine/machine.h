/* What the results record about the machine a run happened on, and the CPU
 * topology (hwloc) behind thread-count resolution and thread pinning. */
#ifndef BVHLAB_CORE_MACHINE_H
#define BVHLAB_CORE_MACHINE_H

#include <stdbool.h>
#include <stdint.h>

enum { MACHINE_L1D, MACHINE_L2, MACHINE_L3, MACHINE_CACHE_LEVELS };

/* One cache level as the allowed CPUs see it. */
struct machine_cache {
	uint64_t size;      /* bytes of one instance; 0 when the level is unknown */
	uint32_t instances; /* instances shared by at least one allowed CPU */
};

/*
 * The part of the machine the calling thread may run on: its affinity mask
 * intersected with the CPUs hwloc reports as allowed (hwloc drops CPUs that
 * a cgroup cpuset forbids). Every count is >= 1 except caches.
 */
struct machine_topology {
	bool from_hwloc;         /* false: hwloc failed; counts come from the mask */
	uint32_t packages;       /* sockets with an allowed CPU */
	uint32_t physical_cores; /* cores with an allowed CPU: what threads = 0 means */
	uint32_t logical_cpus;   /* allowed hardware threads */
	struct machine_cache caches[MACHINE_CACHE_LEVELS];
};

struct machine_info {
	char cpu[128];        /* model name from /proc/cpuinfo, or "unknown" */
	uint32_t cores;       /* online logical CPUs of the machine */
	uint32_t threads_available; /* what threads = 0 resolves to (physical cores) */
	struct machine_topology topo;
};

void machine_info_read(struct machine_info *info);

/* The memory the kernel says is available for new work (MemAvailable of
 * /proc/meminfo) in bytes; 0 when it cannot be read. */
uint64_t machine_memory_available(void);

/* One OpenCL device: its "P:D" indices, names and size. */
struct machine_cl_device {
	unsigned platform_index, device_index;
	char platform[128], name[128], version[128];
	char kind[16];           /* "gpu", "cpu", "accelerator", "other" */
	uint32_t compute_units;
	uint64_t global_mem;     /* bytes */
};

/*
 * Every OpenCL device of every platform, in "P:D" order: 0 and *devices
 * (malloc'd, *count, may be 0: a platform without devices), or a negative
 * errno with why saying what is missing: -ENOTSUP OpenCL not built,
 * -ENODEV no platform (what to install), -ENOMEM, -EIO.
 */
int machine_cl_devices(struct machine_cl_device **devices, size_t *count, char *why,
                       size_t why_size);

/*
 * Before the OpenCL ICD loader first runs (bvhlab's main calls it first):
 * with no OCL_ICD_VENDORS and no .icd file in /etc/OpenCL/vendors (or
 * $BVHLAB_CL_VENDORS_DIR), looks for NVIDIA's, AMD's, Intel's and PoCL's
 * OpenCL libraries on LD_LIBRARY_PATH, then in the usual driver folders
 * (or $BVHLAB_CL_DRIVER_DIRS), and points OCL_ICD_VENDORS at a private
 * folder of .icd files naming those found (machine_icd.c).
 */
void machine_icd_setup(void);
/* Which ICD the loader gets and how it was found, for info --machine. */
const char *machine_icd_how(void);

/*
 * The device a spec names (auto, gpu, cpu or P:D: a device builder's
 * "device" option, chosen as bvhlab_cl_init chooses) described into *out,
 * with the OpenCL runtime loaded and a context made on it that stay for
 * the life of the process (a spec opened before is not opened again).
 * 0, or a negative errno with why saying why (-ENOTSUP OpenCL not built).
 */
int machine_cl_open(const char *spec, struct machine_cl_device *out, char *why, size_t why_size);

/* The 1-minute load average from /proc/loadavg, or -1 when unreadable. */
double machine_load_average(void);

/*
 * CPU time of the whole machine and of this process, to tell how much of
 * the machine others used over an interval: take one before and one after,
 * then machine_other_load(). The 1-minute load average cannot say this: a
 * 2-thread run keeps it near 2 for a minute after, so the next run of a
 * sweep on an idle 2-core machine would look busy.
 */
struct machine_cpu_mark {
	double wall_s;    /* monotonic clock */
	double machine_s; /* busy time of all CPUs (/proc/stat: all but idle and iowait;
	                   * steal too: a hypervisor's other guests) */
	double own_s;     /* this process's CPU time and its waited-for children's */
	bool ok;          /* /proc/stat was read */
};
void machine_cpu_mark(struct machine_cpu_mark *m);
/* The average number of CPUs kept busy by anything but this process and
 * its children between the two marks, or -1 when either is unreadable or
 * the interval is too short to say (under 50 ms: /proc/stat counts 10 ms
 * ticks). */
double machine_other_load(const struct machine_cpu_mark *before,
                          const struct machine_cpu_mark *after);

/* 0, or -ENODEV when hwloc could not load (t is then filled from the mask). */
int machine_topology_read(struct machine_topology *t);

/* "L1d", "L2", "L3". */
const char *machine_cache_name(int level);

/*
 * Pinning plan: one CPU per allowed physical core, in hwloc's logical order
 * (the cores of one package before the next), captured from the calling
 * thread's mask before a build so workers that inherit a pinned mask still
 * spread over the whole set.
 */
struct pin_plan {
	uint32_t count; /* distinct cores, >= 1 */
	int *cpu;       /* [count] the CPU a worker on that core is bound to */
};

bool machine_pinning(void);
int pin_plan_init(struct pin_plan *plan);
void pin_plan_finish(struct pin_plan *plan);
/* Binds the calling thread to plan->cpu[worker % count]. 0 or -errno. */
int pin_plan_apply(const struct pin_plan *plan, uint32_t worker);

#endif
