/*
 * The harness's ray measurements. Rays are traced in the run's child,
 * right after validation, with every hardware thread whatever the run's
 * build thread count: traversal numbers then compare trees, not thread
 * counts. The per-pixel data they give becomes images in
 * output/scene_images.c.
 */
#include <errno.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>
#include <unistd.h>

#include "harness/harness.h"
#include "output/image.h"
#include "output/results.h"
#include "util/util.h"

#define DIFFUSE_SEED 0xd1ff05eULL

void harness_camera(const struct config *cfg, const bvhlab_scene *scene, bvhlab_camera *cam)
{
	if (cfg && cfg->has_camera)
		*cam = cfg->camera;
	else
		bvhlab_camera_frame(&scene->bounds, cam);
}

static int trace_diffuse(const bvhlab_tree *tree, const bvhlab_scene *scene,
                         const bvhlab_ray *primary, const bvhlab_hit *hits, size_t n,
                         uint32_t diffuse, struct ray_metrics *m)
{
	bvhlab_ray *rays = NULL;
	size_t count = 0;
	int r = bvhlab_rays_diffuse(scene, primary, hits, n, diffuse, DIFFUSE_SEED, &rays, &count);
	if (r == 0 && count)
		r = bvhlab_trace_batch(tree, scene, rays, count, false, 0, NULL, NULL, &m->diffuse,
		                       &m->diffuse_s);
	free(rays);
	return r;
}

int harness_trace_rays(const bvhlab_tree *tree, const bvhlab_scene *scene,
                       const bvhlab_camera *cam, uint32_t width, uint32_t height,
                       uint32_t diffuse, struct ray_metrics *m, uint32_t *nodes, uint8_t *shade)
{
	bvhlab_ray *rays = NULL;
	size_t n = (size_t)width * height;
	memset(m, 0, sizeof(*m));
	m->threads = bvhlab_hardware_threads();
	int r = bvhlab_rays_primary(cam, width, height, &rays);
	if (r < 0)
		return r;
	bvhlab_hit *hits = malloc(n * sizeof(*hits));
	if (!hits) {
		r = -ENOMEM;
		goto out;
	}
	r = bvhlab_trace_batch(tree, scene, rays, n, false, 0, hits, nodes, &m->primary,
	                       &m->primary_s);
	if (r == 0 && shade)
		image_shade(scene, rays, hits, n, shade);
	if (r == 0)
		r = trace_diffuse(tree, scene, rays, hits, n, diffuse, m);
	m->measured = r == 0;
out:
	free(hits);
	free(rays);
	return r;
}
