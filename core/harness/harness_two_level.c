/*
 * Two-level builds: one bottom tree per mesh, reused by all its
 * instances, and a top tree over the instances' world boxes (a build over
 * boxes, ABI 1.5 BVHLAB_PRIM_BOXES). The two-level SAH (docs/instances.md)
 * weighs each instance's bottom tree by the chance a ray through the top
 * root enters its box.
 */
#include <errno.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "harness/harness_rays.h"
#include "harness/harness_anim_top.h"
#include "harness/harness_frames.h"
#include "harness/harness_memory.h"
#include "harness/harness_report.h"
#include "harness/harness_series.h"
#include "harness/harness_two_level.h"
#include "trace/trace_cl.h"
#include "trace/trace_instances.h"
#include "util/util.h"

/* A build's phase medians added to the run's, by name. */
static void add_phases(struct two_level_trees *trees, const struct build_series *s)
{
	for (uint32_t j = 0; j < s->phase_count; j++) {
		uint32_t row = 0;
		while (row < trees->phase_count && strcmp(trees->phases[row].name, s->phases[j].name))
			row++;
		if (row == BVHLAB_MAX_PHASES)
			continue;
		if (row == trees->phase_count)
			trees->phases[trees->phase_count++] = (bvhlab_phase){.ms = 0};
		memcpy(trees->phases[row].name, s->phases[j].name, sizeof(s->phases[j].name));
		trees->phases[row].ms += s->phases[j].ms;
	}
}

/* One level's series into `into` (summed), its median into *median_ms,
 * its phases into trees'. */
static int time_level(const struct two_level_job *job, const bvhlab_plugin *plugin,
                      const bvhlab_options *opts, const bvhlab_build_input *input,
                      double *into, double *cold_ms, double *median_ms, bvhlab_tree *tree,
                      struct two_level_trees *trees, bvhlab_error *err)
{
	double *samples = calloc(job->repeat, sizeof(*samples)), mn, mx, med;
	struct build_series s = {.warmup = job->warmup, .repeat = job->repeat,
	                         .threads = job->threads, .samples_ms = samples};
	if (!samples)
		return -ENOMEM;
	int r = harness_time_builds(plugin, opts, input, &s, err);
	if (r == 0) {
		for (uint32_t k = 0; k < job->repeat; k++)
			into[k] += samples[k];
		*cold_ms += s.cold_ms;
		util_summarise(samples, job->repeat, &med, &mn, &mx);
		*median_ms += med;
		add_phases(trees, &s);
	}
	*tree = s.tree;
	free(samples);
	return r;
}

/* The level's figures gain one tree's. */
static void add_tree(struct results_level *l, const bvhlab_tree_stats *st,
                     bvhlab_tree_stats *whole)
{
	l->trees++;
	l->nodes += st->nodes;
	l->leaves += st->leaves;
	l->sah += st->sah_cost;
	l->memory_bytes += st->memory_bytes;
	whole->nodes += st->nodes;
	whole->leaves += st->leaves;
	whole->refs += st->refs;
	whole->memory_bytes += st->memory_bytes;
	for (int k = 0; k < BVHLAB_LEAF_HISTOGRAM; k++)
		whole->leaf_histogram[k] += st->leaf_histogram[k];
}

static enum tree_verdict bottom_level(const struct two_level_job *job, double *samples,
                                      double *cold_ms, struct tree_measure *whole,
                                      struct results_two_level *lv, double *mesh_sah,
                                      struct two_level_trees *trees, bvhlab_error *err)
{
	bool spatial = bvhlab_plugin_builder(job->bottom)->flags & BVHLAB_BUILDER_SPATIAL_SPLITS;
	uint32_t depth = 0;
	for (uint32_t m = 0; m < job->inst->mesh_count; m++) {
		const bvhlab_scene *mesh = job->inst->meshes[m];
		bvhlab_prims prims = {0};
		struct tree_measure tm;
		int r = bvhlab_prims_init(&prims, mesh, err);
		if (r == 0)
			r = time_level(job, job->bottom, job->bottom_opts, &prims.input, samples, cold_ms,
			               &lv->bottom.build_ms, &trees->bottom[m], trees, err);
		enum tree_verdict v = r < 0 ? TREE_FAILED
			: harness_measure_tree(&trees->bottom[m], mesh, &prims.input, spatial,
			                       job->validate_rays, &tm, err);
		bvhlab_prims_finish(&prims);
		if (v != TREE_OK) {
			error_prefix(err, "bottom tree of mesh '%s'", mesh->name);
			return v;
		}
		whole->rays_checked += tm.rays_checked;
		mesh_sah[m] = tm.stats.sah_cost;
		depth = tm.stats.max_depth > depth ? tm.stats.max_depth : depth;
		add_tree(&lv->bottom, &tm.stats, &whole->stats);
	}
	lv->bottom.sah /= job->inst->mesh_count;
	whole->stats.max_depth = depth;
	return TREE_OK;
}

double harness_two_level_sah(const struct scene_instanced *inst, const bvhlab_tree *top,
                             const bvhlab_aabb *boxes, double top_sah, const double *mesh_sah)
{
	double root = bvhlab_box_area(top->nodes[0].lo, top->nodes[0].hi), sah = top_sah;
	for (uint32_t i = 0; root > 0 && i < inst->instance_count; i++)
		sah += bvhlab_box_area(boxes[i].lo, boxes[i].hi) / root *
		       mesh_sah[inst->instances[i].mesh];
	return sah;
}

static enum tree_verdict top_level(const struct two_level_job *job, double *samples,
                                   double *cold_ms, struct tree_measure *whole,
                                   struct results_two_level *lv, const double *mesh_sah,
                                   struct two_level_trees *trees, bvhlab_error *err)
{
	const struct scene_instanced *inst = job->inst;
	bvhlab_aabb *boxes = malloc((size_t)inst->instance_count * sizeof(*boxes));
	bvhlab_tree_stats st;
	if (!boxes)
		return error_set(err, "out of memory for %u instance boxes", inst->instance_count),
		       TREE_FAILED;
	for (uint32_t i = 0; i < inst->instance_count; i++)
		scene_instanced_box(inst, i, &boxes[i]);
	int r = bvhlab_prims_init_boxes(&trees->top_prims, boxes, inst->instance_count, err);
	if (r == 0)
		r = time_level(job, job->top, job->top_opts, &trees->top_prims.input, samples, cold_ms,
		               &lv->top.build_ms, &trees->top, trees, err);
	if (r == 0 && bvhlab_validate_tree(&trees->top, &trees->top_prims.input, false, err) != 0) {
		error_prefix(err, "top tree");
		free(boxes);
		return TREE_INVALID;
	}
	if (r < 0) {
		free(boxes);
		return TREE_FAILED;
	}
	bvhlab_tree_stats_compute(&trees->top, &st);
	add_tree(&lv->top, &st, &whole->stats);
	lv->sah = harness_two_level_sah(inst, &trees->top, boxes, st.sah_cost, mesh_sah);
	whole->stats.max_depth += st.max_depth + 1; /* a top leaf, then an instance's root */
	free(boxes);
	return TREE_OK;
}

/* Sampled rays through both levels against brute force over every
 * instanced triangle (trace_instances.c): any disagreement makes the run
 * invalid. */
static enum tree_verdict check_rays(const struct two_level_job *job,
                                    const struct two_level_trees *trees,
                                    struct tree_measure *whole, bvhlab_error *err)
{
	struct trace_two_level tl = {.inst = job->inst, .top = &trees->top,
	                             .bottom = trees->bottom};
	uint64_t mismatches;
	if (!job->validate_rays)
		return TREE_OK;
	trace_two_level_check(&tl, NULL, job->validate_rays, HARNESS_RAY_SEED, &mismatches, NULL);
	whole->rays_checked += job->validate_rays;
	whole->mismatches += mismatches;
	if (!mismatches)
		return TREE_OK;
	error_set(err, "%llu of %u sampled rays through both levels disagree with brute force "
	          "over the instanced triangles", (unsigned long long)mismatches,
	          job->validate_rays);
	return TREE_INVALID;
}

enum tree_verdict harness_two_level_series(const struct two_level_job *job,
                                           double *samples_ms, double *cold_ms,
                                           struct tree_measure *whole,
                                           struct results_two_level *levels,
                                           struct two_level_trees *trees, bvhlab_error *err)
{
	const struct scene_instanced *inst = job->inst;
	memset(whole, 0, sizeof(*whole));
	memset(levels, 0, sizeof(*levels));
	memset(trees, 0, sizeof(*trees));
	memset(samples_ms, 0, job->repeat * sizeof(*samples_ms));
	*cold_ms = 0;
	snprintf(levels->bottom.plugin, sizeof(levels->bottom.plugin), "%s",
	         bvhlab_plugin_builder(job->bottom)->name);
	snprintf(levels->top.plugin, sizeof(levels->top.plugin), "%s",
	         bvhlab_plugin_builder(job->top)->name);
	trees->bottom = calloc(inst->mesh_count, sizeof(*trees->bottom));
	double *mesh_sah = calloc(inst->mesh_count, sizeof(*mesh_sah));
	trees->mesh_count = trees->bottom ? inst->mesh_count : 0;
	if (!trees->bottom || !mesh_sah) {
		free(mesh_sah);
		error_set(err, "out of memory for %u bottom trees", inst->mesh_count);
		return TREE_FAILED;
	}
	enum tree_verdict v = bottom_level(job, samples_ms, cold_ms, whole, levels, mesh_sah,
	                                   trees, err);
	if (v == TREE_OK)
		v = top_level(job, samples_ms, cold_ms, whole, levels, mesh_sah, trees, err);
	if (v == TREE_OK)
		v = check_rays(job, trees, whole, err);
	free(mesh_sah);
	whole->valid = v == TREE_OK;
	whole->has_stats = whole->valid;
	whole->stats.sah_cost = levels->sah;
	whole->stats.avg_leaf_size =
		whole->stats.leaves ? (double)whole->stats.refs / whole->stats.leaves : 0;
	return v;
}

void harness_two_level_finish(struct two_level_trees *trees)
{
	for (uint32_t m = 0; trees->bottom && m < trees->mesh_count; m++)
		bvhlab_tree_finish(&trees->bottom[m]);
	free(trees->bottom);
	bvhlab_tree_finish(&trees->top);
	bvhlab_prims_finish(&trees->top_prims);
	memset(trees, 0, sizeof(*trees));
}

/* A two-level run's main traversal: the CPU stack one, where the config's
 * is a device traversal, which is measured and compared beside it (and
 * where there is no device it alone is left out, its reason in
 * rays.error). */
static void two_level_main(struct ray_settings *rs)
{
	if (trace_cl_traversal(rs->main)) {
		rs->main = BVHLAB_TRAVERSAL_STACK;
		rs->traversals |= 1u << BVHLAB_TRAVERSAL_STACK;
	}
}

/* The run's camera: the config's, auto-framed on `flat`, the flattened
 * scene's bounds, so its one-level runs trace the same rays (NULL: on
 * the top tree's root box). Its frames keep frame 0's, as one-level
 * frames do. */
static void two_level_camera(const struct config *cfg, const char *scene,
                             const bvhlab_aabb *flat, const struct two_level_trees *trees,
                             bvhlab_camera *cam)
{
	bvhlab_aabb bounds;
	memcpy(bounds.lo, trees->top.nodes[0].lo, sizeof(bounds.lo));
	memcpy(bounds.hi, trees->top.nodes[0].hi, sizeof(bounds.hi));
	harness_camera_of(cfg, scene, flat ? flat : &bounds, cam);
}

/* The run's primary rays through its trees, with the config's traversals. */
static void trace_rays(const struct config *cfg, const struct scene_instanced *inst,
                       const bvhlab_camera *cam, const struct two_level_trees *trees,
                       struct ray_metrics *m)
{
	struct trace_two_level tl = {.inst = inst, .top = &trees->top, .bottom = trees->bottom};
	struct ray_settings rs;
	harness_ray_settings(cfg, &rs);
	two_level_main(&rs);
	if ((size_t)rs.width * rs.height == 0)
		return;
	harness_trace_rays_two_level(&tl, cam, &rs, m);
}

void harness_two_level_frame_rays(const struct config *cfg, const struct trace_two_level *tl,
                                  const bvhlab_camera *cam, struct frame_metrics *fm)
{
	struct ray_settings rs;
	struct ray_metrics m;
	harness_frames_ray_settings(cfg, &rs);
	two_level_main(&rs);
	rs.traversals = 1u << rs.main; /* a frame reports its main traversal's rays */
	bool traced = cam && rs.width && rs.height &&
	              harness_trace_rays_two_level(tl, cam, &rs, &m) == 0;
	harness_frames_cost(cfg, traced ? &m.primary[rs.main] : NULL, fm);
}

enum tree_verdict harness_two_level_run(const struct config *cfg,
                                        const struct harness_builder *hb,
                                        const struct scene_instanced *inst,
                                        const struct harness_anim *anim, const char *scene,
                                        const bvhlab_aabb *flat, uint32_t threads,
                                        struct series_report *rep, bvhlab_error *err)
{
	struct two_level_job job = {.inst = inst, .bottom = hb->plugin, .top = hb->top.plugin,
	                            .bottom_opts = &hb->opts, .top_opts = &hb->top.opts,
	                            .warmup = cfg->warmup, .repeat = cfg->repeat,
	                            .threads = threads,
	                            .validate_rays = cfg->validate ? cfg->validate_rays : 0};
	struct two_level_trees trees;
	/* Its memory: the builds and their validation (interleaved, mesh by
	 * mesh), then tracing and frames; the meshes and instances are the
	 * scene's share. */
	harness_memory_begin_bytes(&rep->memory, harness_memory_instanced_bytes(inst));
	enum tree_verdict v = harness_two_level_series(&job, rep->samples, &rep->cold_ms, &rep->tree,
	                                               &rep->two_level, &trees, err);
	harness_memory_end(&rep->memory, &trees.top);
	for (uint32_t m = 0; m < trees.mesh_count; m++)
		rep->memory.output_bytes += harness_memory_tree_bytes(&trees.bottom[m]);
	rep->sample_count = v == TREE_OK ? cfg->repeat : 0;
	rep->validated = v != TREE_FAILED;
	rep->phase_count = trees.phase_count;
	memcpy(rep->phases, trees.phases, sizeof(rep->phases));
	bvhlab_camera cam;
	if (v == TREE_OK) {
		two_level_camera(cfg, scene, flat, &trees, &cam);
		trace_rays(cfg, inst, &cam, &trees, &rep->rays);
	}
	/* An animated scene's frames, on these trees (harness_anim_top.c). */
	int f = v != TREE_OK ? 0
	                     : harness_anim_top_frames(cfg, hb, anim, &trees, threads, &cam, rep, err);
	v = f > 0 ? TREE_INVALID : f < 0 ? TREE_FAILED : v;
	harness_memory_run_end(&rep->memory);
	harness_two_level_finish(&trees);
	return v;
}

const struct results_two_level *harness_two_level_checked(struct results_two_level *levels)
{
	levels->bottom.plugin[sizeof(levels->bottom.plugin) - 1] = '\0';
	levels->top.plugin[sizeof(levels->top.plugin) - 1] = '\0';
	return levels->top.trees ? levels : NULL;
}
