/*
 * The split searches behind sah_split_job (sah_kernel.c dispatches to
 * them) and the builder set-up helpers it calls: implemented by
 * sah_sweep.c, sah_binned.c, sah_small.c and sah_prims.c, which use
 * sah_nodes.h and sah_bins.h and never call back into the dispatcher.
 * Plugins include sah_kernel.h only.
 */
#ifndef BVHLAB_SAH_SPLIT_H
#define BVHLAB_SAH_SPLIT_H

#include "sah_types.h"

/*
 * Copies the input boxes into dst (prim_count records, id order) and sets
 * b->root_cbox; with input->threads > 1 the parts are copied by that many
 * threads at once (sah_prims.c).
 */
void sah_copy_prims(sah_builder *b, const bvhlab_build_input *input, sah_prim *dst);

/* Jobs of at most this many primitives are built whole by
 * sah_small_subtree (exact SAH on local copies, see sah_small.c). Local
 * indices are bytes, so at most 256. */
#define SAH_SMALL_MAX 64

/* Builds job's whole subtree on the calling thread: quality high
 * (sah_small.c) and fast (sah_small_fast.c). */
void sah_small_subtree(sah_builder *b, const sah_job *job);
void sah_small_fast_subtree(sah_builder *b, const sah_job *job);

/* The methods behind sah_split_job; same contract. */
unsigned sah_sweep_split(sah_builder *b, const sah_job *job, sah_job child[2]);
unsigned sah_binned_split(sah_builder *b, const sah_job *job, sah_job child[2]);

/*
 * Fills b->prims[0..2] with the primitives sorted by centroid along each
 * axis (stable, so ties stay in id order). 0 or -ENOMEM.
 */
int sah_presort(sah_builder *b);

#endif /* BVHLAB_SAH_SPLIT_H */
