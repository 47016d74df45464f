/*
 * Rigid motion by rebuilding the top: an animated two-level scene's
 * instances move, their meshes do not, so each frame needs only a new top
 * level over the instances' new world boxes: rebuilt by the top plugin
 * ("rebuild the top only"), or updated by the builder's animation's
 * update plugin ("refit the top"), rebuilt every K frames with its
 * "rebuild_every". The bottom trees of the series serve every frame. The
 * boxes are computed untimed, as a one-level frame's primitives are.
 */
#include <errno.h>
#include <stdlib.h>

#include "harness/harness_anim_top.h"
#include "harness/harness_frames.h"
#include "harness/harness_measure.h"
#include "harness/harness_report.h"
#include "trace/trace_instances.h"
#include "util/util.h"

struct top_frames {
	const struct config *cfg;
	const struct harness_anim *a;
	struct frames_job job; /* the top's plugin, options and the animation */
	struct frames_updater u;
	struct two_level_trees *trees;
	const bvhlab_camera *cam; /* frame 0's; NULL: no rays timed */
	double *mesh_sah;      /* [mesh_count] each bottom tree's SAH */
};

/* The top's input: the posed instances' world boxes. */
static int top_boxes(const struct scene_instanced *posed, bvhlab_prims *prims,
                     bvhlab_error *err)
{
	bvhlab_aabb *boxes = malloc((size_t)posed->instance_count * sizeof(*boxes));
	if (!boxes) {
		error_set(err, "out of memory for %u instance boxes", posed->instance_count);
		return -ENOMEM;
	}
	for (uint32_t i = 0; i < posed->instance_count; i++)
		scene_instanced_box(posed, i, &boxes[i]);
	bvhlab_prims_finish(prims);
	int r = bvhlab_prims_init_boxes(prims, boxes, posed->instance_count, err);
	free(boxes);
	return r;
}

/* Both levels: the top's structure every frame (the bottom trees, never
 * changed, were judged by the series); on the first, middle and last
 * frames sampled rays through both against brute force over every
 * instanced triangle of the frame. */
static void check(const struct top_frames *tf, const struct scene_instanced *posed,
                  struct frame_metrics *fm, bvhlab_error *err)
{
	uint32_t n = tf->a->frames, f = fm->frame, rays = tf->cfg->validate_rays;
	struct trace_two_level tl = {.inst = posed, .top = &tf->trees->top,
	                             .bottom = tf->trees->bottom};
	uint64_t mismatches = 0;
	fm->valid = bvhlab_validate_tree(&tf->trees->top, &tf->trees->top_prims.input, false,
	                                 err) == 0;
	if (!fm->valid)
		error_prefix(err, "top tree");
	if (!fm->valid || !tf->cfg->validate || !harness_frames_rays_frame(n, f))
		return;
	fm->rays_checked = true;
	trace_two_level_check(&tl, NULL, rays, HARNESS_RAY_SEED, &mismatches, NULL);
	if (mismatches) {
		fm->valid = false;
		error_set(err, "%llu of %u sampled rays through both levels disagree with brute "
		          "force over the instanced triangles", (unsigned long long)mismatches, rays);
	}
}

/* The two-level SAH, and the primary rays of frame 0's camera through
 * both levels, in one short stretch, as a one-level frame's. */
static void measure(const struct top_frames *tf, const struct scene_instanced *posed,
                    struct frame_metrics *fm)
{
	bvhlab_tree_stats st;
	struct trace_two_level tl = {.inst = posed, .top = &tf->trees->top,
	                             .bottom = tf->trees->bottom};
	bvhlab_tree_stats_compute(&tf->trees->top, &st);
	const bvhlab_aabb *boxes = tf->trees->top_prims.input.prim_bounds;
	fm->sah = harness_two_level_sah(posed, &tf->trees->top, boxes, st.sah_cost, tf->mesh_sah);
	harness_two_level_frame_rays(tf->cfg, &tl, tf->cam, fm);
}

static int one_frame(struct top_frames *tf, uint32_t f, struct frame_metrics *fm,
                     bvhlab_error *err)
{
	struct scene_instanced posed;
	bool rebuilt = f == 0 || harness_frames_rebuilds(&tf->job, f);
	*fm = (struct frame_metrics){.frame = f, .rebuilt = rebuilt, .update_ms = tf->job.first_ms};
	int r = harness_anim_pose_instances(tf->a, f, &posed, err);
	if (r == 0 && f > 0)
		r = top_boxes(&posed, &tf->trees->top_prims, err);
	if (r == 0 && f > 0)
		r = harness_frames_advance(&tf->job, &tf->u, f, &tf->trees->top_prims.input,
		                           &tf->trees->top, &fm->update_ms, err);
	if (r == 0)
		check(tf, &posed, fm, err);
	if (r == 0 && fm->valid)
		measure(tf, &posed, fm);
	if (r < 0 || !fm->valid)
		error_prefix(err, "frame %u", f);
	harness_anim_posed_finish(&posed);
	return r < 0 ? r : fm->valid ? 0 : 1;
}

static int mesh_sahs(struct top_frames *tf, bvhlab_error *err)
{
	uint32_t n = tf->trees->mesh_count;
	bvhlab_tree_stats st;
	tf->mesh_sah = calloc(n, sizeof(*tf->mesh_sah));
	if (!tf->mesh_sah) {
		error_set(err, "out of memory");
		return -ENOMEM;
	}
	for (uint32_t m = 0; m < n; m++) {
		bvhlab_tree_stats_compute(&tf->trees->bottom[m], &st);
		tf->mesh_sah[m] = st.sah_cost;
	}
	return 0;
}

int harness_anim_top_frames(const struct config *cfg, const struct harness_builder *hb,
                            const struct harness_anim *a, struct two_level_trees *trees,
                            uint32_t threads, const bvhlab_camera *cam,
                            struct series_report *rep, bvhlab_error *err)
{
	double median, mn, mx;
	struct frame_metrics *out = (struct frame_metrics *)(rep->samples + cfg->repeat);
	if (!a || !a->frames)
		return 0;
	util_summarise(rep->samples, cfg->repeat, &median, &mn, &mx);
	struct top_frames tf = {.cfg = cfg, .a = a, .trees = trees, .cam = cam,
	                        .job = {.cfg = cfg, .cb = hb->cb, .anim = a,
	                                .plugin = hb->top.plugin, .opts = &hb->top.opts,
	                                .threads = threads, .first_ms = median}};
	rep->in_frames = true;
	rep->frame_count = 0;
	int r = mesh_sahs(&tf, err);
	if (r == 0 && hb->cb->animation)
		r = harness_frames_updater_open(&tf.job, &tf.u, err);
	for (uint32_t f = 0; r == 0 && f < a->frames; f++) {
		r = one_frame(&tf, f, &out[f], err);
		if (r >= 0)
			rep->frame_count = f + 1;
	}
	harness_frames_updater_close(&tf.u);
	free(tf.mesh_sah);
	return r;
}
