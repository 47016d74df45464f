/*
 * Four-lane float vectors for the SAH kernel's hot loops: SSE2 where the
 * compiler targets it (every x86-64), plain C elsewhere. Both backends do
 * the same IEEE operations in the same order, so the tree never depends on
 * the backend. Lane 3 is padding: the loaders zero it, results ignore it.
 */
#ifndef BVHLAB_SAH_SIMD_H
#define BVHLAB_SAH_SIMD_H

#include <stdint.h>

#if defined(__SSE2__) && !defined(SAH_NO_SIMD) /* SAH_NO_SIMD: test the plain C backend */
#include <emmintrin.h>

typedef __m128 v4;

/* p[0..2] and zero; reads 16 bytes, so p[3] must be readable memory (the
 * sah_prim fields after lo and hi are). */
static inline v4 v4_load3(const float *p)
{
	const __m128 mask = _mm_castsi128_ps(_mm_set_epi32(0, -1, -1, -1));
	return _mm_and_ps(_mm_loadu_ps(p), mask);
}
static inline v4 v4_load(const float *p) { return _mm_loadu_ps(p); }
static inline v4 v4_set3(float x, float y, float z) { return _mm_set_ps(0, z, y, x); }
static inline v4 v4_set1(float x) { return _mm_set1_ps(x); }
static inline void v4_store(float *p, v4 a) { _mm_storeu_ps(p, a); }
static inline v4 v4_add(v4 a, v4 b) { return _mm_add_ps(a, b); }
static inline v4 v4_sub(v4 a, v4 b) { return _mm_sub_ps(a, b); }
static inline v4 v4_mul(v4 a, v4 b) { return _mm_mul_ps(a, b); }
/* Per lane a < b ? a : b, and a > b ? a : b: the minps/maxps rule. */
static inline v4 v4_min(v4 a, v4 b) { return _mm_min_ps(a, b); }
static inline v4 v4_max(v4 a, v4 b) { return _mm_max_ps(a, b); }
/* -a, exactly (the sign bit flipped). */
static inline v4 v4_neg(v4 a) { return _mm_xor_ps(a, _mm_set1_ps(-0.0f)); }
/* Truncates lanes known to be in [0, 2^31). */
static inline void v4_trunc(v4 a, int32_t out[4])
{
	_mm_storeu_si128((__m128i *)out, _mm_cvttps_epi32(a));
}

#else

typedef struct v4 {
	float f[4];
} v4;

static inline v4 v4_load3(const float *p) { return (v4){ { p[0], p[1], p[2], 0 } }; }
static inline v4 v4_load(const float *p) { return (v4){ { p[0], p[1], p[2], p[3] } }; }
static inline v4 v4_set3(float x, float y, float z) { return (v4){ { x, y, z, 0 } }; }
static inline v4 v4_set1(float x) { return (v4){ { x, x, x, x } }; }
static inline void v4_store(float *p, v4 a)
{
	for (int k = 0; k < 4; k++)
		p[k] = a.f[k];
}
#define V4_LANES(expr) \
	v4 r; \
	for (int k = 0; k < 4; k++) \
		r.f[k] = (expr); \
	return r
static inline v4 v4_add(v4 a, v4 b) { V4_LANES(a.f[k] + b.f[k]); }
static inline v4 v4_sub(v4 a, v4 b) { V4_LANES(a.f[k] - b.f[k]); }
static inline v4 v4_mul(v4 a, v4 b) { V4_LANES(a.f[k] * b.f[k]); }
static inline v4 v4_min(v4 a, v4 b) { V4_LANES(a.f[k] < b.f[k] ? a.f[k] : b.f[k]); }
static inline v4 v4_max(v4 a, v4 b) { V4_LANES(a.f[k] > b.f[k] ? a.f[k] : b.f[k]); }
static inline v4 v4_neg(v4 a) { V4_LANES(-a.f[k]); }
#undef V4_LANES
static inline void v4_trunc(v4 a, int32_t out[4])
{
	for (int k = 0; k < 4; k++)
		out[k] = (int32_t)a.f[k];
}

#endif

/* Lanes 0..2 into p[0..2]. */
static inline void v4_store3(float *p, v4 a)
{
	float t[4];

	v4_store(t, a);
	p[0] = t[0];
	p[1] = t[1];
	p[2] = t[2];
}

/* Half the surface area of the box [lo, hi], summed in the same order as
 * the scalar bvhlab_aabb_half_area: (dx*dy + dy*dz) + dz*dx. The SSE version stays
 * in registers: a store and three loads per area cost more than the area
 * in the sweeps' inner loops. */
#if defined(__SSE2__) && !defined(SAH_NO_SIMD)
static inline float v4_half_area(v4 lo, v4 hi)
{
	__m128 d = _mm_sub_ps(hi, lo);
	__m128 p = _mm_mul_ps(d, _mm_shuffle_ps(d, d, _MM_SHUFFLE(3, 0, 2, 1)));
	__m128 s = _mm_add_ss(p, _mm_shuffle_ps(p, p, _MM_SHUFFLE(3, 3, 3, 1)));
	return _mm_cvtss_f32(_mm_add_ss(s, _mm_movehl_ps(p, p)));
}
#else
static inline float v4_half_area(v4 lo, v4 hi)
{
	float d[4];

	v4_store(d, v4_sub(hi, lo));
	return d[0] * d[1] + d[1] * d[2] + d[2] * d[0];
}
#endif

#endif /* BVHLAB_SAH_SIMD_H */
