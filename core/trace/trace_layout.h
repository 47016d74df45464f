/*
 * The tracer's constants and buffer layouts, in the C that OpenCL C also
 * is: one definition for the CPU traversals (trace_kernel.h), the device
 * tracer's host side (trace_cl.c) and its kernels (trace_cl.cl, whose
 * program is tree_node.h, this file, then the kernels).
 *
 * Device buffers: nodes as tree_node.h's 32-byte nodes; the triangles'
 * vertices in leaf-slot order (TRACE_SLOT_FLOATS a slot, as the CPU batch
 * tracer's copy); prim_index; the parent links (stackless); rays as two
 * float4 (org + tmin, dir + tmax: bvhlab_ray); hits as uint4 (t, u, v
 * bits, prim: bvhlab_hit); per ray two uints, the nodes entered
 * (TRACE_OVERFLOW when the stack kernel's stack overflowed) and the
 * triangles tested. The kernels' arguments come in the order of enum
 * trace_arg.
 */
#ifndef BVHLAB_TRACE_LAYOUT_H
#define BVHLAB_TRACE_LAYOUT_H

/* The slab test rounds; Ize ("Robust BVH Ray Traversal", JCGT 2013) shows
 * scaling the far distance by 1 + 2 gamma(3) keeps it conservative. The
 * sheared triangle test has rounding of its own (a hit it reports may lie
 * a few ulps outside the triangle's exact box), so the margin is wider: a
 * few extra boxes visited cost nothing, a missed hit makes validation lie. */
#define FAR_SCALE (1.0f + 32.0f * FLT_EPSILON)

/* A ray that hit nothing (BVHLAB_NO_HIT), and a ray whose stack overflowed. */
#define TRACE_NO_HIT 0xffffffffu
#define TRACE_OVERFLOW 0xffffffffu
/* Floats of one leaf slot's triangle: three vertices. */
#define TRACE_SLOT_FLOATS 9
/* The stack kernel's private stack: at least this many entries (the host
 * builds a program per power of two at or above a tree's need). */
#define TRACE_MIN_STACK 64

/* The device kernels' arguments, by index (trace_cl.c sets them so). */
enum trace_arg {
	TRACE_ARG_NODES,
	TRACE_ARG_TRIS,
	TRACE_ARG_PRIM_INDEX,
	TRACE_ARG_PARENTS, /* wide8: the leaf ranges (trace_cl_wide8.cl) */
	TRACE_ARG_NODE_COUNT,
	TRACE_ARG_INDEX_COUNT,
	TRACE_ARG_TRI_COUNT,
	TRACE_ARG_RAYS,
	TRACE_ARG_RAY_COUNT,
	TRACE_ARG_ANY,
	TRACE_ARG_HITS,
	TRACE_ARG_COUNTS,
	TRACE_ARGS
};

/* A two-level scene's kernels (trace_cl_two_level.cl) take the arguments
 * above, with the bottom trees (every mesh's, one after another) as the
 * tree and node_total, index_count and tri_count unused, then these. */
enum trace_arg_two_level {
	TRACE_ARG_TOP = TRACE_ARGS, /* the top tree's nodes */
	TRACE_ARG_TOP_INDEX,        /* its prim_index: instance ids */
	TRACE_ARG_TOP_PARENTS,      /* its parent links (stackless) */
	TRACE_ARG_TOP_COUNT,        /* its node count */
	TRACE_ARG_TOP_INDEX_COUNT,  /* its prim_index's length */
	TRACE_ARG_MESHES,           /* TRACE_MESH_FIELDS uints per mesh */
	TRACE_ARG_INVERSE,          /* 12 doubles per instance: world to object, row-major 3x4 */
	TRACE_ARG_INSTANCE_MESH,    /* a uint per instance: its mesh */
	TRACE_ARG_INSTANCE_COUNT,
	TRACE_ARG_HIT_INSTANCE,     /* out: a uint per ray, the hit's instance */
	TRACE_ARGS_TWO_LEVEL
};

/* One mesh's place in the concatenated bottom trees: its first node (a
 * tree_node, or a cw_node for wide8), node count, first leaf slot (into
 * the vertices and prim_index), slot count, triangle count, and first
 * link (parent links: its first node's; wide8: its first leaf range). */
enum trace_mesh_field {
	TRACE_MESH_NODE_BASE,
	TRACE_MESH_NODES,
	TRACE_MESH_SLOT_BASE,
	TRACE_MESH_SLOTS,
	TRACE_MESH_TRIS,
	TRACE_MESH_LINK_BASE,
	TRACE_MESH_FIELDS
};

#endif /* BVHLAB_TRACE_LAYOUT_H */
