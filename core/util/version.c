/* The library's version (bvhlab.h), from meson's project version. */
#include <bvhlab/bvhlab.h>

#ifndef BVHLAB_VERSION
#define BVHLAB_VERSION "unknown"
#endif

const char *bvhlab_version(void)
{
	return BVHLAB_VERSION;
}
