/*
 * An animated config scene (docs/animation.md): its meshes loaded once, at
 * rest, and any frame made from them on demand, or read from its frame
 * file and checked against the first frame's topology.
 */
#ifndef BVHLAB_CORE_HARNESS_ANIM_H
#define BVHLAB_CORE_HARNESS_ANIM_H

#include <stdint.h>

#include <bvhlab/bvhlab.h>

#include "config/config.h"
#include "scene/instances.h"
#include "scene/scene_anim.h"

struct harness_anim {
	const struct config_scene *cs;
	uint32_t frames;              /* 0: not animated (nothing else is set) */
	bvhlab_scene **meshes;        /* [mesh_count] at rest, in their own frame */
	struct scene_motion *motions; /* [mesh_count] */
	uint32_t mesh_count;          /* parts, or 1; 0 for frame files */
	const bvhlab_scene *first;    /* frame 0, which frame files must match */
	/* An animated two-level scene (harness_anim_inst.c): its instances at
	 * rest (not owned); its frames are those instances posed, and, for the
	 * builders of one-level trees, flattened. NULL otherwise. */
	const struct scene_instanced *inst;
};

/* Whether the config scene is animated ("frames"). */
static inline bool harness_anim_on(const struct config_scene *cs)
{
	return cs->frames > 0;
}

/* Loads the scene's meshes (a frame-file scene loads none). 0 or a negative
 * errno with err naming the scene (and the part). */
int harness_anim_open(const struct config_scene *cs, struct harness_anim *a, bvhlab_error *err);
/* Frees what open loaded and zeroes a (frames 0); fine on a zeroed one. */
void harness_anim_close(struct harness_anim *a);

/* The sweep's scene: harness_load_scene's for a static scene (a->frames
 * 0), else the animation opened into a and its frame 0. */
int harness_anim_load(const struct config_scene *cs, struct harness_anim *a,
                      bvhlab_scene **scene, bvhlab_error *err);

/*
 * Frame f (< a->frames) as a new scene, named as the config says. A frame
 * file whose triangles differ from the first frame's (count, or the
 * vertices they join) is -EINVAL with err naming the file; a->first must be
 * set for that check (frame 0 itself needs none).
 */
int harness_anim_frame(const struct harness_anim *a, uint32_t f, bvhlab_scene **out,
                       bvhlab_error *err);

/* ---- animated two-level scenes (harness_anim_inst.c) ---- */

/* a for the two-level scene cs, whose instances at rest are inst (kept by
 * the caller for as long as a): frames 0 for a static scene. */
void harness_anim_instanced(const struct config_scene *cs, const struct scene_instanced *inst,
                            struct harness_anim *a);

/*
 * Frame f's instances (a->inst set) into *out: the rest's meshes, shared,
 * and instances of its own, each that moves posed at f (its inverse with
 * it). 0, -ENOMEM or -EINVAL (err says why); free it with
 * harness_anim_posed_finish, never scene_instanced_finish.
 */
int harness_anim_pose_instances(const struct harness_anim *a, uint32_t f,
                                struct scene_instanced *out, bvhlab_error *err);
void harness_anim_posed_finish(struct scene_instanced *posed);

/* Frame f posed and flattened, named as the scene (harness_anim_frame's
 * for a two-level scene). */
int harness_anim_flat_frame(const struct harness_anim *a, uint32_t f, bvhlab_scene **out,
                            bvhlab_error *err);

#endif
