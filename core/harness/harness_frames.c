/*
 * A run's strategy over an animated scene's frames. It runs in the run's
 * child after the usual series on frame 0, on that series' tree: frame 0
 * costs the series' median build, and each later frame is made (posed or
 * read), its primitives computed (untimed: an engine has them), then
 * rebuilt or updated (timed with its stages), validated and traced.
 */
#include <errno.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "harness/harness_frames.h"
#include "harness/harness_rays.h"
#include "util/util.h"

/* The brute-force check's rays: the same seed as a static run's. */
#define FRAME_RAY_SEED 0x5eedULL

void harness_frames_updater_close(struct frames_updater *u)
{
	for (uint32_t k = 0; k < u->stage_count; k++) {
		bvhlab_options_finish(&u->stage_opts[k]);
		bvhlab_plugin_close(u->stage_plugins[k]);
	}
	if (u->opts.values)
		bvhlab_options_finish(&u->opts);
	bvhlab_plugin_close(u->plugin);
}

static int open_stage(const struct frames_job *job, struct frames_updater *u, size_t k,
                      bvhlab_error *err)
{
	const struct config_animation *a = job->cb->animation;
	int r = bvhlab_plugin_open(a->refine[k].plugin, &u->stage_plugins[k], err);
	if (r < 0)
		return r;
	if (bvhlab_options_init(&u->stage_opts[k], bvhlab_plugin_builder(u->stage_plugins[k])) < 0) {
		bvhlab_plugin_close(u->stage_plugins[k]);
		error_set(err, "out of memory");
		return -ENOMEM;
	}
	u->stage_count++;
	if (!bvhlab_builder_refine(bvhlab_plugin_builder(u->stage_plugins[k]))) {
		error_set(err, "animation refine stage %zu: plugin '%s' has no refinement stage",
		          k + 1, a->refine[k].plugin);
		return -EINVAL;
	}
	return config_apply_anim_refine_options(job->cfg, job->cb, k, &u->stage_opts[k], err);
}

int harness_frames_updater_open(const struct frames_job *job, struct frames_updater *u,
                                bvhlab_error *err)
{
	const struct config_animation *a = job->cb->animation;
	int r = bvhlab_plugin_open(a->update, &u->plugin, err);
	if (r == 0 && !bvhlab_builder_update(bvhlab_plugin_builder(u->plugin))) {
		error_set(err, "animation update: plugin '%s' has no update function (ABI 1.4)",
		          a->update);
		r = -EINVAL;
	}
	/* Updates take no options from the config: the plugin's defaults,
	 * read into its struct once for the run. */
	if (r == 0 && bvhlab_options_init(&u->opts, bvhlab_plugin_builder(u->plugin)) < 0)
		r = -ENOMEM;
	if (r == 0)
		r = bvhlab_options_check(&u->opts, err);
	for (size_t k = 0; r == 0 && k < a->refine_count; k++)
		r = open_stage(job, u, k, err);
	return r;
}

bool harness_frames_rebuilds(const struct frames_job *job, uint32_t f)
{
	const struct config_animation *a = job->cb->animation;
	return !a || (a->rebuild_every && f % a->rebuild_every == 0);
}

int harness_frames_advance(const struct frames_job *job, const struct frames_updater *u,
                           uint32_t f, const bvhlab_build_input *in, bvhlab_tree *tree,
                           double *ms, bvhlab_error *err)
{
	bool rebuild = harness_frames_rebuilds(job, f);
	double t0 = util_now();
	int r = rebuild ? bvhlab_build(job->plugin, job->opts, in, job->threads, tree, err)
	                : bvhlab_update(u->plugin, &u->opts, in, job->threads, tree, err);
	uint32_t n = rebuild ? job->stage_count : u->stage_count;
	for (uint32_t k = 0; r == 0 && k < n; k++)
		r = rebuild ? bvhlab_refine(job->stages[k].plugin, job->stages[k].opts, in, job->threads,
		                            tree, err)
		            : bvhlab_refine(u->stage_plugins[k], &u->stage_opts[k], in, job->threads,
		                            tree, err);
	*ms = (util_now() - t0) * 1e3;
	return r;
}

/* Structure always; brute-force rays on the first, middle and last frames. */
static int check(const struct frames_job *job, const bvhlab_scene *scene,
                 const bvhlab_build_input *in, const bvhlab_tree *tree,
                 struct frame_metrics *fm, bvhlab_error *err)
{
	uint32_t n = job->anim->frames, f = fm->frame;
	uint64_t mismatches = 0;
	fm->valid = bvhlab_validate_tree(tree, in, job->spatial_splits, err) == 0;
	if (!fm->valid || !job->cfg->validate || !harness_frames_rays_frame(n, f))
		return 0;
	fm->rays_checked = true;
	int r = bvhlab_validate_rays(tree, scene, job->cfg->validate_rays, FRAME_RAY_SEED,
	                             &mismatches, err);
	if (r == 0 && mismatches) {
		fm->valid = false;
		error_set(err, "%llu of %u sampled rays disagree with brute force",
		          (unsigned long long)mismatches, job->cfg->validate_rays);
	}
	return r;
}

void harness_frames_ray_settings(const struct config *cfg, struct ray_settings *rs)
{
	harness_ray_settings(cfg, rs);
	rs->diffuse = 0;
	rs->kinds = 1u << RAY_PRIMARY; /* a frame reports its primary rays only */
	rs->min_ms /= rs->rounds;
	rs->min_repeats = 1;
}

void harness_frames_cost(const struct config *cfg, const bvhlab_trace_timing *t,
                         struct frame_metrics *fm)
{
	if (t) {
		fm->nodes_per_ray = t->stats.rays ? (double)t->stats.nodes_visited / t->stats.rays : 0;
		fm->mrays_per_s = t->mrays_best;
		fm->traced = t->stats.rays > 0 && t->mrays_best > 0;
	}
	/* Untraced rays are not free: such a frame's cost stays unknown. */
	fm->costed = fm->traced || cfg->rays_per_frame == 0;
	fm->cost_ms = fm->update_ms;
	if (fm->traced)
		fm->cost_ms += (double)cfg->rays_per_frame / (fm->mrays_per_s * 1e3);
}

/* SAH, and the primary rays of frame 0's camera, in one short stretch. */
static void measure(const struct frames_job *job, const bvhlab_scene *scene,
                    const bvhlab_tree *tree, const bvhlab_camera *cam,
                    struct frame_metrics *fm)
{
	bvhlab_tree_stats st;
	struct ray_settings rs;
	struct ray_metrics m = {0};
	bvhlab_tree_stats_compute(tree, &st);
	fm->sah = st.sah_cost;
	harness_frames_ray_settings(job->cfg, &rs);
	bool traced = rs.width && rs.height &&
	              harness_trace_rays(tree, scene, cam, &rs, &m, NULL, NULL) == 0;
	harness_frames_cost(job->cfg, traced ? &m.primary[rs.main] : NULL, fm);
}

/* Frame f's scene and primitives, with the triangles of frame 0. */
static int make_frame(const struct frames_job *job, const struct harness_anim *a, uint32_t f,
                      bvhlab_scene **scene, bvhlab_prims *prims, bvhlab_error *err)
{
	int r = f == 0 ? 0 : harness_anim_frame(a, f, scene, err);
	const bvhlab_scene *s = f == 0 ? job->first : *scene;
	if (r == 0 && s->triangle_count != job->first->triangle_count) {
		error_set(err, "frame %u of scene '%s' has %u triangles, the first %u", f,
		          job->first->name, s->triangle_count, job->first->triangle_count);
		r = -EINVAL;
	}
	return r == 0 ? bvhlab_prims_init(prims, s, err) : r;
}

static int one_frame(const struct frames_job *job, const struct harness_anim *a,
                     const struct frames_updater *u, uint32_t f, const bvhlab_camera *cam,
                     bvhlab_tree *tree, struct frame_metrics *fm, bvhlab_error *err)
{
	bvhlab_scene *scene = NULL;
	bvhlab_prims prims = {0};
	bool rebuilt = f == 0 || harness_frames_rebuilds(job, f);
	*fm = (struct frame_metrics){.frame = f, .rebuilt = rebuilt, .update_ms = job->first_ms};
	int r = make_frame(job, a, f, &scene, &prims, err);
	if (r == 0 && f > 0)
		r = harness_frames_advance(job, u, f, &prims.input, tree, &fm->update_ms, err);
	if (r == 0)
		r = check(job, scene ? scene : job->first, &prims.input, tree, fm, err);
	if (r == 0 && fm->valid)
		measure(job, scene ? scene : job->first, tree, cam, fm);
	if (r < 0 || !fm->valid)
		error_prefix(err, "frame %u", f);
	bvhlab_prims_finish(&prims);
	bvhlab_scene_destroy(scene);
	return r < 0 ? r : fm->valid ? 0 : 1;
}

int harness_frames_run(const struct frames_job *job, bvhlab_tree *tree,
                       struct frame_metrics *out, uint32_t *count, bvhlab_error *err)
{
	struct frames_updater u = {0};
	struct harness_anim a = *job->anim;
	bvhlab_camera cam;
	int r = job->cb->animation ? harness_frames_updater_open(job, &u, err) : 0;
	a.first = job->first; /* frame files are checked against it */
	harness_camera(job->cfg, job->first, &cam);
	*count = 0;
	for (uint32_t f = 0; r == 0 && f < a.frames; f++) {
		r = one_frame(job, &a, &u, f, &cam, tree, &out[f], err);
		if (r >= 0)
			*count = f + 1;
	}
	harness_frames_updater_close(&u);
	return r;
}

int harness_frames_after_series(const struct config *cfg, const struct harness_builder *hb,
                                const struct harness_anim *a, const bvhlab_scene *first,
                                uint32_t threads, double *samples, uint32_t repeat,
                                bvhlab_tree *tree, uint32_t *count, bvhlab_error *err)
{
	double mn, mx, median;
	const bvhlab_builder *desc = bvhlab_plugin_builder(hb->plugin);
	if (!a->frames)
		return 0; /* a static scene */
	util_summarise(samples, repeat, &median, &mn, &mx);
	struct frames_job job = {.cfg = cfg, .cb = hb->cb, .anim = a, .first = first,
	                         .plugin = hb->plugin, .opts = &hb->opts, .stages = hb->refine,
	                         .stage_count = (uint32_t)hb->cb->refine_count, .threads = threads,
	                         .spatial_splits = desc->flags & BVHLAB_BUILDER_SPATIAL_SPLITS,
	                         .first_ms = median};
	return harness_frames_run(&job, tree, (struct frame_metrics *)(samples + repeat), count, err);
}

void harness_frames_death(const struct config_builder *cb, uint32_t f, char *why, size_t size)
{
	char was[512];
	const struct config_animation *a = cb->animation;
	snprintf(was, sizeof(was), "%s", why);
	if (a && !(a->rebuild_every && f % a->rebuild_every == 0))
		snprintf(why, size, "frame %u, updated by '%s'%s: %s", f, a->update,
		         a->refine_count ? " and its refine stages" : "", was);
	else
		snprintf(why, size, "frame %u, rebuilt by '%s'%s: %s", f, cb->top ? cb->top : cb->plugin,
		         cb->top ? " (the top)" : "", was);
}
