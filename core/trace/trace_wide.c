/*
 * The wide traversal: the tree collapsed into 4-child nodes
 * (wide_bvh.c), four slab tests per node in one vector pass and a leaf's
 * triangles four at a time: trace_wide_body.h's kernel at four lanes, the
 * lanes of SSE on x86-64 and NEON on arm64 (x86 gets three SSE builtins
 * besides).
 */
#include "trace/trace_kernel.h"
#include "trace/trace_wide.h"

/* One lane per child box and per triangle of a group. (8 lanes were
 * tried: no faster, see README.) */
_Static_assert(WIDE == TRI_LANES, "node and triangle lanes share one vector type");

#define WB_LANES WIDE
#define WB_TRI_LANES TRI_LANES
#define WB_NODE struct wide_node
#define WB_TRIS struct wide_tris
#define WB_BVH struct wide_bvh
#define WB_STACK WIDE_STACK
#define WB(name) wide_##name

/* SSE's MAXPS/MINPS are exactly the generic selects and MOVMSKPS gathers
 * lane signs. */
#if defined(__SSE__) && defined(__GNUC__) && !defined(__clang__)
#define WB_MAX(a, b) __builtin_ia32_maxps(a, b)
#define WB_MIN(a, b) __builtin_ia32_minps(a, b)
#define WB_BITS(m) ((unsigned)__builtin_ia32_movmskps((vf)(m)))
#define WB_TBITS WB_BITS
#endif

#include "trace/trace_wide_body.h"

void trace_ray_wide(const bvhlab_tree *tree, const bvhlab_scene *scene,
                    const struct trace_view *view, const bvhlab_ray *ray, bool any,
                    bvhlab_hit *hit, bvhlab_trace_stats *stats)
{
	wide_trace_ray(view->wide, wide_trace, tree, scene, view, ray, any, hit, stats);
}
