/*
 * Scenes the plugin tests share. Define FIXTURE_SEED before including: each
 * test keeps its own seed, so its scenes stay what they were.
 */
#ifndef BVHLAB_SCENE_FIXTURE_H
#define BVHLAB_SCENE_FIXTURE_H

#include <stdbool.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>

#include <bvhlab/bvhlab.h>

#include "testutil.h"

#ifndef FIXTURE_SEED
#error "define FIXTURE_SEED before including scene_fixture.h"
#endif

/* Node for node the same tree: the counts, the nodes and the leaf slots,
 * byte for byte (what "the same tree for every thread count" means). */
static inline bool trees_identical(const bvhlab_tree *a, const bvhlab_tree *b)
{
	return a->node_count == b->node_count && a->index_count == b->index_count &&
	       memcmp(a->nodes, b->nodes, a->node_count * sizeof(bvhlab_node)) == 0 &&
	       memcmp(a->prim_index, b->prim_index, a->index_count * sizeof(uint32_t)) == 0;
}

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

/* Opens plugin `name` into *plugin; false, with a failed check and the
 * reason, when it does not load. */
static inline bool plugin_loads(const char *name, bvhlab_plugin **plugin)
{
	bvhlab_error err = { { 0 } };

	if (bvhlab_plugin_open(name, plugin, &err) == 0)
		return true;
	fprintf(stderr, "%s: %s\n", name, err.message);
	CHECK(!"plugin loads");
	return false;
}

/* A scene with room for `vertices` vertices and `triangles` triangles, for
 * the caller to fill; NULL (a failed check) when out of memory. */
static inline bvhlab_scene *blank_scene(uint32_t vertices, uint32_t triangles)
{
	bvhlab_scene *scene = calloc(1, sizeof(*scene));

	CHECK(scene != NULL);
	if (!scene)
		return NULL;
	scene->vertices = malloc(3 * (size_t)vertices * sizeof(float));
	scene->indices = malloc(3 * (size_t)triangles * sizeof(uint32_t));
	CHECK(scene->vertices && scene->indices);
	if (!scene->vertices || !scene->indices) {
		bvhlab_scene_destroy(scene);
		return NULL;
	}
	scene->vertex_count = vertices;
	scene->triangle_count = triangles;
	return scene;
}

/* n copies of one triangle: every centroid equal, so no split separates
 * any two of them (and every Morton code is the same). */
static inline bvhlab_scene *identical_scene(uint32_t n)
{
	static const float tri[9] = { 0, 0, 0, 1, 0.5f, 0, 0.25f, 1, 0.75f };
	bvhlab_scene *scene = blank_scene(3, n);

	if (!scene)
		return NULL;
	memcpy(scene->vertices, tri, sizeof(tri));
	for (uint32_t i = 0; i < 3 * n; i++)
		scene->indices[i] = i % 3;
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

/* The SAH cost of the builds of one setup (option value, collapse) on a
 * scene, after the test's checks of them. */
typedef double (*collapse_check_fn)(const char *name, const bvhlab_scene *scene,
                                    const bvhlab_build_input *in, uint32_t value,
                                    bool collapse, uint32_t rays);

/* For each value of `option`: the builds with and without collapse, whose
 * SAH costs are printed; collapse never raises it. Destroys scene. */
static inline void compare_collapse(const char *name, bvhlab_scene *scene, uint32_t rays,
                                    const char *option, const uint32_t *values,
                                    size_t count, collapse_check_fn check)
{
	bvhlab_prims prims;
	bvhlab_error err = { { 0 } };

	if (!scene)
		return;
	CHECK_INT(bvhlab_prims_init(&prims, scene, &err), 0);
	for (size_t k = 0; k < count; k++) {
		double with = check(name, scene, &prims.input, values[k], true, rays);
		double without = check(name, scene, &prims.input, values[k], false, rays);

		printf("%-18s %8u triangles  %s %2u  SAH collapse %9.4f  single %9.4f\n", name,
		       scene->triangle_count, option, values[k], with, without);
		CHECK(with <= without * (1 + 1e-6));
	}
	bvhlab_prims_finish(&prims);
	bvhlab_scene_destroy(scene);
}

/*
 * test(file, scene) on the first `count` shared meshes of files (the first
 * `small_count` under a sanitizer, where the rest are too slow), scene NULL for one
 * that does not load. False, and a line saying so, when the shared meshes
 * are not there, so the test can report itself skipped.
 */
static inline bool for_shared(const char *const *files, size_t count, size_t small_count,
                              void (*test)(const char *file, bvhlab_scene *scene))
{
	struct stat st;

	if (stat(BVHLAB_SHARED_SCENES, &st) != 0 || !S_ISDIR(st.st_mode)) {
		printf("no shared scenes at %s: shared meshes skipped\n", BVHLAB_SHARED_SCENES);
		return false;
	}
	for (size_t i = 0; i < (UNDER_SANITIZER ? small_count : count); i++)
		test(files[i], load_shared(files[i]));
	return true;
}

#endif
