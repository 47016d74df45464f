/*
 * Open trees (ABI 1.5): lbvh's binary tree collapsed by the wide_collapse
 * test stage into 3-, 4- and 8-wide trees, on generated scenes and every
 * shared mesh, is validated, compared, measured and traced like a binary
 * one: valid, equal to itself in another node order and to the collapse of
 * a rebuild, unequal to the binary tree, the same leaves, a lower depth,
 * and every traversal (stack, stackless, the wide view, wide4 and wide8
 * on the tree as built, wide8 on each of its code paths, the device ones
 * where a device is there) finds the same closest hits as in the binary
 * tree it came from, and the CPU ones the same rays blocked as any-hit
 * primary and shadow rays. The binary-only stages refuse it by name. Builds over
 * boxes (ABI 1.5 prim_kind): lbvh, ploc and sah_seq build a top-level tree
 * over instance boxes that validates (every box inside its leaf's box,
 * every id once); a triangle-only builder is refused by name.
 */
#include <errno.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include <bvhlab/bvhlab.h>
#include <bvhlab/epo.h>

#include "testutil.h"

#define FIXTURE_SEED 40
#include "scene_fixture.h"

#define SIDE 48 /* primary rays per side of the image */

static bvhlab_plugin *lbvh, *collapser;

/* Refines with plugin `p` and one option item (or NULL): 0 or the failure. */
static int stage(bvhlab_plugin *p, const char *item, const bvhlab_build_input *in,
                 bvhlab_tree *tree, bvhlab_error *err)
{
	bvhlab_options opts;
	int rc = bvhlab_options_init(&opts, bvhlab_plugin_builder(p));
	if (rc == 0 && item)
		rc = bvhlab_options_parse(&opts, item, err);
	if (rc == 0)
		rc = bvhlab_refine(p, &opts, in, 1, tree, err);
	bvhlab_options_finish(&opts);
	return rc;
}

static void collapse(const bvhlab_build_input *in, const bvhlab_tree *bin, uint32_t width,
                     bvhlab_tree *out)
{
	char item[32];
	bvhlab_error err = { { 0 } };
	snprintf(item, sizeof(item), "width=%u", width);
	tree_dup(out, bin);
	if (stage(collapser, item, in, out, &err) != 0)
		fprintf(stderr, "wide_collapse: %s\n", err.message);
	CHECK_INT(out->width, width);
}

/* The same tree written in another node order: the children lists of the
 * root's inner children reversed, with their subtrees' links fixed. */
static void reorder(bvhlab_tree *t)
{
	bvhlab_node *root = &t->nodes[0];
	uint32_t k = root->count == 0 ? 2 : root->count & ~BVHLAB_NODE_INNER, f = root->first;
	if (t->node_count == 1)
		return;
	for (uint32_t i = 0; i < k / 2; i++) {
		bvhlab_node x = t->nodes[f + i];
		t->nodes[f + i] = t->nodes[f + k - 1 - i];
		t->nodes[f + k - 1 - i] = x;
	}
}

/* Same closest hit: the same t, bit for bit, and the same triangle, or
 * another that the ray meets at that very t (a shared edge). */
static void check_same_hits(const char *what, const bvhlab_scene *scene,
                            const bvhlab_ray *rays, const bvhlab_hit *a, const bvhlab_hit *b,
                            size_t n)
{
	size_t bad = 0, ties = 0;
	for (size_t i = 0; i < n; i++) {
		if (a[i].prim == b[i].prim && (a[i].prim == BVHLAB_NO_HIT || a[i].t == b[i].t))
			continue;
		bvhlab_hit h = { rays[i].tmax, 0, 0, BVHLAB_NO_HIT };
		if (a[i].prim != BVHLAB_NO_HIT && b[i].prim != BVHLAB_NO_HIT && a[i].t == b[i].t &&
		    bvhlab_intersect_triangle(&rays[i], scene, b[i].prim, &h) && h.t == a[i].t) {
			ties++;
			continue;
		}
		if (bad++ == 0)
			fprintf(stderr, "%s: ray %zu: prim %u t %.9g vs prim %u t %.9g\n", what, i,
			        a[i].prim, a[i].t, b[i].prim, b[i].t);
	}
	if (ties)
		printf("  %s: %zu ties between triangles at the same t\n", what, ties);
	CHECK_INT(bad, 0);
}

/* Hits of `tree` with traversal `trav`; false when the traversal cannot
 * run here (a device one without a device). */
static bool trace(const bvhlab_tree *tree, const bvhlab_scene *scene, const bvhlab_ray *rays,
                  size_t n, int trav, bvhlab_hit *hits)
{
	bvhlab_trace_options o = { .traversal = trav, .threads = 2, .min_repeats = 1,
	                           .max_repeats = 1 };
	bvhlab_trace_timing timing;
	int rc = bvhlab_trace_measure(tree, scene, rays, n, &o, hits, NULL, &timing);
	static bool told;
	if (trav >= BVHLAB_TRAVERSAL_DEVICE_STACK && (rc == -ENOTSUP || rc == -ENODEV)) {
		if (!told)
			printf("  device traversals skipped: no OpenCL device\n");
		told = true;
		return false;
	}
	CHECK_INT(rc, 0);
	return rc == 0;
}

/* Rays of an any-hit batch by traversal `trav` blocked exactly when the
 * closest hits `ref` have a hit: how many are not. */
static size_t any_differs(const bvhlab_tree *tree, const bvhlab_scene *scene,
                          const bvhlab_ray *rays, size_t n, int trav, const bvhlab_hit *ref,
                          bvhlab_hit *hits)
{
	bvhlab_trace_options o = { .traversal = trav, .threads = 2, .min_repeats = 1,
	                           .max_repeats = 1, .any_hit = true };
	bvhlab_trace_timing timing;
	size_t bad = 0;
	CHECK_INT(bvhlab_trace_measure(tree, scene, rays, n, &o, hits, NULL, &timing), 0);
	for (size_t i = 0; i < n; i++)
		bad += (hits[i].prim == BVHLAB_NO_HIT) != (ref[i].prim == BVHLAB_NO_HIT);
	return bad;
}

/* One CPU traversal on `wide`: the closest hits of ref, and as any-hit
 * rays the same rays blocked, and the shadow rays blocked as the stack
 * traversal's closest hits (shadow_ref) say. */
static void check_cpu(const char *what, const bvhlab_scene *scene, const bvhlab_tree *wide,
                      int trav, const bvhlab_ray *rays, size_t n, const bvhlab_hit *ref,
                      const bvhlab_ray *shadow, size_t ns, const bvhlab_hit *shadow_ref,
                      bvhlab_hit *hits)
{
	if (!trace(wide, scene, rays, n, trav, hits))
		return;
	check_same_hits(what, scene, rays, ref, hits, n);
	size_t bad = any_differs(wide, scene, rays, n, trav, ref, hits);
	if (ns)
		bad += any_differs(wide, scene, shadow, ns, trav, shadow_ref, hits);
	if (bad)
		fprintf(stderr, "%s: %zu any-hit rays (primary and shadow) disagree\n", what, bad);
	CHECK_INT(bad, 0);
}

/* Every traversal finds in `wide` the closest hits `ref` (the binary
 * tree's, stack traversal) has; the CPU ones also agree on any-hit
 * primary and shadow rays, wide8 with each code path this CPU runs. */
static void check_traced(const char *name, const bvhlab_scene *scene, const bvhlab_tree *wide,
                         const bvhlab_ray *rays, size_t n, const bvhlab_hit *ref)
{
	static const char *const isas[] = { "portable", "avx2", "avx512" };
	bvhlab_hit *hits = malloc(n * sizeof(*hits)), *shadow_ref = NULL;
	bvhlab_ray *shadow = NULL;
	size_t ns = 0;
	float light[3];
	bvhlab_light_frame(&scene->bounds, light);
	CHECK_INT(bvhlab_rays_shadow(scene, rays, ref, n, light, &shadow, &ns), 0);
	shadow_ref = ns ? malloc(ns * sizeof(*shadow_ref)) : NULL;
	if (ns && (!shadow_ref || !trace(wide, scene, shadow, ns, BVHLAB_TRAVERSAL_STACK,
	                                 shadow_ref)))
		ns = 0;
	CHECK(hits != NULL);
	for (int trav = 0; hits && trav < BVHLAB_TRAVERSAL_COUNT; trav++) {
		char what[96];
		snprintf(what, sizeof(what), "%s %u-wide %s", name, wide->width,
		         bvhlab_traversal_name(trav));
		if (trav == BVHLAB_TRAVERSAL_DEVICE_STACK || trav == BVHLAB_TRAVERSAL_DEVICE_STACKLESS ||
		    trav == BVHLAB_TRAVERSAL_DEVICE_WIDE8) {
			if (trace(wide, scene, rays, n, trav, hits))
				check_same_hits(what, scene, rays, ref, hits, n);
			continue;
		}
		for (size_t k = 0; k < (trav == BVHLAB_TRAVERSAL_WIDE8 ? 3u : 1u); k++) {
			char isa[128];
			snprintf(isa, sizeof(isa), "%s%s%s", what, trav == BVHLAB_TRAVERSAL_WIDE8 ? " " : "",
			         trav == BVHLAB_TRAVERSAL_WIDE8 ? isas[k] : "");
			if (trav == BVHLAB_TRAVERSAL_WIDE8)
				setenv("BVHLAB_WIDE8_ISA", isas[k], 1);
			check_cpu(isa, scene, wide, trav, rays, n, ref, shadow, ns, shadow_ref, hits);
		}
		unsetenv("BVHLAB_WIDE8_ISA");
	}
	free(hits);
	free(shadow);
	free(shadow_ref);
}

/* One width on one scene: the judges on the collapsed tree. */
static void check_width(const char *name, const bvhlab_scene *scene,
                        const bvhlab_build_input *in, const bvhlab_tree *bin, uint32_t width,
                        const bvhlab_ray *rays, size_t n, const bvhlab_hit *ref)
{
	bvhlab_tree wide, again;
	bvhlab_tree_stats sb, sw;
	bvhlab_error err = { { 0 } };
	collapse(in, bin, width, &wide);
	if (bvhlab_validate_tree(&wide, in, false, &err) != 0)
		fprintf(stderr, "%s %u-wide: %s\n", name, width, err.message);
	CHECK_INT(bvhlab_validate_tree(&wide, in, false, &err), 0);
	bvhlab_tree_stats_compute(bin, &sb);
	bvhlab_tree_stats_compute(&wide, &sw);
	CHECK_INT(sw.leaves, sb.leaves);
	CHECK_INT(sw.refs, sb.refs);
	CHECK(sw.max_depth <= sb.max_depth);
	CHECK(isfinite(sw.sah_cost) && sw.sah_cost > 0);
	if (sb.leaves > 2)
		CHECK(sw.nodes < sb.nodes);
	printf("  %s %u-wide: %u nodes (binary %u), depth %u (%u), SAH %.3f (%.3f)\n", name,
	       width, sw.nodes, sb.nodes, sw.max_depth, sb.max_depth, sw.sah_cost, sb.sah_cost);
	tree_dup(&again, &wide);
	reorder(&again);
	CHECK_INT(bvhlab_validate_tree(&again, in, false, &err), 0);
	CHECK_INT(bvhlab_tree_compare(&wide, &again, &err), 0);
	if (sb.leaves > 2) {
		CHECK_INT(bvhlab_tree_compare(&wide, bin, &err), 1);
		CHECK_CONTAINS(err.message, "children");
	}
	check_traced(name, scene, &wide, rays, n, ref);
	bvhlab_tree_finish(&again);
	bvhlab_tree_finish(&wide);
}

/* EPO and the sampled ray check against brute force (generated scenes). */
static void check_judged(const char *name, const bvhlab_scene *scene,
                         const bvhlab_build_input *in, const bvhlab_tree *bin)
{
	bvhlab_tree wide;
	uint64_t mismatches = 1;
	double epo_bin = -1, epo_wide = -1;
	bvhlab_error err = { { 0 } };
	collapse(in, bin, 4, &wide);
	CHECK_INT(bvhlab_validate_rays(&wide, scene, 512, 40, &mismatches, &err), 0);
	CHECK_INT(mismatches, 0);
	CHECK_INT(bvhlab_tree_epo(bin, scene, 2000, 40, &epo_bin), 0);
	CHECK_INT(bvhlab_tree_epo(&wide, scene, 2000, 40, &epo_wide), 0);
	CHECK(epo_wide >= 0 && isfinite(epo_wide));
	printf("  %s: EPO binary %.4f, 4-wide %.4f\n", name, epo_bin, epo_wide);
	bvhlab_tree_finish(&wide);
}

static void test_scene(const char *name, bvhlab_scene *scene, bool generated)
{
	bvhlab_prims prims;
	bvhlab_error err = { { 0 } };
	bvhlab_tree bin = { 0 };
	bvhlab_camera cam;
	bvhlab_ray *rays = NULL;
	bvhlab_hit *ref = NULL;
	const char *none[] = { NULL };
	if (!scene)
		return;
	CHECK_INT(bvhlab_prims_init(&prims, scene, &err), 0);
	CHECK_INT(build_with(lbvh, none, &prims.input, 2, &bin, &err), 0);
	CHECK_INT(bvhlab_validate_tree(&bin, &prims.input, false, &err), 0);
	bvhlab_camera_frame(&scene->bounds, &cam);
	CHECK_INT(bvhlab_rays_primary(&cam, SIDE, SIDE, &rays), 0);
	ref = malloc(SIDE * SIDE * sizeof(*ref));
	CHECK(ref != NULL);
	if (ref && rays && trace(&bin, scene, rays, SIDE * SIDE, BVHLAB_TRAVERSAL_STACK, ref)) {
		static const uint32_t widths[] = { 3, 4, 8 };
		for (size_t w = generated ? 0 : 1; w < 3; w++)
			check_width(name, scene, &prims.input, &bin, widths[w], rays, SIDE * SIDE, ref);
		if (generated)
			check_judged(name, scene, &prims.input, &bin);
	}
	free(ref);
	free(rays);
	bvhlab_tree_finish(&bin);
	bvhlab_prims_finish(&prims);
	bvhlab_scene_destroy(scene);
}

/* reinsert (refine) and refit (update) keep the binary fast path: a wide
 * tree is refused by name, before the plugin sees it. */
static void test_binary_only(void)
{
	bvhlab_scene *scene = generate("soup", 200, 0, 0);
	bvhlab_plugin *reinsert = NULL, *refit = NULL;
	bvhlab_prims prims;
	bvhlab_tree bin = { 0 }, wide;
	bvhlab_error err = { { 0 } };
	const char *none[] = { NULL };
	CHECK_INT(bvhlab_prims_init(&prims, scene, &err), 0);
	CHECK_INT(build_with(lbvh, none, &prims.input, 1, &bin, &err), 0);
	collapse(&prims.input, &bin, 4, &wide);
	if (plugin_loads("reinsert", &reinsert)) {
		CHECK_INT(stage(reinsert, NULL, &prims.input, &wide, &err), -ENOTSUP);
		CHECK_CONTAINS(err.message, "refinement 'reinsert' takes binary trees only; this tree "
		                            "is 4-wide");
	}
	if (plugin_loads("refit", &refit)) {
		bvhlab_options opts;
		CHECK_INT(bvhlab_options_init(&opts, bvhlab_plugin_builder(refit)), 0);
		CHECK_INT(bvhlab_update(refit, &opts, &prims.input, 1, &wide, &err), -ENOTSUP);
		CHECK_CONTAINS(err.message, "update 'refit' takes binary trees only");
		bvhlab_options_finish(&opts);
	}
	CHECK_INT(stage(collapser, NULL, &prims.input, &wide, &err), -ENOTSUP);
	CHECK_CONTAINS(err.message, "refinement 'wide_collapse' takes binary trees only");
	bvhlab_plugin_close(reinsert);
	bvhlab_plugin_close(refit);
	bvhlab_tree_finish(&wide);
	bvhlab_tree_finish(&bin);
	bvhlab_prims_finish(&prims);
	bvhlab_scene_destroy(scene);
}

/* Uniform in [0, 1), from a splitmix64 state. */
static float unit(uint64_t *state)
{
	uint64_t z = (*state += 0x9e3779b97f4a7c15u);
	z = (z ^ (z >> 30)) * 0xbf58476d1ce4e5b9u;
	z = (z ^ (z >> 27)) * 0x94d049bb133111ebu;
	return (float)((z ^ (z >> 31)) >> 40) * 0x1p-24f;
}

/* Instance boxes of a top-level build: clusters of boxes of mixed sizes,
 * some identical, some overlapping. */
static bvhlab_aabb *instance_boxes(uint32_t n)
{
	bvhlab_aabb *b = malloc(n * sizeof(*b));
	uint64_t s = 40;
	for (uint32_t i = 0; b && i < n; i++) {
		float size = 0.01f + 4.0f * unit(&s);
		for (int k = 0; k < 3; k++) {
			b[i].lo[k] = i % 7 == 0 ? 0.0f : 100.0f * unit(&s);
			b[i].hi[k] = b[i].lo[k] + size;
		}
	}
	return b;
}

/* What a top-level tree must be, read from the nodes themselves: every
 * box inside its leaf's node box, every id in exactly one leaf. */
static void check_box_tree(const bvhlab_tree *t, const bvhlab_aabb *boxes, uint32_t n)
{
	uint8_t *seen = calloc(n, 1);
	CHECK(seen != NULL);
	for (uint32_t i = 0; seen && i < t->node_count; i++) {
		const bvhlab_node *nd = &t->nodes[i];
		if (nd->count == 0 || (nd->count & BVHLAB_NODE_INNER))
			continue;
		for (uint32_t s = nd->first; s < nd->first + nd->count; s++) {
			uint32_t id = t->prim_index[s];
			CHECK(id < n && !seen[id]);
			if (id >= n)
				continue;
			seen[id] = 1;
			for (int k = 0; k < 3; k++)
				CHECK(nd->lo[k] <= boxes[id].lo[k] && boxes[id].hi[k] <= nd->hi[k]);
		}
	}
	for (uint32_t i = 0; seen && i < n; i++)
		CHECK(seen[i]);
	free(seen);
}

static void test_boxes(void)
{
	static const char *takers[] = { "lbvh", "ploc", "sah_seq", "sah_tasks", "sbvh" };
	static const uint32_t counts[] = { 1, 2, 777 };
	const char *none[] = { NULL };
	bvhlab_error err = { { 0 } };
	for (size_t c = 0; c < 3; c++) {
		bvhlab_aabb *boxes = instance_boxes(counts[c]);
		bvhlab_prims prims;
		CHECK(boxes != NULL);
		CHECK_INT(bvhlab_prims_init_boxes(&prims, boxes, counts[c], &err), 0);
		CHECK_INT(prims.input.prim_kind, BVHLAB_PRIM_BOXES);
		CHECK(prims.input.vertices == NULL && prims.input.indices == NULL);
		for (size_t k = 0; k < sizeof(takers) / sizeof(takers[0]); k++) {
			bvhlab_plugin *p = NULL;
			bvhlab_tree t = { 0 }, wide;
			if (!plugin_loads(takers[k], &p))
				continue;
			CHECK(bvhlab_builder_takes_boxes(bvhlab_plugin_builder(p)));
			if (build_with(p, none, &prims.input, 2, &t, &err) != 0)
				fprintf(stderr, "%s over boxes: %s\n", takers[k], err.message);
			CHECK_INT(bvhlab_validate_tree(&t, &prims.input, false, &err), 0);
			check_box_tree(&t, boxes, counts[c]);
			collapse(&prims.input, &t, 4, &wide);
			CHECK_INT(bvhlab_validate_tree(&wide, &prims.input, false, &err), 0);
			check_box_tree(&wide, boxes, counts[c]);
			bvhlab_tree_finish(&wide);
			bvhlab_tree_finish(&t);
			bvhlab_plugin_close(p);
		}
		bvhlab_prims_finish(&prims);
		free(boxes);
	}
}

/* A builder without BVHLAB_BUILDER_BOXES is refused a box build by name,
 * before it is called; a bad box is refused when the input is made. */
static void test_box_refusals(void)
{
	bvhlab_aabb boxes[2] = { { { 0, 0, 0 }, { 1, 1, 1 } }, { { 2, 0, 0 }, { 3, 1, 1 } } };
	bvhlab_plugin *p = NULL;
	bvhlab_prims prims;
	bvhlab_tree t = { 0 };
	bvhlab_error err = { { 0 } };
	const char *none[] = { NULL };
	CHECK_INT(bvhlab_prims_init_boxes(&prims, boxes, 2, &err), 0);
	if (plugin_loads("hlbvh", &p)) {
		CHECK(!bvhlab_builder_takes_boxes(bvhlab_plugin_builder(p)));
		CHECK_INT(build_with(p, none, &prims.input, 1, &t, &err), -ENOTSUP);
		CHECK_CONTAINS(err.message, "builder 'hlbvh' builds over triangles only");
		CHECK_INT(t.node_count, 0);
	}
	bvhlab_plugin_close(p);
	bvhlab_tree_finish(&t);
	bvhlab_prims_finish(&prims);
	boxes[1].lo[0] = NAN;
	CHECK_INT(bvhlab_prims_init_boxes(&prims, boxes, 2, &err), -EINVAL);
	CHECK_CONTAINS(err.message, "box 1 is empty or not finite");
}

int main(void)
{
	static const struct scene_sizes sizes = { 3000, 8, 2000, 32, 40 };
	static const char *const shared[] = { "stanford-bunny.obj", "horse.ply", "igea.ply",
		                              "nefertiti.obj", "ogre.obj", "sponza.obj",
		                              "conference.obj" };
	if (!plugin_loads("lbvh", &lbvh) || !plugin_loads("wide_collapse", &collapser))
		return test_finish();
	for_scenes(&sizes, shared, 7, 1, test_scene);
	test_binary_only();
	test_boxes();
	test_box_refusals();
	bvhlab_plugin_close(lbvh);
	bvhlab_plugin_close(collapser);
	return test_finish();
}
