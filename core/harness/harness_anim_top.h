/*
 * The frames of a two-level run on an animated two-level scene
 * (harness_anim_top.c; docs/instances.md, "Animated instances"): the
 * bottom trees built once by the series and kept; per frame the top
 * rebuilt, or updated by the builder's "animation", over the moved
 * instances' boxes.
 */
#ifndef BVHLAB_CORE_HARNESS_ANIM_TOP_H
#define BVHLAB_CORE_HARNESS_ANIM_TOP_H

#include "config/config.h"
#include "harness/harness_anim.h"
#include "harness/harness_builders.h"
#include "harness/harness_two_level.h"

struct series_report; /* harness_report.h */

/*
 * After hb's series on a's frame 0 (trees its trees, rep->samples[repeat]
 * its times): frames 0 .. a->frames - 1 into the frame records after the
 * samples, rep->frame_count the frames done; rep->in_frames set when they
 * begin. Returns as harness_frames_run: 0, 1 for an invalid frame (err
 * names it), a negative errno for one that could not be made or built.
 * 0 at once for a static scene.
 */
int harness_anim_top_frames(const struct config *cfg, const struct harness_builder *hb,
                            const struct harness_anim *a, struct two_level_trees *trees,
                            uint32_t threads, const bvhlab_camera *cam,
                            struct series_report *rep, bvhlab_error *err);

#endif
