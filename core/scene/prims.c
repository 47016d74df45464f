/*
 * Per-triangle boxes and centroids: the builder input for a scene.
 */
#include <errno.h>
#include <math.h>
#include <stdlib.h>
#include <string.h>

#include <bvhlab/aabb.h>

#include "scene/scene_private.h"

/* Fills the per-primitive arrays and the two overall boxes. */
static void compute_prims(bvhlab_prims *prims, const bvhlab_scene *scene)
{
	bvhlab_build_input *in = &prims->input;

	bvhlab_aabb_empty(&in->bounds);
	bvhlab_aabb_empty(&in->centroid_bounds);
	for (size_t t = 0; t < scene->triangle_count; t++) {
		const uint32_t *tri = scene->indices + 3 * t;
		bvhlab_aabb *box = &prims->bounds_storage[t];
		float *c = prims->centroid_storage + 3 * t;

		bvhlab_aabb_empty(box);
		for (int j = 0; j < 3; j++)
			bvhlab_aabb_grow_point(box, scene->vertices + 3 * (size_t)tri[j]);
		/* The box centre, not the vertex average: builders bin by the
		 * same boxes they bound with. */
		for (int k = 0; k < 3; k++)
			c[k] = bvhlab_aabb_center(box, k);
		bvhlab_aabb_grow(&in->bounds, box);
		bvhlab_aabb_grow_point(&in->centroid_bounds, c);
	}
}

int bvhlab_prims_init(bvhlab_prims *prims, const bvhlab_scene *scene, bvhlab_error *err)
{
	size_t count = scene->triangle_count;

	memset(prims, 0, sizeof(*prims));
	if (count == 0) {
		scene_error(err, "scene '%s' has no triangles", scene->name ? scene->name : "?");
		return -EINVAL;
	}
	prims->bounds_storage = malloc(count * sizeof(bvhlab_aabb));
	prims->centroid_storage = malloc(count * 3 * sizeof(float));
	if (!prims->bounds_storage || !prims->centroid_storage) {
		bvhlab_prims_finish(prims);
		scene_error(err, "out of memory for the boxes of %zu triangles", count);
		return -ENOMEM;
	}
	compute_prims(prims, scene);
	prims->input.struct_size = sizeof(bvhlab_build_input);
	prims->input.prim_count = scene->triangle_count;
	prims->input.prim_bounds = prims->bounds_storage;
	prims->input.centroids = prims->centroid_storage;
	prims->input.vertices = scene->vertices;
	prims->input.vertex_count = scene->vertex_count;
	prims->input.indices = scene->indices;
	prims->input.threads = 1;
	return 0;
}

void bvhlab_prims_finish(bvhlab_prims *prims)
{
	if (!prims)
		return;
	free(prims->bounds_storage);
	free(prims->centroid_storage);
	memset(prims, 0, sizeof(*prims));
}
