// tinybvh_cpus.h: holds the threads tinybvh spawns to the run's thread count.
//
// tinybvh's threaded builders (binned, avx, sweep, hq over 50,000
// triangles or more) start two std::threads per split down to depth 5 and
// join them: up to 62 threads, however many CPUs there are, and no knob
// to say how many. A new thread starts with its creator's CPU affinity, so
// limiting the calling thread to N CPUs holds all of them to N CPUs at a
// time. At one thread the plugin turns the library's threaded path off
// instead (BVH::threadedBuild = false), so nothing is spawned at all.
#ifndef BVHLAB_TINYBVH_CPUS_H
#define BVHLAB_TINYBVH_CPUS_H

#include <sched.h>

#include <cstdint>

namespace tbvh {

// Restricts the calling thread to `threads` CPUs of its affinity mask
// (distinct physical cores first) for its lifetime, then restores the mask.
class CpuLimit {
public:
	CpuLimit() = default;
	CpuLimit(const CpuLimit &) = delete;
	CpuLimit &operator=(const CpuLimit &) = delete;
	~CpuLimit();

	// 0 (also when the mask already has `threads` CPUs or fewer: nothing
	// to narrow), or a negative errno from the affinity calls.
	int limit(uint32_t threads);

private:
	cpu_set_t saved_{};
	bool active_ = false;
};

} // namespace tbvh

#endif
