/*
 * Refinement stages (reinsert, treelet) can only rearrange whole nodes,
 * and the SAH builders keep most primitives in leaves of several. With
 * their `leaves` option on, a stage first splits every such leaf into a
 * balanced subtree of one-primitive leaves, refines, and then cuts the
 * tree into leaves again by the SAH; the result is kept only when its SAH
 * is lower than the tree's as it came in (leaves.c). A static library
 * linked into each stage that uses it.
 */
#ifndef BVHLAB_LEAVES_H
#define BVHLAB_LEAVES_H

#include <stdbool.h>
#include <stdint.h>

#include <bvhlab/builder.h>

/* The options `leaves` and `max_leaf`, in a stage's option array. */
#define LEAVES_OPTION_DECLS                                                                 \
	{ .name = "leaves", .type = BVHLAB_OPTION_BOOL,                                     \
	  .help = "split leaves of several primitives first, so that their primitives can " \
	          "be rearranged too, and cut the tree into leaves by the SAH afterwards "  \
	          "(kept only if the SAH fell)",                                            \
	  .def_bool = true },                                                               \
	{ .name = "max_leaf", .type = BVHLAB_OPTION_INT,                                    \
	  .help = "most primitives in a leaf of that final cut (8, as the builders)",       \
	  .def_int = 8, .min = 1, .max = 64 }

/* The tree as it came in, to put back if splitting leaves did not pay. */
typedef struct leaves_saved {
	bvhlab_node *nodes;
	uint32_t *index;
	uint32_t node_count;
	double sah;
} leaves_saved;

/* A copy of t: 0 or -ENOMEM (leaves_finish frees what was taken). */
int leaves_save(leaves_saved *s, const bvhlab_build_output *t);
void leaves_finish(leaves_saved *s);

/* Splits every leaf of t, growing the output for the new nodes; false
 * (t untouched) when the host refuses the room. */
bool leaves_split(const bvhlab_host *host, bvhlab_build_ctx *ctx,
                  const bvhlab_build_input *in, bvhlab_build_output *t);

/* Cuts the split tree into leaves of at most max_leaf by the SAH and
 * keeps it only when its SAH is below s's; else puts s back. 0 or
 * -ENOMEM (t is then s's tree again). */
int leaves_collapse_or_restore(const leaves_saved *s, bvhlab_build_output *t,
                               uint32_t max_leaf);

/* The SAH cost as the core's metric computes it (c_trav = c_isect = 1). */
double leaves_sah(const bvhlab_node *nodes, uint32_t count);

#endif /* BVHLAB_LEAVES_H */
