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

/* The options `leaves` and `max_leaf`, in a stage's table (plugin_options.h,
 * which the stage includes), into the members `leaves` (bool) and
 * `max_leaf` (int64_t) of its struct `owner`. */
#define LEAVES_OPTIONS(owner)                                                             \
	PLUGIN_OPTION(owner, leaves, BOOL, .name = "leaves",                              \
	              .help = "split leaves of several primitives first, so that their "  \
	                      "primitives can be rearranged too, and cut the tree into "  \
	                      "leaves by the SAH afterwards (kept only if the SAH fell)", \
	              .def_bool = true),                                                  \
	PLUGIN_MAX_LEAF(owner, max_leaf, I64, 64,                                         \
	                "most primitives in a leaf of that final cut (8, as the builders)")

/* A stage's own work between the split and the cut: 0, or a negative
 * errno after host->set_error. */
typedef int (*leaves_stage_fn)(void *arg, bvhlab_build_output *tree);

/*
 * Runs stage(arg, tree) with leaves split first when `split` (and the host
 * gives the room for the new nodes), then cuts the tree into leaves of at
 * most max_leaf by the SAH when it was split or `cut` asks for it, keeping
 * the cut tree only when its SAH is below the tree's as it came in (else
 * that tree is put back). 0, or a negative errno after host->set_error.
 */
int leaves_run(const bvhlab_host *host, bvhlab_build_ctx *ctx, const bvhlab_build_input *in,
               bvhlab_build_output *tree, bool split, bool cut, uint32_t max_leaf,
               leaves_stage_fn stage, void *arg);

/* At the end of a stage's file: its descriptor (PLUGIN_WITH_OPTIONS over
 * `table`), a refinement stage's: no build, its refine(), parallel and
 * deterministic; the arguments after the table name and describe it
 * (.name, .summary). */
#define LEAVES_STAGE_PLUGIN(table, ...)                                             \
	PLUGIN_WITH_OPTIONS(table,                                                  \
	                    .flags = BVHLAB_BUILDER_PARALLEL | BVHLAB_BUILDER_DETERMINISTIC, \
	                    .build = NULL, .refine = refine, __VA_ARGS__)

#endif /* BVHLAB_LEAVES_H */
