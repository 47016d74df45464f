/*
 * Private to sah_bins.c and sah_bins_avx2.c: the 8-lane binning, built
 * where the compiler can target AVX2 for one function (GCC and Clang on
 * x86-64) and called only where the CPU has it (sah_options_read).
 */
#ifndef BVHLAB_SAH_BINS_AVX2_H
#define BVHLAB_SAH_BINS_AVX2_H

#include <stdbool.h>

#include "sah_kernel.h"

#if defined(__x86_64__) && (defined(__GNUC__) || defined(__clang__)) && !defined(SAH_NO_SIMD)
#define SAH_HAVE_AVX2 1
/* sah_bins_fill's AVX2 path; same bins, bit for bit, as the SSE one. */
void sah_bins_fill_avx2(sah_bins *out, const sah_grid *g, const sah_prim *prims,
                        uint32_t begin, uint32_t end);
#endif

/* True when this build has the AVX2 path and the CPU runs it. */
bool sah_cpu_has_avx2(void);

/* Every bin of the grid empty. */
void sah_bins_clear(sah_bins *g, uint32_t nb);

#endif /* BVHLAB_SAH_BINS_AVX2_H */
