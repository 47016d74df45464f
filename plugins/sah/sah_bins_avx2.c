/*
 * Binning with 8-lane vectors. A primitive record (sah_prim: lo, id, hi,
 * pad) is one 256-bit load; with lo negated (and the id and pad lanes
 * cleared) one max grows a bin's whole box, where 4 lanes need a min and a
 * max. The bin indices come from the same SSE operations as the 4-lane
 * path (VEX-encoded, same rounding; no FMA is enabled), so both fill the
 * same bins and the tree does not depend on the path.
 */
#include "sah_bins_avx2.h"

#ifdef SAH_HAVE_AVX2
#include <immintrin.h>
#include <math.h>

#define AVX2 __attribute__((target("avx2")))

AVX2 static inline void bins_of(__m256 p, __m128 base, __m128 scale, __m128 top, int32_t k[4])
{
	const __m128 half = _mm_set1_ps(0.5f), zero = _mm_setzero_ps();
	const __m128 lanes3 = _mm_castsi128_ps(_mm_set_epi32(0, -1, -1, -1));
	__m128 lo = _mm_and_ps(_mm256_castps256_ps128(p), lanes3);
	__m128 hi = _mm_and_ps(_mm256_extractf128_ps(p, 1), lanes3);
	__m128 f = _mm_mul_ps(_mm_sub_ps(_mm_mul_ps(_mm_add_ps(lo, hi), half), base), scale);

	_mm_storeu_si128((__m128i *)(void *)k, _mm_cvttps_epi32(_mm_max_ps(_mm_min_ps(f, top), zero)));
}

/* (-lo, 0, hi, 0): the bin layout of sah_bins. */
AVX2 static inline __m256 as_bin(__m256 p)
{
	const __m256 keep = _mm256_castsi256_ps(_mm256_set_epi32(0, -1, -1, -1, 0, -1, -1, -1));
	const __m256 sign = _mm256_castsi256_ps(_mm256_set_epi32(0, 0, 0, 0, 0, INT32_MIN,
	                                                         INT32_MIN, INT32_MIN));

	return _mm256_xor_ps(_mm256_and_ps(p, keep), sign);
}

/* Every bin of the grid empty: counts 0, boxes -inf (the empty union). */
AVX2 static void clear(sah_bins *g, uint32_t nb)
{
	const __m256 ninf = _mm256_set1_ps(-INFINITY);

	for (int a = 0; a < 3; a++) {
		for (uint32_t j = 0; j < nb; j++) {
			g->count[a][j] = 0;
			_mm256_storeu_ps(g->box[a][j], ninf);
		}
	}
}

/* Adds src's bins into dst: the same max as sah_bins_merge, 8 lanes at once. */
AVX2 static void merge(sah_bins *dst, const sah_bins *src, uint32_t nb)
{
	for (int a = 0; a < 3; a++) {
		for (uint32_t j = 0; j < nb; j++) {
			dst->count[a][j] += src->count[a][j];
			_mm256_storeu_ps(dst->box[a][j], _mm256_max_ps(_mm256_loadu_ps(dst->box[a][j]),
			                                               _mm256_loadu_ps(src->box[a][j])));
		}
	}
}

AVX2 static inline void add(sah_bins *g, const int32_t k[4], __m256 v)
{
	for (int a = 0; a < 3; a++) {
		float *box = g->box[a][k[a]];
		g->count[a][k[a]]++;
		_mm256_storeu_ps(box, _mm256_max_ps(_mm256_loadu_ps(box), v));
	}
}

/* The three bins of primitive p, and p into them. */
AVX2 static inline void add_prim(sah_bins *bins, const sah_prim *p, __m128 base, __m128 scale,
                                 __m128 top)
{
	int32_t k[4];
	__m256 v = _mm256_loadu_ps(p->lo);

	bins_of(v, base, scale, top, k);
	add(bins, k, as_bin(v));
}

AVX2 void sah_bins_fill_avx2(sah_bins *out, const sah_grid *g, const sah_prim *prims,
                             uint32_t begin, uint32_t end)
{
	const __m128 base = _mm_set_ps(0, g->lo[2], g->lo[1], g->lo[0]);
	const __m128 scale = _mm_set_ps(0, g->scale[2], g->scale[1], g->scale[0]);
	const __m128 top = _mm_set1_ps((float)(g->nb - 1));
	sah_bins odd;

	clear(out, g->nb);
	clear(&odd, g->nb);
#define ADD_AVX2(bins, i) add_prim(bins, &prims[i], base, scale, top)
	SAH_BINS_EVEN_ODD(out, &odd, begin, end, ADD_AVX2);
#undef ADD_AVX2
	merge(out, &odd, g->nb);
}

bool sah_cpu_has_avx2(void)
{
	__builtin_cpu_init();
	return __builtin_cpu_supports("avx2");
}

#else

bool sah_cpu_has_avx2(void)
{
	return false;
}

#endif
