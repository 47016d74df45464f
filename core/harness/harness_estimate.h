/* A run's peak memory estimated before it starts (harness_estimate.c). */
#ifndef BVHLAB_CORE_HARNESS_ESTIMATE_H
#define BVHLAB_CORE_HARNESS_ESTIMATE_H

#include <stddef.h>

#include <bvhlab/bvhlab.h>

#include "config/config.h"
#include "harness/harness_builders.h"
#include "output/results.h"

/*
 * The run's peak from the scene's size and what its builder and refine
 * stages declare per primitive (bvhlab_builder.peak_bytes_per_prim, ABI
 * 1.7), or, when larger, what validation and tracing hold after the
 * builds (the tree, the checks, the tracing copies of the config's
 * traversals; `frames`: an animation's frames follow, so the builds'
 * scratch stays), against the builder's or the config's memory_limit_mb,
 * or without one the memory available now plus the scene's (resident
 * already). 0 when it fits or the limit is unknown; -E2BIG when it does
 * not, `why` naming scene, builder, the estimate and the limit. *e is
 * filled either way.
 */
int harness_estimate_run(const struct config *cfg, const struct harness_builder *hb,
                         const char *scene, const bvhlab_build_input *in, bool frames,
                         struct memory_estimate *e, char *why, size_t size);

struct scene_instanced; /* scene/instances.h */
/*
 * The same for a two-level run of builder hb over inst: the meshes' and
 * instances' arrays, per unique triangle the bottom build's declaration
 * (every bottom tree is held as built) plus validation's or tracing's
 * copies, per instance the top build's declaration plus its input and
 * tracing's (harness_estimate.c). *e's bytes_per_prim and
 * after_bytes_per_prim are per unique triangle; instances and
 * top_bytes_per_instance are set. 0, or -E2BIG with `why` naming scene,
 * builder, the estimate's parts and the limit.
 */
int harness_estimate_two_level(const struct config *cfg, const struct harness_builder *hb,
                               const char *scene, const struct scene_instanced *inst,
                               struct memory_estimate *e, char *why, size_t size);

#endif
