/*
 * bvhlab — the machine builds run on, as the library sees it: what a
 * thread count of 0 resolves to, and the switch for pinning builder
 * threads to cores (host->pin_thread in builder.h).
 */
#ifndef BVHLAB_MACHINE_H
#define BVHLAB_MACHINE_H

#include <stdbool.h>
#include <stdint.h>

#include "types.h"

BVHLAB_BEGIN_DECLS

/*
 * What threads = 0 means, >= 1: the physical cores the calling thread may
 * run on, from hwloc's topology intersected with the thread's affinity mask
 * (taskset, sched_setaffinity; hwloc already drops CPUs a cgroup cpuset
 * forbids). SMT siblings count once. Without hwloc's topology, the CPUs of
 * the affinity mask.
 */
uint32_t bvhlab_hardware_threads(void);

/*
 * Process-wide switch for host->pin_thread (off by default): when on, a
 * builder worker that calls it is bound to one CPU of a distinct physical
 * core. Set it between builds, not during one.
 */
void bvhlab_set_pinning(bool on);

BVHLAB_END_DECLS

#endif /* BVHLAB_MACHINE_H */
