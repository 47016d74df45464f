/* What the results record about the machine a run happened on. */
#ifndef BVHLAB_CORE_MACHINE_H
#define BVHLAB_CORE_MACHINE_H

#include <stdint.h>

struct machine_info {
	char cpu[128];        /* model name from /proc/cpuinfo, or "unknown" */
	uint32_t cores;       /* online logical CPUs of the machine */
	uint32_t threads_available; /* CPUs this process may run on */
};

void machine_info_read(struct machine_info *info);

#endif
