/*
 * Degenerate scenes for the ploc and reinsert tests (after scene_fixture.h):
 * needles, long thin triangles along one line, whose boxes are flat or
 * nearly so and overlap heavily.
 */
#ifndef BVHLAB_REFINE_SCENES_H
#define BVHLAB_REFINE_SCENES_H

#include <stdlib.h>

#include <bvhlab/bvhlab.h>

#include "testutil.h"

/* n needles: triangle i spans x in [i/4, i/4 + 10], a hair's width in y. */
static inline bvhlab_scene *needle_scene(uint32_t n)
{
	bvhlab_scene *scene = blank_scene(3 * n, n);

	if (!scene)
		return NULL;
	for (uint32_t i = 0; i < n; i++) {
		float x = 0.25f * (float)i, *v = scene->vertices + 9 * (size_t)i;

		v[0] = x, v[1] = 0, v[2] = 0;
		v[3] = x + 10, v[4] = 0, v[5] = 0;
		v[6] = x + 5, v[7] = 1e-4f * (float)(i % 7), v[8] = 0;
		for (int k = 0; k < 3; k++)
			scene->indices[3 * (size_t)i + k] = 3 * i + (uint32_t)k;
	}
	bvhlab_scene_update(scene);
	return scene;
}

#endif
