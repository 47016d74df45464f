/*
 * Coverage check for trees of spatial-split builders, whose leaf boxes may
 * hold only the part of a triangle that lies in them (validate_clip.c).
 */
#ifndef BVHLAB_CORE_VALIDATE_CLIP_H
#define BVHLAB_CORE_VALIDATE_CLIP_H

#include <stdint.h>

#include <bvhlab/tree.h>

/*
 * For a tree that passed the structural walk (slot_leaf[s] is the leaf
 * using prim_index slot s): every reference's leaf box overlaps its
 * triangle, and the parts of each triangle inside its references' leaf
 * boxes together cover all of it. Boxes are widened by a few float ulps
 * of their coordinates and 1e-6 of their extent (builders round clipped
 * boxes to float), and an uncovered area up to 1e-5 of the triangle's is
 * accepted; a zero-area triangle needs each vertex inside some box.
 * 0, -EINVAL with the primitive and leaf named in err, or -ENOMEM.
 */
int validate_coverage(const bvhlab_tree *tree, const bvhlab_build_input *input,
                      const uint32_t *slot_leaf, bvhlab_error *err);

#endif /* BVHLAB_CORE_VALIDATE_CLIP_H */
