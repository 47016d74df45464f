/*
 * The harness's ray measurements. Rays are traced in the run's child,
 * right after validation, with the config's ray threads whatever the run's
 * build thread count: traversal numbers then compare trees, not thread
 * counts. Each batch is timed over repeated passes (bvhlab_trace_measure),
 * with one or both traversals. The per-pixel data they give becomes images
 * in output/images.c.
 */
#include <errno.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "harness/harness_rays.h"
#include "output/image.h"
#include "output/results.h"
#include "trace/trace_instances.h"
#include "trace/trace_series.h"
#include "util/util.h"

void harness_camera_of(const struct config *cfg, const char *name, const bvhlab_aabb *bounds,
                       bvhlab_camera *cam)
{
	/* Scene names are unique in a config, and the harness names each
	 * loaded scene after its config entry. */
	for (size_t i = 0; cfg && name && i < cfg->scene_count; i++)
		if (cfg->scenes[i].has_camera && strcmp(cfg->scenes[i].name, name) == 0) {
			*cam = cfg->scenes[i].camera;
			return;
		}
	if (cfg && cfg->has_camera)
		*cam = cfg->camera;
	else
		bvhlab_camera_frame(bounds, cam);
}

void harness_camera(const struct config *cfg, const bvhlab_scene *scene, bvhlab_camera *cam)
{
	harness_camera_of(cfg, scene->name, &scene->bounds, cam);
}

void harness_ray_settings(const struct config *cfg, struct ray_settings *rs)
{
	if (!cfg) {
		*rs = (struct ray_settings){.traversals = 1u << BVHLAB_TRAVERSAL_STACK,
		                            .main = BVHLAB_TRAVERSAL_STACK, .rounds = 1,
		                            .kinds = RAY_KINDS_DEFAULT};
		return;
	}
	*rs = (struct ray_settings){.width = cfg->ray_width, .height = cfg->ray_height,
	                            .diffuse = cfg->ray_diffuse, .kinds = cfg->ray_kinds,
	                            .has_light = cfg->has_light,
	                            .light = {cfg->ray_light[0], cfg->ray_light[1],
	                                      cfg->ray_light[2]},
	                            .ao_length = (float)cfg->ray_ao_length,
	                            .threads = cfg->ray_threads,
	                            .min_ms = cfg->ray_min_ms, .min_repeats = HARNESS_MIN_REPEATS,
	                            .rounds = cfg->ray_rounds, .traversals = cfg->ray_traversals,
	                            .main = cfg->ray_traversal, .device = cfg->ray_device};
}

/* Same triangle at bit-identical t, u, v; for any-hit rays, which may
 * stop at any hit, whether either hit anything. */
static bool same_hit(const bvhlab_hit *a, const bvhlab_hit *b, bool any)
{
	if (any)
		return (a->prim == BVHLAB_NO_HIT) == (b->prim == BVHLAB_NO_HIT);
	return a->prim == b->prim && memcmp(&a->t, &b->t, sizeof(a->t)) == 0 &&
	       memcmp(&a->u, &b->u, sizeof(a->u)) == 0 && memcmp(&a->v, &b->v, sizeof(a->v)) == 0;
}

/* A traversal's failure joins the others' in m->error ("; " between), on
 * one line: a device's build log ends in a newline and may hold more. */
static void add_error(struct ray_metrics *m, const char *text)
{
	size_t used = strlen(m->error), n = strlen(text);
	while (n > 0 && (text[n - 1] == '\n' || text[n - 1] == '\r' || text[n - 1] == ' '))
		n--;
	if (used && strstr(m->error, text))
		return; /* the diffuse batch's repeat of a primary one's */
	if (used && used + 2 < sizeof(m->error)) {
		memcpy(m->error + used, "; ", 2);
		used += 2;
	}
	for (size_t k = 0; k < n && used + 1 < sizeof(m->error); k++)
		m->error[used++] = text[k] == '\n' || text[k] == '\r' || text[k] == '\t' ? ' ' : text[k];
	m->error[used < sizeof(m->error) ? used : sizeof(m->error) - 1] = '\0';
}

/* One traversal of a batch; a failure's reason, named after the
 * traversal, goes to m->error. */
static int measure(const bvhlab_tree *tree, const bvhlab_scene *scene, const bvhlab_ray *rays,
                   size_t n, const bvhlab_trace_options *o, bvhlab_hit *hits, uint32_t *nodes,
                   bvhlab_trace_timing *out, struct ray_metrics *m)
{
	bvhlab_error err = {{0}};
	char device[sizeof(m->device)] = "";
	int r = trace_measure(tree, scene, rays, n, o, hits, nodes, out, device, sizeof(device),
	                      &err);
	if (device[0])
		memcpy(m->device, device, sizeof(device));
	if (r < 0) {
		if (!err.message[0])
			error_set(&err, "%s", strerror(-r));
		error_prefix(&err, "%s", bvhlab_traversal_name(o->traversal));
		add_error(m, err.message);
	}
	return r;
}

/*
 * One batch with every traversal of m (rs's, less those that failed), the
 * main one first (its hits go to hits, its node counts to nodes); another
 * traversal's hits are compared with the main one's, ray by ray, into
 * m->disagreements. Another traversal that cannot run (no OpenCL device)
 * is dropped from m with its reason in m->error; the main one failing
 * fails the batch.
 */
static int trace_kind(const bvhlab_tree *tree, const bvhlab_scene *scene,
                      const bvhlab_ray *rays, size_t n, const struct ray_settings *rs,
                      int kind, bvhlab_hit *hits, uint32_t *nodes, struct ray_metrics *m)
{
	bvhlab_trace_timing *out = ray_metrics_kind(m, kind);
	bvhlab_trace_options o = {.traversal = rs->main, .threads = rs->threads,
	                          .any_hit = ray_kind_any(kind),
	                          .min_ms = rs->min_ms, .min_repeats = rs->min_repeats,
	                          .device = rs->device};
	int r = measure(tree, scene, rays, n, &o, hits, nodes, &out[rs->main], m);
	m->threads = out[rs->main].threads;
	for (int k = 0; r == 0 && k < BVHLAB_TRAVERSAL_COUNT; k++) {
		if (k == rs->main || !(m->traversals & (1u << k)))
			continue;
		bvhlab_hit *other = malloc(n * sizeof(*other));
		if (!other)
			return -ENOMEM;
		o.traversal = k;
		if (measure(tree, scene, rays, n, &o, other, NULL, &out[k], m) == 0) {
			for (size_t i = 0; i < n; i++)
				m->disagreements += !same_hit(&hits[i], &other[i], o.any_hit);
		} else { /* this traversal only (no device, say): the others go on */
			m->traversals &= ~(1u << k);
			out[k] = (bvhlab_trace_timing){0};
		}
		free(other);
	}
	return r;
}

int harness_secondary_rays(int kind, const bvhlab_scene *scene, const struct ray_settings *rs,
                           const bvhlab_ray *primary, const bvhlab_hit *hits, size_t n,
                           bvhlab_ray **rays, size_t *count)
{
	float light[3];
	*rays = NULL;
	*count = 0;
	if (!(rs->kinds & (1u << kind)))
		return 0;
	switch (kind) {
	case RAY_DIFFUSE:
		return bvhlab_rays_diffuse(scene, primary, hits, n, rs->diffuse, HARNESS_DIFFUSE_SEED,
		                           rays, count);
	case RAY_SHADOW:
		if (rs->has_light)
			memcpy(light, rs->light, sizeof(light));
		else
			bvhlab_light_frame(&scene->bounds, light);
		return bvhlab_rays_shadow(scene, primary, hits, n, light, rays, count);
	case RAY_AO:
		return bvhlab_rays_ao(scene, primary, hits, n, rs->ao_length, HARNESS_AO_SEED, rays,
		                      count);
	default:
		return 0;
	}
}

/* Every secondary kind of rs from the primary rays' hits. */
static int trace_secondary(const bvhlab_tree *tree, const bvhlab_scene *scene,
                           const bvhlab_ray *primary, const bvhlab_hit *hits, size_t n,
                           const struct ray_settings *rs, struct ray_metrics *m)
{
	int r = 0;
	for (int kind = RAY_DIFFUSE; r == 0 && kind < RAY_KINDS; kind++) {
		bvhlab_ray *rays = NULL;
		size_t count = 0;
		r = harness_secondary_rays(kind, scene, rs, primary, hits, n, &rays, &count);
		bvhlab_hit *h = r == 0 && count ? malloc(count * sizeof(*h)) : NULL;
		if (r == 0 && count)
			r = h ? trace_kind(tree, scene, rays, count, rs, kind, h, NULL, m) : -ENOMEM;
		free(h);
		free(rays);
	}
	return r;
}

int harness_trace_rays(const bvhlab_tree *tree, const bvhlab_scene *scene,
                       const bvhlab_camera *cam, const struct ray_settings *rs,
                       struct ray_metrics *m, uint32_t *nodes, uint8_t *shade)
{
	bvhlab_ray *rays = NULL;
	size_t n = (size_t)rs->width * rs->height;
	memset(m, 0, sizeof(*m));
	m->traversals = rs->traversals;
	m->main = rs->main;
	m->kinds = rs->kinds;
	m->rounds = 1;
	int r = bvhlab_rays_primary(cam, rs->width, rs->height, &rays);
	if (r < 0) {
		snprintf(m->error, sizeof(m->error), "primary rays: %s", strerror(-r));
		return r;
	}
	bvhlab_hit *hits = malloc(n * sizeof(*hits));
	if (!hits) {
		r = -ENOMEM;
		goto out;
	}
	r = trace_kind(tree, scene, rays, n, rs, RAY_PRIMARY, hits, nodes, m);
	if (r == 0 && shade)
		image_shade(scene, rays, hits, n, shade);
	if (r == 0)
		r = trace_secondary(tree, scene, rays, hits, n, rs, m);
	m->measured = r == 0;
	if (r < 0 && !m->error[0])
		snprintf(m->error, sizeof(m->error), "%s", strerror(-r));
out:
	free(hits);
	free(rays);
	return r;
}

/* One traversal of a two-level batch, as measure() one of a tree. */
static int measure_two_level(const struct trace_two_level *tl, const bvhlab_ray *rays, size_t n,
                             const bvhlab_trace_options *o, bvhlab_hit *hits,
                             bvhlab_trace_timing *out, struct ray_metrics *m)
{
	bvhlab_error err = {{0}};
	char device[sizeof(m->device)] = "";
	int r = trace_measure_two_level(tl, rays, n, o, hits, out, device, sizeof(device), &err);
	if (device[0])
		memcpy(m->device, device, sizeof(device));
	if (r < 0) {
		error_prefix(&err, "%s", bvhlab_traversal_name(o->traversal));
		add_error(m, err.message);
	}
	return r;
}

int harness_trace_rays_two_level(const struct trace_two_level *tl, const bvhlab_camera *cam,
                                 const struct ray_settings *rs, struct ray_metrics *m)
{
	bvhlab_ray *rays = NULL;
	size_t n = (size_t)rs->width * rs->height;
	memset(m, 0, sizeof(*m));
	m->traversals = rs->traversals;
	m->main = rs->main;
	m->kinds = 1u << RAY_PRIMARY;
	m->rounds = 1;
	int r = bvhlab_rays_primary(cam, rs->width, rs->height, &rays);
	bvhlab_hit *hits = r == 0 ? malloc(n * sizeof(*hits)) : NULL, *other = NULL;
	other = hits ? malloc(n * sizeof(*other)) : NULL;
	r = r < 0 ? r : other ? 0 : -ENOMEM;
	bvhlab_trace_options o = {.traversal = rs->main, .threads = rs->threads,
	                          .min_ms = rs->min_ms, .min_repeats = rs->min_repeats,
	                          .device = rs->device};
	if (r == 0)
		r = measure_two_level(tl, rays, n, &o, hits, &m->primary[rs->main], m);
	m->threads = m->primary[rs->main].threads;
	for (int k = 0; r == 0 && k < BVHLAB_TRAVERSAL_COUNT; k++) {
		if (k == rs->main || !(m->traversals & (1u << k)))
			continue;
		o.traversal = k;
		if (measure_two_level(tl, rays, n, &o, other, &m->primary[k], m) == 0) {
			for (size_t i = 0; i < n; i++)
				m->disagreements += !same_hit(&hits[i], &other[i], false);
		} else { /* this traversal only (no device, say): the others go on */
			m->traversals &= ~(1u << k);
			m->primary[k] = (bvhlab_trace_timing){0};
		}
	}
	m->measured = r == 0;
	if (r < 0 && !m->error[0])
		snprintf(m->error, sizeof(m->error), "%s", strerror(-r));
	free(other);
	free(hits);
	free(rays);
	return r;
}

void harness_rays_error(int r, uint64_t memory_limit, bool isolated, char *buf, size_t size)
{
	char note[64] = "";
	if (r == -ENOMEM && memory_limit && isolated)
		snprintf(note, sizeof(note), " (under memory_limit_mb = %llu)",
		         (unsigned long long)(memory_limit >> 20));
	snprintf(buf, size, "%s%s", r == -ENOMEM ? "out of memory tracing the rays" : strerror(-r),
	         note);
}
