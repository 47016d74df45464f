/*
 * The device tests' first step: whether this machine has an OpenCL device
 * at all. Without one a test skips (77, meson's skip) with the reason,
 * since PoCL is optional and the rest of the suite must still pass.
 */
#ifndef BVHLAB_TEST_CL_DEVICE_H
#define BVHLAB_TEST_CL_DEVICE_H

#include <stdbool.h>
#include <stdio.h>
#include <string.h>

#include <bvhlab/opencl.h>

/* True with the device's name in name (size bytes) when there is one;
 * false after printing why not. */
static inline bool cl_device_present(char *name, size_t size)
{
	bvhlab_cl cl = {0};
	char why[BVHLAB_CL_ERROR_SIZE];
	if (bvhlab_cl_init(&cl, "auto", why, sizeof(why)) < 0) {
		printf("skipped: no OpenCL device on this machine (%s)\n", why);
		return false;
	}
	if (name && size)
		snprintf(name, size, "%s", cl.name);
	bvhlab_cl_finish(&cl);
	return true;
}

#endif
