/*
 * The 8-lane wide traversal (rays.traversal "wide8") of an 8-wide tree as
 * built: trace_wide.c's design at eight lanes, nearest child first, the
 * others on a stack with their entry distances. The kernel
 * (trace_wide8_body.h) is compiled three times, portable (GCC's generic
 * vectors, two SSE halves on a plain x86-64 build), with AVX2 and with
 * AVX-512VL (256-bit vectors, compares into mask registers), and the
 * widest the CPU has is taken when the view is made (BVHLAB_WIDE8_ISA
 * = portable|avx2|avx512 picks one, for tests and comparisons).
 */
#include <stdlib.h>
#include <string.h>

#include "trace/trace_kernel.h"
#include "trace/trace_wide8.h"

/* At most 7 entries per wide level: deeper trees go to the stack traversal. */
#define WIDE8_STACK 512

/* 32-byte vectors pass between this file's static functions only, so the
 * calling convention GCC warns about never meets other code. */
#if defined(__GNUC__) && !defined(__clang__)
#pragma GCC diagnostic ignored "-Wpsabi"
#endif

typedef float vf8 __attribute__((vector_size(32)));
typedef int32_t vi8 __attribute__((vector_size(32)));

struct w8_entry {
	uint32_t child, count; /* count 0: an inner lane, else a leaf's triangles */
	float t;
};

struct w8_ray {
	ray_prep *p;
	bool sheared;
	vf8 org[3], inv[3];
	vf8 sx, sy;
	int near[3], far[3];
};

struct w8_walk {
	const struct wide8_bvh *bvh;
	bvhlab_hit *hit;
	uint64_t nodes, tris;
	bool any;
};

/* isect() and take_hit() on lane i of a group. */
static bool isect_lane8(const ray_prep *p, const struct wide8_tris *g, uint32_t i,
                        bvhlab_hit *hit)
{
	float v[3][3], out[3];
	for (int j = 0; j < 3; j++)
		for (int k = 0; k < 3; k++)
			v[j][k] = g->v[3 * j + k][i];
	return isect(p, v[0], v[1], v[2], hit->t, out) && take_hit(hit, g->prim[i], out);
}

/* The entered lanes, nearest first. */
static uint32_t sort_lanes8(const struct wide8_node *n, unsigned mask, const float *t,
                            struct w8_entry e[WIDE8])
{
	uint32_t m = 0;
	for (; mask; mask &= mask - 1) {
		uint32_t i = (uint32_t)__builtin_ctz(mask);
		struct w8_entry x = {n->child[i], n->count[i], t[i]};
		uint32_t j = m++;
		for (; j > 0 && e[j - 1].t > x.t; j--)
			e[j] = e[j - 1];
		e[j] = x;
	}
	return m;
}

static inline void prefetch8(const struct wide8_bvh *b, const struct w8_entry *e)
{
	const char *p = e->count == 0 ? (const char *)&b->nodes[e->child]
	                              : (const char *)&b->tris[e->child];
	size_t size = e->count == 0 ? sizeof(struct wide8_node) : sizeof(struct wide8_tris);
	for (size_t line = 0; line < size; line += 64)
		__builtin_prefetch(p + line);
}

/* Portable: selects written as box_enter() writes them (a NaN in a leaves b). */
static inline vf8 generic_max(vf8 a, vf8 b)
{
	vi8 m = a > b;
	return (vf8)((m & (vi8)a) | (~m & (vi8)b));
}

static inline vf8 generic_min(vf8 a, vf8 b)
{
	vi8 m = a < b;
	return (vf8)((m & (vi8)a) | (~m & (vi8)b));
}

static inline unsigned generic_bits(vi8 m)
{
	unsigned bits = 0;
	for (int i = 0; i < WIDE8; i++)
		bits |= (unsigned)(m[i] & 1) << i;
	return bits;
}

#define W8(name) portable_##name
#define W8_MAX generic_max
#define W8_MIN generic_min
#define W8_BITS generic_bits
#include "trace/trace_wide8_body.h"
#undef W8
#undef W8_MAX
#undef W8_MIN
#undef W8_BITS

#if defined(__x86_64__) && defined(__GNUC__) && !defined(__clang__)
#define X86_PATHS 1
/* VMAXPS/VMINPS are exactly the selects above; VMOVMSKPS the sign gather. */
#define W8_MAX(a, b) __builtin_ia32_maxps256(a, b)
#define W8_MIN(a, b) __builtin_ia32_minps256(a, b)
#define W8_BITS(m) ((unsigned)__builtin_ia32_movmskps256((vf8)(m)))

#pragma GCC push_options
#pragma GCC target("avx2")
#define W8(name) avx2_##name
#include "trace/trace_wide8_body.h"
#undef W8
#pragma GCC pop_options

#pragma GCC push_options
#pragma GCC target("avx2,avx512f,avx512vl")
#define W8(name) avx512_##name
#include "trace/trace_wide8_body.h"
#undef W8
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
	const struct wide8_bvh *b = view->wide8;
	if (!b || b->depth * (WIDE8 - 1) + 1 > WIDE8_STACK) {
		trace_ray_stack(tree, scene, view, ray, any, hit, stats);
		return;
	}
	struct w8_walk w = {b, hit, 0, 0, any};
	ray_prep p;
	hit->t = ray->tmax;
	hit->u = hit->v = 0.0f;
	hit->prim = BVHLAB_NO_HIT;
	if (prep_box(ray, &p) && box_enter(&p, &view->nodes[0], hit->t) != INFINITY) {
#if X86_PATHS
		if (view->wide8_isa == ISA_AVX512)
			avx512_trace(&w, &p);
		else if (view->wide8_isa == ISA_AVX2)
			avx2_trace(&w, &p);
		else
#endif
			portable_trace(&w, &p);
	}
	if (stats) {
		stats->rays++;
		stats->nodes_visited += w.nodes;
		stats->tris_tested += w.tris;
	}
}

int trace_wide8_pick(void)
{
	return pick_isa();
}
