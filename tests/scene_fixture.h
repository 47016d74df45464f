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

/* A copy of a tree (counts, width, nodes, leaf slots) with capacity for
 * just what it holds. */
static inline void tree_dup(bvhlab_tree *dst, const bvhlab_tree *src)
{
	CHECK_INT(bvhlab_tree_init(dst, src->node_count, src->index_count), 0);
	memcpy(dst->nodes, src->nodes, src->node_count * sizeof(bvhlab_node));
	memcpy(dst->prim_index, src->prim_index, src->index_count * sizeof(uint32_t));
	dst->node_count = src->node_count;
	dst->index_count = src->index_count;
	dst->width = src->width;
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

/* The sizes of the generated scenes a builder test runs (for_generated). */
struct scene_sizes {
	uint32_t soup;      /* triangles */
	uint32_t icosphere; /* frequency */
	uint32_t stadium;   /* triangles */
	uint32_t terrain;   /* size */
	uint32_t identical; /* triangles */
};

/* The generated scenes every builder test runs, in order: a soup, an
 * icosphere, a stadium and a terrain of the given sizes, `identical`
 * copies of one triangle, and soups of 1 and 2 triangles. */
#define GENERATED_SCENES 7
static inline bvhlab_scene *generated_scene(const struct scene_sizes *s, int k,
                                            const char **name)
{
	static const char *const names[GENERATED_SCENES] = {
		"soup", "icosphere", "stadium", "terrain", "identical", "one", "two" };
	*name = names[k];
	switch (k) {
	case 0: return generate("soup", s->soup, 0, 0);
	case 1: return generate("icosphere", 0, s->icosphere, 0);
	case 2: return generate("stadium", s->stadium, 0, 0);
	case 3: return generate("terrain", 0, 0, s->terrain);
	case 4: return identical_scene(s->identical);
	default: return generate("soup", (uint32_t)k - 4, 0, 0);
	}
}

/* test(name, scene) on the generated scenes (generated_scene). */
static inline void for_generated(const struct scene_sizes *sizes,
                                 void (*test)(const char *name, bvhlab_scene *scene))
{
	const char *name;
	for (int k = 0; k < GENERATED_SCENES; k++) {
		bvhlab_scene *scene = generated_scene(sizes, k, &name);
		test(name, scene);
	}
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

/* Builds with `plugin` and the options `items` ("key=value" texts, NULL-
 * terminated), parsed in turn: 0, or the first failure, in err. */
static inline int build_with(const bvhlab_plugin *plugin, const char *const *items,
                             const bvhlab_build_input *in, uint32_t threads, bvhlab_tree *tree,
                             bvhlab_error *err)
{
	bvhlab_options opts;
	int rc = bvhlab_options_init(&opts, bvhlab_plugin_builder(plugin));

	if (rc < 0)
		return rc;
	for (size_t k = 0; rc == 0 && items[k]; k++)
		rc = bvhlab_options_parse(&opts, items[k], err);
	if (rc == 0)
		rc = bvhlab_build(plugin, &opts, in, threads, tree, err);
	bvhlab_options_finish(&opts);
	return rc;
}

/* Builds with `opts` and validates the tree's structure, then finishes
 * opts: 0, or the failure, reported as "`what` threads=N: why" with a
 * failed check. */
static inline int build_validated(const bvhlab_plugin *plugin, bvhlab_options *opts,
                                  const bvhlab_build_input *in, uint32_t threads,
                                  bvhlab_tree *tree, const char *what)
{
	bvhlab_error err = { { 0 } };
	int rc = bvhlab_build(plugin, opts, in, threads, tree, &err);

	if (rc == 0)
		rc = bvhlab_validate_tree(tree, in, false, &err);
	if (rc != 0) {
		fprintf(stderr, "%s threads=%u: %s\n", what, threads, err.message);
		CHECK(!"valid build");
	}
	bvhlab_options_finish(opts);
	return rc;
}

/* Leaves of at most `most` primitives; the first larger one is reported. */
static inline void check_leaf_sizes(const bvhlab_tree *tree, uint32_t most)
{
	for (uint32_t i = 0; i < tree->node_count; i++)
		if (tree->nodes[i].count > most) {
			fprintf(stderr, "node %u: leaf of %u > %u\n", i, tree->nodes[i].count, most);
			CHECK(!"leaf within max_leaf");
			return;
		}
}

/* `tree`, built with `threads` threads, is `ref` (built with 1): equal for
 * bvhlab_tree_compare, and the same arrays, node order included. */
static inline void check_same_tree(const char *name, const bvhlab_tree *ref,
                                   const bvhlab_tree *tree, uint32_t threads)
{
	bvhlab_error err = { { 0 } };

	if (bvhlab_tree_compare(ref, tree, &err) != 0) {
		fprintf(stderr, "%s: threads=%u vs 1: %s\n", name, threads, err.message);
		CHECK(!"same tree");
		return;
	}
	CHECK_INT(tree->node_count, ref->node_count);
	CHECK_INT(tree->index_count, ref->index_count);
	CHECK(trees_identical(ref, tree));
}

/* A test's build of its setup (the plugin's option values) with `threads`
 * threads, validated: 0, or the failure, reported with a failed check. */
typedef int (*setup_build_fn)(const char *name, const bvhlab_build_input *in,
                              const void *setup, uint32_t threads, bvhlab_tree *tree);

/* One setup of a deterministic builder, for check_threads_same. */
struct setup_check {
	setup_build_fn build;
	const void *setup;
	bool collapse;         /* false: one primitive a leaf, 2n - 1 nodes */
	uint32_t most;         /* the largest leaf allowed */
	const uint32_t *threads; /* the builds that must give the 1-thread tree again */
	size_t thread_count;
	uint64_t ray_seed;
};

/*
 * One setup on one scene: the 1-thread tree is checked in full (structure,
 * rays against brute force, leaves), then every count of c->threads must
 * build it again, node for node. Returns its SAH cost.
 */
static inline double check_threads_same(const char *name, const bvhlab_scene *scene,
                                        const bvhlab_build_input *in,
                                        const struct setup_check *c, uint32_t rays)
{
	bvhlab_tree ref = { 0 }, tree = { 0 };
	bvhlab_tree_stats stats = { 0 };
	bvhlab_error err = { { 0 } };
	uint64_t mismatches = 1;

	if (c->build(name, in, c->setup, 1, &ref) != 0)
		goto out;
	CHECK_INT(ref.index_count, in->prim_count);
	if (!c->collapse)
		CHECK_INT(ref.node_count, 2 * in->prim_count - 1);
	CHECK_INT(bvhlab_validate_rays(&ref, scene, rays, c->ray_seed, &mismatches, &err), 0);
	CHECK_INT(mismatches, 0);
	check_leaf_sizes(&ref, c->most);
	bvhlab_tree_stats_compute(&ref, &stats);
	for (size_t t = 0; t < c->thread_count; t++)
		if (c->build(name, in, c->setup, c->threads[t], &tree) == 0)
			check_same_tree(name, &ref, &tree, c->threads[t]);
out:
	bvhlab_tree_finish(&ref);
	bvhlab_tree_finish(&tree);
	return stats.sah_cost;
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

/* Whether ../shared/scenes is there; a line saying so when not, so the
 * test can report itself skipped. */
static inline bool shared_present(void)
{
	struct stat st;

	if (stat(BVHLAB_SHARED_SCENES, &st) != 0 || !S_ISDIR(st.st_mode)) {
		printf("no shared scenes at %s: shared meshes skipped\n", BVHLAB_SHARED_SCENES);
		return false;
	}
	return true;
}

/* The shared meshes a test runs: the first `count` of files, the first
 * `small_count` under a sanitizer (where the rest are too slow). */
static inline size_t shared_count(size_t count, size_t small_count)
{
	return UNDER_SANITIZER ? small_count : count;
}

/*
 * test(file, scene) on the shared meshes of files (shared_count), scene
 * NULL for one that does not load. False when they are not there
 * (shared_present).
 */
static inline bool for_shared(const char *const *files, size_t count, size_t small_count,
                              void (*test)(const char *file, bvhlab_scene *scene))
{
	if (!shared_present())
		return false;
	for (size_t i = 0; i < shared_count(count, small_count); i++)
		test(files[i], load_shared(files[i]));
	return true;
}

/* for_generated and for_shared with one test, told which it has:
 * test(name, scene, generated). for_shared's result. */
static inline bool for_scenes(const struct scene_sizes *sizes, const char *const *files,
                              size_t count, size_t small_count,
                              void (*test)(const char *name, bvhlab_scene *scene,
                                           bool generated))
{
	const char *name;
	for (int k = 0; k < GENERATED_SCENES; k++) {
		bvhlab_scene *scene = generated_scene(sizes, k, &name);
		test(name, scene, true);
	}
	if (!shared_present())
		return false;
	for (size_t i = 0; i < shared_count(count, small_count); i++)
		test(files[i], load_shared(files[i]), false);
	return true;
}

#endif
