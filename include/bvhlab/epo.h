/*
 * bvhlab — end-point overlap (EPO), the tree metric of Aila, Karras and
 * Laine, "On Quality Metrics of Bounding Volume Hierarchies", HPG 2013.
 *
 * SAH assumes a ray that enters a box was aimed at it; EPO counts the
 * boxes a ray's end point lies in although the surface it ends on belongs
 * to another subtree: work that box overlap adds however well the areas
 * were split. With the node costs of the SAH in tree.h (k(n) / 2 per inner
 * node of k(n) children, 1 in a binary tree; count(l) per leaf):
 *
 *   EPO = sum over nodes n of c(n) * A(surface outside subtree(n) inside box(n))
 *         / A(all surface)
 *
 * estimated here from points spread uniformly over the triangles' area.
 * A point lying in box(n) counts c(n) unless its triangle is referenced
 * in n's subtree. Kept apart from tree.h so it can move as one block.
 */
#ifndef BVHLAB_EPO_H
#define BVHLAB_EPO_H

#include <stdint.h>

#include "scene.h"
#include "tree.h"

BVHLAB_BEGIN_DECLS

/*
 * EPO of a valid tree (bvhlab_validate_tree) over `scene`, from `samples`
 * points drawn with `seed`: the same tree, samples and seed always give
 * the same value. A point is placed on a triangle picked with probability
 * proportional to its area; triangles without area are never picked, and
 * a scene without area has EPO 0. Spatial-split trees: a point counts as
 * inside n's subtree when the first leaf found holding both it and its
 * triangle lies there. 0, -EINVAL (samples 0, links not a tree), -ENOMEM.
 */
int bvhlab_tree_epo(const bvhlab_tree *tree, const bvhlab_scene *scene, uint32_t samples,
                    uint64_t seed, double *epo);

BVHLAB_END_DECLS

#endif /* BVHLAB_EPO_H */
