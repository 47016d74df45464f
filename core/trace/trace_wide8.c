/*
 * The 8-lane wide traversal (rays.traversal "wide8") of an 8-wide tree as
 * built: trace_wide_body.h's kernel at eight lanes, compiled three
 * times, portable (GCC's generic vectors, two SSE halves on a plain x86-64
 * build), with AVX2 and with AVX-512VL (256-bit vectors, compares into
 * mask registers), and the widest the CPU has is taken when the view is made (BVHLAB_WIDE8_ISA
 * = portable|avx2|avx512 picks one, for tests and comparisons).
 */
#include <stdlib.h>
#include <string.h>

#include "trace/trace_kernel.h"
#include "trace/trace_wide8.h"

/* 32-byte vectors pass between this file's static functions only, so the
 * calling convention GCC warns about never meets other code. */
#if defined(__GNUC__) && !defined(__clang__)
#pragma GCC diagnostic ignored "-Wpsabi"
#endif

#define WB_LANES WIDE8
#define WB_TRI_LANES TRI_LANES
#define WB_NODE struct wide8_node
#define WB_TRIS struct wide8_tris
#define WB_BVH struct wide8_bvh
#define WB_STACK WIDE8_STACK

#define WB(name) portable_##name
#include "trace/trace_wide_body.h"
#undef WB

#if defined(__x86_64__) && defined(__GNUC__) && !defined(__clang__)
#define X86_PATHS 1
/* VMAXPS/VMINPS are exactly the generic selects; VMOVMSKPS the sign gather. */
#define WB_MAX(a, b) __builtin_ia32_maxps256(a, b)
#define WB_MIN(a, b) __builtin_ia32_minps256(a, b)
#define WB_BITS(m) ((unsigned)__builtin_ia32_movmskps256((vf)(m)))
#define WB_TBITS(m) ((unsigned)__builtin_ia32_movmskps((vt)(m)))

#pragma GCC push_options
#pragma GCC target("avx2")
#define WB(name) avx2_##name
#include "trace/trace_wide_body.h"
#undef WB
#pragma GCC pop_options

#pragma GCC push_options
#pragma GCC target("avx2,avx512f,avx512vl")
#define WB(name) avx512_##name
#include "trace/trace_wide_body.h"
#undef WB
#pragma GCC pop_options
#else
#define X86_PATHS 0
#endif

enum isa { ISA_PORTABLE, ISA_AVX2, ISA_AVX512 };

/* The widest path this CPU runs, or the one BVHLAB_WIDE8_ISA names (no
 * wider than the CPU has). */
static int pick_isa(void)
{
	int best = ISA_PORTABLE;
#if X86_PATHS
	if (__builtin_cpu_supports("avx2"))
		best = ISA_AVX2;
	if (best == ISA_AVX2 && __builtin_cpu_supports("avx512f") &&
	    __builtin_cpu_supports("avx512vl"))
		best = ISA_AVX512;
#endif
	const char *want = getenv("BVHLAB_WIDE8_ISA");
	if (want && !strcmp(want, "portable"))
		return ISA_PORTABLE;
	if (want && !strcmp(want, "avx2") && best >= ISA_AVX2)
		return ISA_AVX2;
	return best;
}

const char *trace_wide8_isa(void)
{
	static const char *const names[] = {"portable", "avx2", "avx512"};
	return names[pick_isa()];
}

void trace_ray_wide8(const bvhlab_tree *tree, const bvhlab_scene *scene,
                     const struct trace_view *view, const bvhlab_ray *ray, bool any,
                     bvhlab_hit *hit, bvhlab_trace_stats *stats)
{
	wide_trace_fn *trace = portable_trace;
#if X86_PATHS
	if (view->wide8_isa == ISA_AVX512)
		trace = avx512_trace;
	else if (view->wide8_isa == ISA_AVX2)
		trace = avx2_trace;
#endif
	wide_trace_ray(view->wide8, trace, tree, scene, view, ray, any, hit, stats);
}

int trace_wide8_pick(void)
{
	return pick_isa();
}
