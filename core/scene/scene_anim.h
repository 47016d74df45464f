/*
 * Posing a mesh at a moment of an animation (private to the core): rigid
 * motion from a rest placement, a travelling wave along the normals, and
 * triangles flying apart (scene_anim.c; docs/animation.md).
 */
#ifndef BVHLAB_CORE_SCENE_ANIM_H
#define BVHLAB_CORE_SCENE_ANIM_H

#include <stdbool.h>
#include <stdint.h>

#include <bvhlab/scene.h>

enum scene_deform { SCENE_DEFORM_NONE, SCENE_DEFORM_WAVE, SCENE_DEFORM_EXPLODE };

/* Defaults of `amplitude`, as fractions of the mesh's extent (its box's
 * diagonal): a wave a few per cent high, fragments flying half of it. */
#define SCENE_WAVE_AMPLITUDE 0.02
#define SCENE_EXPLODE_AMPLITUDE 0.5

/* How one mesh moves over an animation, t from 0 (first frame) to 1 (last). */
struct scene_motion {
	bvhlab_transform rest;  /* where the mesh is placed at t = 0 */
	bool rigid;             /* the placement moves: */
	double rotate[3];       /* degrees added by t = 1 */
	double translate[3];    /* offset added by t = 1 */
	double scale;           /* factor reached by t = 1 */
	int deform;             /* enum scene_deform, in the mesh's own frame */
	double amplitude;       /* fraction of the mesh's extent; 0: the default */
	uint64_t seed;          /* explode: the directions */
};

/* A copy of base in which each triangle has its own three vertices (3k,
 * 3k + 1, 3k + 2): triangles that explode move apart. Same triangles, same
 * order. 0, -ENOMEM or -EOVERFLOW with err set. */
int scene_anim_unshare(const bvhlab_scene *base, bvhlab_scene **out, bvhlab_error *err);

/*
 * A copy of base (named and sourced alike) posed at t in [0, 1]: deformed
 * in base's own frame (the wave ramps up over the first quarter, so t = 0
 * is base itself), then placed by the rest transform moved t of the way
 * to its offset. An explode needs base unshared. 0 or -ENOMEM with err set.
 */
int scene_anim_pose(const bvhlab_scene *base, const struct scene_motion *m, double t,
                    bvhlab_scene **out, bvhlab_error *err);

#endif
