/*
 * The 8-lane binning (sah_bins_avx2.c), for sah_bins.c and the option
 * reader in sah_kernel.c: built where the compiler can target AVX2 for one
 * function (GCC and Clang on x86-64) and called only where the CPU has it
 * (sah_options_resolve). Self-contained: it clears and merges its own bins.
 */
#ifndef BVHLAB_SAH_BINS_AVX2_H
#define BVHLAB_SAH_BINS_AVX2_H

#include <stdbool.h>

#include "sah_types.h"

#if defined(__x86_64__) && (defined(__GNUC__) || defined(__clang__)) && !defined(SAH_NO_SIMD)
#define SAH_HAVE_AVX2 1
/* sah_bins_fill's AVX2 path; same bins, bit for bit, as the SSE one. */
void sah_bins_fill_avx2(sah_bins *out, const sah_grid *g, const sah_prim *prims,
                        uint32_t begin, uint32_t end);
#endif

/*
 * Both paths' fill loop: ADD(bins, i) bins primitive i into *bins; even
 * primitives go to out, odd ones to odd (both cleared before, merged
 * after). Neighbours in memory are neighbours in space, so consecutive
 * primitives mostly hit the same bins, and with one set each update would
 * wait for the store of the one before. A macro, so that ADD is inlined
 * in each path's own instruction set.
 */
#define SAH_BINS_EVEN_ODD(out, odd, begin, end, ADD) \
	do {                                          \
		uint32_t i_ = (begin);                \
		for (; i_ + 1 < (end); i_ += 2) {     \
			ADD(out, i_);                 \
			ADD(odd, i_ + 1);             \
		}                                     \
		if (i_ < (end))                       \
			ADD(out, i_);                 \
	} while (0)

/* True when this build has the AVX2 path and the CPU runs it. */
bool sah_cpu_has_avx2(void);

#endif /* BVHLAB_SAH_BINS_AVX2_H */
