/*
 * Exact clipping of a triangle to boxes and planes, for spatial-split
 * builders (sbvh, and the embree plugin's split callback). A reference to
 * a triangle stands for the part of it inside the reference's box; these
 * helpers keep that part as a convex polygon (in double, so clipping a
 * float triangle does not drift) and give its box rounded outwards to
 * float, so a box never loses a sliver of its triangle.
 */
#ifndef BVHLAB_TRI_CLIP_H
#define BVHLAB_TRI_CLIP_H

#include <bvhlab/clip.h>
#include <bvhlab/types.h>

/* A convex polygon (the clipper is <bvhlab/clip.h>, shared with the
 * validator); n == 0 is empty. */
typedef bvhlab_poly tri_poly;

/* Keeps the part of p inside box (closed). */
void tri_poly_clip_box(tri_poly *p, const bvhlab_aabb *box);

/* The parts of p with x[axis] <= pos (left) and >= pos (right); points on
 * the plane get x[axis] = pos exactly. */
void tri_poly_split(const tri_poly *p, int axis, double pos, tri_poly *left,
                    tri_poly *right);

/* The box of p rounded outwards to float, intersected with `within`; an
 * empty polygon gives an empty box (lo = +inf, hi = -inf). */
void tri_poly_bounds(const tri_poly *p, const bvhlab_aabb *within, bvhlab_aabb *out);

/*
 * The boxes of the part of triangle `tri` inside `box` on either side of
 * the plane x[axis] = pos (each within box; empty when that side has
 * nothing of the triangle).
 */
void tri_clip_split(const float *vertices, const uint32_t *tri, const bvhlab_aabb *box,
                    int axis, float pos, bvhlab_aabb *left, bvhlab_aabb *right);

#endif /* BVHLAB_TRI_CLIP_H */
