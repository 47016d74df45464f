/* The machine: CPU model and the CPUs this process may use. */
#include <sched.h>
#include <stdio.h>
#include <string.h>
#include <unistd.h>

#include <bvhlab/bvhlab.h>

#include "machine.h"

#ifndef BVHLAB_VERSION
#define BVHLAB_VERSION "unknown"
#endif

const char *bvhlab_version(void)
{
	return BVHLAB_VERSION;
}

uint32_t bvhlab_hardware_threads(void)
{
	/* The affinity mask, not the machine's CPU count: taskset and cgroup
	 * cpusets both narrow it, and builders must not oversubscribe. */
	cpu_set_t set;
	if (sched_getaffinity(0, sizeof(set), &set) == 0) {
		int n = CPU_COUNT(&set);
		if (n > 0)
			return (uint32_t)n;
	}
	long n = sysconf(_SC_NPROCESSORS_ONLN);
	return n > 0 ? (uint32_t)n : 1;
}

static void read_cpu_name(char *out, size_t size)
{
	snprintf(out, size, "unknown");
	FILE *f = fopen("/proc/cpuinfo", "r");
	if (!f)
		return;
	char line[512];
	while (fgets(line, sizeof(line), f)) {
		if (strncmp(line, "model name", 10) != 0)
			continue;
		const char *colon = strchr(line, ':');
		if (!colon)
			break;
		colon++;
		while (*colon == ' ' || *colon == '\t')
			colon++;
		snprintf(out, size, "%.*s", (int)strcspn(colon, "\n"), colon);
		break;
	}
	fclose(f);
}

void machine_info_read(struct machine_info *info)
{
	read_cpu_name(info->cpu, sizeof(info->cpu));
	long n = sysconf(_SC_NPROCESSORS_ONLN);
	info->cores = n > 0 ? (uint32_t)n : 1;
	info->threads_available = bvhlab_hardware_threads();
}
