// The CPU limit behind tinybvh's thread count (see tinybvh_cpus.h).
#include "tinybvh_cpus.h"

#include <cerrno>
#include <cstdio>
#include <set>
#include <utility>

namespace tbvh {

namespace {

// The (package, core) a CPU belongs to, from sysfs; (-1, cpu) when unknown,
// so an unknown CPU counts as a core of its own.
std::pair<long, long> core_of(int cpu)
{
	long ids[2] = {-1, cpu};
	const char *names[2] = {"physical_package_id", "core_id"};
	for (int k = 0; k < 2; k++) {
		char path[128];
		std::snprintf(path, sizeof(path), "/sys/devices/system/cpu/cpu%d/topology/%s", cpu,
		              names[k]);
		if (FILE *f = std::fopen(path, "r")) {
			long v;
			if (std::fscanf(f, "%ld", &v) == 1)
				ids[k] = v;
			std::fclose(f);
		}
	}
	return {ids[0], ids[1]};
}

// `threads` CPUs of `from`: one per physical core first, then SMT siblings.
cpu_set_t pick(const cpu_set_t &from, uint32_t threads)
{
	cpu_set_t use;
	CPU_ZERO(&use);
	std::set<std::pair<long, long>> cores;
	uint32_t n = 0;
	for (int pass = 0; pass < 2 && n < threads; pass++)
		for (int c = 0; c < CPU_SETSIZE && n < threads; c++) {
			if (!CPU_ISSET(c, &from) || CPU_ISSET(c, &use))
				continue;
			if (pass == 0 && !cores.insert(core_of(c)).second)
				continue;
			CPU_SET(c, &use);
			n++;
		}
	return use;
}

} // namespace

int CpuLimit::limit(uint32_t threads)
{
	if (sched_getaffinity(0, sizeof(saved_), &saved_) != 0)
		return -errno;
	if (static_cast<uint32_t>(CPU_COUNT(&saved_)) <= threads)
		return 0;
	cpu_set_t use = pick(saved_, threads);
	if (sched_setaffinity(0, sizeof(use), &use) != 0)
		return -errno;
	active_ = true;
	return 0;
}

CpuLimit::~CpuLimit()
{
	if (active_)
		sched_setaffinity(0, sizeof(saved_), &saved_);
}

} // namespace tbvh
