/*
 * The 8-lane wide traversal's copy of a tree (trace_wide8.c): an 8-wide
 * tree as built (wide_built.c), eight child boxes side by side per node
 * and triangles in groups of eight, so one node visit is one 256-bit slab
 * test (AVX2 or AVX-512VL, chosen at run time) and a leaf of up to eight
 * triangles one vector sign test. Empty lanes and groups are as in
 * trace_wide.h: count WIDE_EMPTY with an inverted box, NaN vertices.
 */
#ifndef BVHLAB_CORE_TRACE_WIDE8_H
#define BVHLAB_CORE_TRACE_WIDE8_H

#include <stdint.h>

#include "trace/trace_kernel.h"
#include "trace/trace_wide.h"

#define WIDE8 8
#define WIDE8_STACK 512 /* a ray's stack entries (at most 7 per wide level) */

/*
 * trace_wide.h's layout at 8 lanes: a node is 256 bytes, four cache
 * lines. Triangle groups keep trace_wide.h's 4 lanes (160 bytes): most
 * leaves of a collapsed tree hold 1 to 4 triangles, and 8-lane groups
 * (320 bytes, five lines) doubled the bytes a leaf visit reads
 * (docs/wide.md, "Why wide8 was slower than wide").
 */
WIDE_LAYOUT(wide8_node, wide8_tris, wide8_bvh, WIDE8, TRI_LANES);

/* The 8-lane traversal of view->wide8, as trace_ray_wide (trace_kernel.h). */
void trace_ray_wide8(const bvhlab_tree *tree, const bvhlab_scene *scene,
                     const struct trace_view *view, const bvhlab_ray *ray, bool any,
                     bvhlab_hit *hit, bvhlab_trace_stats *stats);

/* Which code path trace_ray_wide8 takes on this CPU: "avx512", "avx2" or
 * "portable" (GCC's generic vectors). */
const char *trace_wide8_isa(void);
/* The same as a code for trace_view.wide8_isa. */
int trace_wide8_pick(void);

#endif
