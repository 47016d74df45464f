/* The device layer in a build without OpenCL (device.h): every request is
 * refused with what to install. */
#include <errno.h>
#include <stdio.h>

#include "device/device.h"

int device_program(const char *spec, const char *src, size_t len, const char *options,
                   const void **device, void **program, char *err, size_t err_size)
{
	(void)spec, (void)src, (void)len, (void)options;
	*device = NULL;
	*program = NULL;
	snprintf(err, err_size, "the device layer needs OpenCL, and this bvhlab was built "
	         "without it (install ocl-icd-opencl-dev and opencl-c-headers, then meson "
	         "setup again)");
	return -ENOTSUP;
}
