/*
 * Scenes the plugin tests share. Define FIXTURE_SEED before including: each
 * test keeps its own seed, so its scenes stay what they were.
 */
#ifndef BVHLAB_SCENE_FIXTURE_H
#define BVHLAB_SCENE_FIXTURE_H

#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include <bvhlab/bvhlab.h>

#include "testutil.h"

#ifndef FIXTURE_SEED
#error "define FIXTURE_SEED before including scene_fixture.h"
#endif

/* A generated scene; 0 keeps a parameter's default. */
static inline bvhlab_scene *generate(const char *generator, uint32_t count, uint32_t frequency,
                                     uint32_t size)
{
	bvhlab_gen_params params;
	bvhlab_scene *scene = NULL;
	bvhlab_error err = { { 0 } };

	bvhlab_gen_params_init(&params);
	params.seed = FIXTURE_SEED;
	if (count)
		params.count = count;
	if (frequency)
		params.frequency = frequency;
	if (size)
		params.size = size;
	if (bvhlab_scene_generate(generator, &params, &scene, &err) < 0)
		fprintf(stderr, "%s: %s\n", generator, err.message);
	CHECK(scene != NULL);
	return scene;
}

/* n copies of one triangle: every centroid equal, so no split separates
 * any two of them (and every Morton code is the same). */
static inline bvhlab_scene *identical_scene(uint32_t n)
{
	static const float tri[9] = { 0, 0, 0, 1, 0.5f, 0, 0.25f, 1, 0.75f };
	bvhlab_scene *scene = calloc(1, sizeof(*scene));

	CHECK(scene != NULL);
	if (!scene)
		return NULL;
	scene->vertices = malloc(sizeof(tri));
	scene->indices = malloc(3 * (size_t)n * sizeof(uint32_t));
	CHECK(scene->vertices && scene->indices);
	memcpy(scene->vertices, tri, sizeof(tri));
	for (uint32_t i = 0; i < 3 * n; i++)
		scene->indices[i] = i % 3;
	scene->vertex_count = 3;
	scene->triangle_count = n;
	bvhlab_scene_update(scene);
	return scene;
}

/* A mesh of ../shared/scenes by file name; NULL (a failed check) if it
 * does not load. */
static inline bvhlab_scene *load_shared(const char *file)
{
	char path[1024];
	bvhlab_scene *scene = NULL;
	bvhlab_error err = { { 0 } };

	snprintf(path, sizeof(path), "%s/%s", BVHLAB_SHARED_SCENES, file);
	if (bvhlab_scene_load(path, &scene, &err) < 0) {
		fprintf(stderr, "%s\n", err.message);
		CHECK(!"shared mesh loads");
	}
	return scene;
}

#endif
