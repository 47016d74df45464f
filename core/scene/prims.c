/*
 * Per-triangle boxes and centroids: the builder input for a scene.
 */
#include <errno.h>
#include <math.h>
#include <stdlib.h>
#include <string.h>

#include <bvhlab/aabb.h>

#include "scene/scene_private.h"
#include "util/util.h"

/* The centroids and the two overall boxes, from the per-primitive boxes. */
static void compute_centres(bvhlab_prims *prims, size_t count)
{
	bvhlab_build_input *in = &prims->input;

	bvhlab_aabb_empty(&in->bounds);
	bvhlab_aabb_empty(&in->centroid_bounds);
	for (size_t t = 0; t < count; t++) {
		const bvhlab_aabb *box = &prims->bounds_storage[t];
		float *c = prims->centroid_storage + 3 * t;

		/* The box centre, not the vertex average: builders bin by the
		 * same boxes they bound with. */
		for (int k = 0; k < 3; k++)
			c[k] = bvhlab_aabb_center(box, k);
		bvhlab_aabb_grow(&in->bounds, box);
		bvhlab_aabb_grow_point(&in->centroid_bounds, c);
	}
}

/* Fills the per-primitive arrays and the two overall boxes. */
static void compute_prims(bvhlab_prims *prims, const bvhlab_scene *scene)
{
	for (size_t t = 0; t < scene->triangle_count; t++) {
		const uint32_t *tri = scene->indices + 3 * t;
		bvhlab_aabb *box = &prims->bounds_storage[t];

		bvhlab_aabb_empty(box);
		for (int j = 0; j < 3; j++)
			bvhlab_aabb_grow_point(box, scene->vertices + 3 * (size_t)tri[j]);
	}
	compute_centres(prims, scene->triangle_count);
}

static int alloc_prims(bvhlab_prims *prims, size_t count, bvhlab_error *err)
{
	/* Huge pages: Morton builders read the boxes in sorted order, which is
	 * no order in memory (util_big_alloc). */
	prims->bounds_storage = util_big_alloc(count, sizeof(bvhlab_aabb));
	prims->centroid_storage = util_big_alloc(count, 3 * sizeof(float));
	if (!prims->bounds_storage || !prims->centroid_storage) {
		bvhlab_prims_finish(prims);
		scene_error(err, "out of memory for the boxes of %zu primitives", count);
		return -ENOMEM;
	}
	return 0;
}

int bvhlab_prims_init(bvhlab_prims *prims, const bvhlab_scene *scene, bvhlab_error *err)
{
	size_t count = scene->triangle_count;

	memset(prims, 0, sizeof(*prims));
	if (count == 0) {
		scene_error(err, "scene '%s' has no triangles", scene->name ? scene->name : "?");
		return -EINVAL;
	}
	int r = alloc_prims(prims, count, err);
	if (r < 0)
		return r;
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

int bvhlab_prims_init_boxes(bvhlab_prims *prims, const bvhlab_aabb *boxes, uint32_t count,
                            bvhlab_error *err)
{
	memset(prims, 0, sizeof(*prims));
	for (uint32_t i = 0; i < count; i++)
		for (int k = 0; k < 3; k++)
			if (!isfinite(boxes[i].lo[k]) || !isfinite(boxes[i].hi[k]) ||
			    !(boxes[i].lo[k] <= boxes[i].hi[k])) {
				scene_error(err, "box %u is empty or not finite", i);
				return -EINVAL;
			}
	if (count == 0) {
		scene_error(err, "a build over boxes needs at least one box");
		return -EINVAL;
	}
	int r = alloc_prims(prims, count, err);
	if (r < 0)
		return r;
	memcpy(prims->bounds_storage, boxes, count * sizeof(*boxes));
	compute_centres(prims, count);
	prims->input.struct_size = sizeof(bvhlab_build_input);
	prims->input.prim_count = count;
	prims->input.prim_bounds = prims->bounds_storage;
	prims->input.centroids = prims->centroid_storage;
	prims->input.threads = 1;
	prims->input.prim_kind = BVHLAB_PRIM_BOXES;
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
