/*
 * The embree peer plugin: every quality at 1 and 2 threads, on generated
 * scenes and two shared meshes, gives trees the core validator accepts and
 * whose rays agree with brute force. "low" and "medium" reference each
 * primitive exactly once; "high" really splits (more references than
 * triangles on a soup of long triangles) and keeps its clipped leaf boxes,
 * which the coverage check accepts and the whole-box rule rejects; every
 * tree carries the "input" and "convert" phases. A second build at the
 * same thread count goes into the BVH and primitive array the plugin kept
 * from the first (the device is kept per thread count), and is judged the
 * same way. With `width` 4 and 8 every quality gives Embree's own wide
 * tree on the generated scenes, valid and agreeing with brute force, no
 * node wider than asked and some that wide. Built only when Embree is found.
 */
#include <errno.h>
#include <unistd.h>

#include <bvhlab/bvhlab.h>

#include "testutil.h"

#define FIXTURE_SEED 3
#include "scene_fixture.h"

#define RAYS 256
#define MAX_LEAF 8

static const char *const qualities[] = {"low", "medium", "high"};

static bvhlab_plugin *plugin;

static int build(const bvhlab_prims *prims, const char *quality, uint32_t threads,
                 bvhlab_tree *tree, bvhlab_error *err)
{
	char q[32];

	snprintf(q, sizeof(q), "quality=%s", quality);
	return build_with(plugin, (const char *const[]){ q, NULL }, &prims->input, threads, tree,
	                  err);
}

static void check_leaves(const bvhlab_tree *t, const char *what)
{
	for (uint32_t i = 0; i < t->node_count; i++)
		if (t->nodes[i].count > MAX_LEAF) {
			fprintf(stderr, "%s: leaf %u holds %u > %d\n", what, i, t->nodes[i].count,
			        MAX_LEAF);
			test_failures++;
			return;
		}
}

/* The primitive array's fill and the conversion into the standard layout
 * are reported apart (ABI 1.3). */
static void check_phases(const bvhlab_tree *t, const char *what)
{
	static const char *const names[] = {"input", "convert"};
	for (int n = 0; n < 2; n++) {
		uint32_t k = 0;
		while (k < t->phase_count &&
		       (strcmp(t->phases[k].name, names[n]) != 0 || !(t->phases[k].ms >= 0)))
			k++;
		if (k == t->phase_count) {
			fprintf(stderr, "%s: no %s phase\n", what, names[n]);
			test_failures++;
		}
	}
}

/* One build, judged like the harness does; returns its reference count. */
static uint32_t check_one(const bvhlab_scene *s, const bvhlab_prims *prims, int q,
                          uint32_t threads)
{
	bvhlab_tree tree = {0};
	bvhlab_error err = {{0}};
	uint64_t mismatches = 1;
	uint32_t refs = 0;
	char what[160];
	snprintf(what, sizeof(what), "%s, %s, %u thread(s)", s->name, qualities[q], threads);
	int rc = build(prims, qualities[q], threads, &tree, &err);
	if (rc == 0)
		rc = bvhlab_validate_tree(&tree, &prims->input, q == 2, &err);
	if (rc == 0)
		rc = bvhlab_validate_rays(&tree, s, RAYS, 0x5eed, &mismatches, &err);
	if (rc < 0 || mismatches) {
		fprintf(stderr, "%s: rc %d, %llu mismatches: %s\n", what, rc,
		        (unsigned long long)mismatches, err.message);
		test_failures++;
	} else {
		check_leaves(&tree, what);
		check_phases(&tree, what);
		refs = tree.index_count;
		/* Split references have clipped boxes: judged without the
		 * spatial-splits flag, some leaf box must miss part of its triangle. */
		if (q == 2 && refs > prims->input.prim_count &&
		    bvhlab_validate_tree(&tree, &prims->input, false, &err) != -EINVAL) {
			fprintf(stderr, "%s: clipped boxes pass without the flag\n", what);
			test_failures++;
		}
		printf("ok: %s, %u nodes, %u references\n", what, tree.node_count, refs);
	}
	bvhlab_tree_finish(&tree);
	return refs;
}

/* Embree's own 4- and 8-wide trees (the width option), 2 threads. */
static void check_wide(const bvhlab_scene *s, const bvhlab_prims *prims, int q)
{
	for (uint32_t width = 4; width <= 8; width *= 2) {
		char qo[32], wo[32];
		bvhlab_tree tree = {0};
		bvhlab_error err = {{0}};
		uint64_t mismatches = 1;
		uint32_t widest = 0;
		snprintf(qo, sizeof(qo), "quality=%s", qualities[q]);
		snprintf(wo, sizeof(wo), "width=%u", width);
		int rc = build_with(plugin, (const char *const[]){qo, wo, NULL}, &prims->input, 2,
		                    &tree, &err);
		if (rc == 0)
			rc = bvhlab_validate_tree(&tree, &prims->input, q == 2, &err);
		if (rc == 0)
			rc = bvhlab_validate_rays(&tree, s, RAYS, 0x5eed, &mismatches, &err);
		if (rc < 0 || mismatches)
			fprintf(stderr, "%s, %s, %u-wide: rc %d, %llu mismatches: %s\n", s->name,
			        qualities[q], width, rc, (unsigned long long)mismatches, err.message);
		CHECK(rc == 0 && mismatches == 0);
		CHECK_INT(tree.width, width);
		for (uint32_t i = 0; i < tree.node_count; i++)
			if (tree.nodes[i].count & BVHLAB_NODE_INNER) {
				uint32_t k = tree.nodes[i].count & ~BVHLAB_NODE_INNER;
				widest = k > widest ? k : widest;
			}
		CHECK(widest > 2 && widest <= width);
		bvhlab_tree_finish(&tree);
	}
}

/* Returns the most references "high" made. */
static uint32_t check_scene(const bvhlab_scene *s)
{
	bvhlab_prims prims = {0};
	bvhlab_error err = {{0}};
	uint32_t most = 0;
	if (bvhlab_prims_init(&prims, s, &err) < 0) {
		fprintf(stderr, "%s: %s\n", s->name, err.message);
		test_failures++;
		return 0;
	}
	/* 2 twice: the second build reuses what the first kept. */
	static const uint32_t thread_counts[] = {1, 2, 2};
	for (int q = 0; q < 3; q++) {
		for (int k = 0; k < 3; k++) {
			uint32_t refs = check_one(s, &prims, q, thread_counts[k]);
			if (q == 2 && refs > most)
				most = refs;
		}
		if (s->triangle_count <= 20000) /* the generated scenes: the suite's time */
			check_wide(s, &prims, q);
	}
	bvhlab_prims_finish(&prims);
	return most;
}

static void check_generated(const char *gen, uint32_t count, bool expect_splits)
{
	bvhlab_scene *s = generate(gen, count, 16, 0);
	if (!s)
		return;
	uint32_t refs = check_scene(s);
	if (expect_splits)
		CHECK(refs > s->triangle_count);
	bvhlab_scene_destroy(s);
}

/* A missing ../shared reports "skipped" (77), not a pass without the meshes. */
static bool shared_missing;

static void check_mesh(const char *file)
{
	char path[1024];
	bvhlab_scene *s = NULL;
	bvhlab_error err = {{0}};
	snprintf(path, sizeof(path), "%s/%s", BVHLAB_SHARED_SCENES, file);
	if (access(path, R_OK) != 0) {
		printf("skip: %s not found\n", path);
		shared_missing = true;
		return;
	}
	CHECK_INT(bvhlab_scene_load(path, &s, &err), 0);
	if (s)
		check_scene(s);
	bvhlab_scene_destroy(s);
}

/* Duplicates are allowed for this descriptor, a missing primitive is not. */
static void check_missing_caught(void)
{
	bvhlab_gen_params gp;
	bvhlab_scene *s = NULL;
	bvhlab_prims prims = {0};
	bvhlab_tree t = {0};
	bvhlab_error err = {{0}};
	bvhlab_gen_params_init(&gp);
	gp.frequency = 8;
	CHECK_INT(bvhlab_scene_generate("icosphere", &gp, &s, &err), 0);
	CHECK_INT(bvhlab_prims_init(&prims, s, &err), 0);
	CHECK_INT(build(&prims, "medium", 2, &t, &err), 0);
	uint32_t leaf = 0;
	while (leaf < t.node_count && t.nodes[leaf].count < 2)
		leaf++;
	CHECK(leaf < t.node_count);
	if (leaf < t.node_count) {
		uint32_t *slot = &t.prim_index[t.nodes[leaf].first];
		slot[1] = slot[0]; /* one primitive twice, its neighbour nowhere */
		CHECK_INT(bvhlab_validate_tree(&t, &prims.input, true, &err), -EINVAL);
		CHECK_CONTAINS(err.message, "referenced by no leaf");
	}
	bvhlab_tree_finish(&t);
	bvhlab_prims_finish(&prims);
	bvhlab_scene_destroy(s);
}

int main(void)
{
	bvhlab_error err = {{0}};
	if (bvhlab_plugin_open("embree", &plugin, &err) < 0) {
		fprintf(stderr, "%s\n", err.message);
		return 1;
	}
	CHECK(bvhlab_plugin_builder(plugin)->flags & BVHLAB_BUILDER_SPATIAL_SPLITS);
	check_generated("icosphere", 0, false);
	check_generated("soup", 4000, true);
	check_generated("stadium", 4000, false);
	check_mesh("stanford-bunny.obj");
	check_mesh("horse.ply");
	check_missing_caught();
	bvhlab_plugin_close(plugin);
	return shared_missing && !test_failures ? TEST_SKIP : test_finish();
}
