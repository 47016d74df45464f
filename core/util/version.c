/* The library's version (bvhlab.h): meson's project version and the
 * commit ("0.1.0+2f1cbf6a0b1c", "-dirty" after it with uncommitted
 * changes, "+unknown" for a build outside git). */
#include <bvhlab/bvhlab.h>

#include "util/commit.h"

#ifndef BVHLAB_VERSION
#define BVHLAB_VERSION "unknown"
#endif

const char *bvhlab_version(void)
{
	return BVHLAB_VERSION "+" BVHLAB_COMMIT;
}
