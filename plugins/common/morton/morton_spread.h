/*
 * The bits of a cell index spread out to every third bit, 21 bits into 63:
 * one definition for the CPU sort (morton_sort.c, which tabulates it) and
 * the device sort (plugins/common/cl/morton_sort.cl, whose program the
 * build starts with this file), so both make the same codes. The C that
 * OpenCL C also is; only the 64-bit type is named apart.
 */
#ifndef BVHLAB_MORTON_SPREAD_H
#define BVHLAB_MORTON_SPREAD_H

#ifdef __OPENCL_VERSION__
typedef ulong morton_word;
#else
#include <stdint.h>
typedef uint64_t morton_word;
#endif

static inline morton_word morton_spread21(morton_word x)
{
	x &= 0x1fffff;
	x = (x | x << 32) & 0x001f00000000ffff;
	x = (x | x << 16) & 0x001f0000ff0000ff;
	x = (x | x << 8) & 0x100f00f00f00f00f;
	x = (x | x << 4) & 0x10c30c30c30c30c3;
	x = (x | x << 2) & 0x1249249249249249;
	return x;
}

#endif /* BVHLAB_MORTON_SPREAD_H */
