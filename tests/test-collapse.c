/*
 * The collapse refinement stage (plugins/collapse): after lbvh, sah_tasks,
 * ploc and sbvh, on the generated scenes and the bunny, both methods at
 * widths 4 and 8 give a valid tree of that width with every reference of
 * the binary tree in one leaf (as many times as before), no wider node,
 * and the closest hits of the binary tree on every primary ray; `sah`'s
 * wide SAH is never above `greedy`'s. On tiny trees `sah`'s cost, under
 * the default and under other cost constants and leaf limits, is the
 * optimum found by enumerating every wide node's possible child sets.
 * Options outside the declared ones are refused; a wide tree is refused.
 */
#include <errno.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include <bvhlab/aabb.h>
#include <bvhlab/bvhlab.h>

#include "testutil.h"

#define FIXTURE_SEED 41
#include "scene_fixture.h"

#define SIDE 40 /* primary rays per side of the image */

static bvhlab_plugin *collapser;

/* Refines `tree` with collapse and the option items (NULL-terminated). */
static int collapse(const char *const *items, const bvhlab_build_input *in, bvhlab_tree *tree,
                    bvhlab_error *err)
{
	bvhlab_options opts;
	int rc = bvhlab_options_init(&opts, bvhlab_plugin_builder(collapser));
	for (size_t k = 0; rc == 0 && items[k]; k++)
		rc = bvhlab_options_parse(&opts, items[k], err);
	if (rc == 0)
		rc = bvhlab_refine(collapser, &opts, in, 1, tree, err);
	bvhlab_options_finish(&opts);
	return rc;
}

/* How often each primitive is referenced by the tree's leaves. */
static uint32_t *ref_counts(const bvhlab_tree *t, uint32_t prims)
{
	uint32_t *c = calloc(prims, sizeof(*c));
	CHECK(c != NULL);
	for (uint32_t i = 0; c && i < t->node_count; i++) {
		const bvhlab_node *n = &t->nodes[i];
		if (n->count == 0 || (n->count & BVHLAB_NODE_INNER))
			continue;
		for (uint32_t s = n->first; s < n->first + n->count; s++)
			c[t->prim_index[s]]++;
	}
	return c;
}

/* No node wider than the tree says, at least one that wide (a tree big
 * enough to have one), and the same references as the binary tree. */
static void check_shape(const char *what, const bvhlab_tree *bin, const bvhlab_tree *wide,
                        uint32_t prims, uint32_t width)
{
	uint32_t widest = 2, *a = ref_counts(bin, prims), *b = ref_counts(wide, prims);
	CHECK_INT(wide->width, width);
	CHECK_INT(wide->index_count, bin->index_count);
	for (uint32_t i = 0; i < wide->node_count; i++) {
		const bvhlab_node *n = &wide->nodes[i];
		uint32_t k = n->count & BVHLAB_NODE_INNER ? n->count & ~BVHLAB_NODE_INNER : 2;
		if (n->count == 0 || (n->count & BVHLAB_NODE_INNER))
			widest = k > widest ? k : widest;
	}
	CHECK(widest <= width);
	if (bin->node_count > 4 * width)
		CHECK(widest > 2);
	if (a && b && memcmp(a, b, prims * sizeof(*a)) != 0) {
		fprintf(stderr, "%s: the references changed\n", what);
		CHECK(!"same references");
	}
	free(a);
	free(b);
}

/* The same closest hit as the binary tree's: same t, bit for bit, and the
 * same triangle or another the ray meets at that t (a shared edge). */
static void check_hits(const char *what, const bvhlab_scene *scene, const bvhlab_tree *wide,
                       const bvhlab_ray *rays, const bvhlab_hit *ref, size_t n)
{
	bvhlab_trace_options o = { .traversal = BVHLAB_TRAVERSAL_STACK, .threads = 1,
	                           .min_repeats = 1, .max_repeats = 1 };
	bvhlab_trace_timing timing;
	bvhlab_hit *hits = malloc(n * sizeof(*hits));
	size_t bad = 0;
	CHECK(hits != NULL);
	if (!hits)
		return;
	CHECK_INT(bvhlab_trace_measure(wide, scene, rays, n, &o, hits, NULL, &timing), 0);
	for (size_t i = 0; i < n; i++) {
		bvhlab_hit h = { rays[i].tmax, 0, 0, BVHLAB_NO_HIT };
		if (hits[i].prim == ref[i].prim && (ref[i].prim == BVHLAB_NO_HIT || hits[i].t == ref[i].t))
			continue;
		if (hits[i].prim != BVHLAB_NO_HIT && ref[i].prim != BVHLAB_NO_HIT &&
		    hits[i].t == ref[i].t && bvhlab_intersect_triangle(&rays[i], scene, hits[i].prim, &h) &&
		    h.t == ref[i].t)
			continue;
		if (bad++ == 0)
			fprintf(stderr, "%s: ray %zu: prim %u t %.9g, binary prim %u t %.9g\n", what, i,
			        hits[i].prim, hits[i].t, ref[i].prim, ref[i].t);
	}
	CHECK_INT(bad, 0);
	free(hits);
}

struct scene_case {
	const char *name;
	const bvhlab_scene *scene;
	const bvhlab_build_input *in;
	const bvhlab_ray *rays;
	size_t n;
};

/* One builder's tree collapsed both ways at both widths. */
static void check_builder(const struct scene_case *sc, const char *builder, bool dup)
{
	static const char *const methods[] = { "method=sah", "method=greedy" };
	static const char *const widths[] = { "width=4", "width=8" };
	bvhlab_plugin *p = NULL;
	bvhlab_tree bin = { 0 };
	bvhlab_error err = { { 0 } };
	const char *none[] = { NULL };
	bvhlab_hit *ref = malloc(sc->n * sizeof(*ref));
	bvhlab_trace_options o = { .traversal = BVHLAB_TRAVERSAL_STACK, .threads = 1,
	                           .min_repeats = 1, .max_repeats = 1 };
	bvhlab_trace_timing timing;
	if (!ref || !plugin_loads(builder, &p) || build_with(p, none, sc->in, 1, &bin, &err) != 0 ||
	    bvhlab_trace_measure(&bin, sc->scene, sc->rays, sc->n, &o, ref, NULL, &timing) != 0) {
		fprintf(stderr, "%s on %s: %s\n", builder, sc->name, err.message);
		CHECK(!"binary tree built and traced");
		goto out;
	}
	for (size_t w = 0; w < 2; w++) {
		double sah[2];
		for (size_t m = 0; m < 2; m++) {
			const char *items[] = { methods[m], widths[w], NULL };
			char what[128];
			bvhlab_tree wide;
			bvhlab_tree_stats st;
			snprintf(what, sizeof(what), "%s %s %s %s", sc->name, builder, methods[m] + 7,
			         widths[w] + 6);
			tree_dup(&wide, &bin);
			if (collapse(items, sc->in, &wide, &err) != 0 ||
			    bvhlab_validate_tree(&wide, sc->in, dup, &err) != 0) {
				fprintf(stderr, "%s: %s\n", what, err.message);
				CHECK(!"valid wide tree");
			} else {
				check_shape(what, &bin, &wide, sc->in->prim_count, 4u << w);
				check_hits(what, sc->scene, &wide, sc->rays, ref, sc->n);
			}
			bvhlab_tree_stats_compute(&wide, &st);
			sah[m] = st.sah_cost;
			bvhlab_tree_finish(&wide);
		}
		printf("  %-18s %-9s %s  SAH sah %9.4f  greedy %9.4f\n", sc->name, builder, widths[w],
		       sah[0], sah[1]);
		CHECK(sah[0] <= sah[1] * (1 + 1e-9));
	}
out:
	free(ref);
	bvhlab_tree_finish(&bin);
	bvhlab_plugin_close(p);
}

static void test_scene(const char *name, bvhlab_scene *scene, bool generated)
{
	static const char *const builders[] = { "lbvh", "sah_tasks", "ploc", "sbvh" };
	bvhlab_prims prims;
	bvhlab_error err = { { 0 } };
	bvhlab_camera cam;
	bvhlab_ray *rays = NULL;
	(void)generated;
	if (!scene)
		return;
	CHECK_INT(bvhlab_prims_init(&prims, scene, &err), 0);
	bvhlab_camera_frame(&scene->bounds, &cam);
	CHECK_INT(bvhlab_rays_primary(&cam, SIDE, SIDE, &rays), 0);
	struct scene_case sc = { name, scene, &prims.input, rays, SIDE * SIDE };
	for (size_t b = 0; rays && b < 4; b++)
		check_builder(&sc, builders[b], b == 3);
	free(rays);
	bvhlab_prims_finish(&prims);
	bvhlab_scene_destroy(scene);
}

/* ---- the optimum of tiny trees, by enumeration ------------------------------ */

struct costs {
	const char *items[7]; /* collapse's options, NULL-terminated */
	double c_node, c_trav, c_isect;
	uint32_t max_leaf, width;
};

/* A child set of a wide node: how many nodes, and their subtrees' least
 * costs summed. */
struct cut {
	uint32_t size;
	double sum;
};

struct cuts {
	struct cut *c;
	size_t n;
};

static double node_area(const bvhlab_node *n)
{
	return bvhlab_box_area(n->lo, n->hi);
}

static uint32_t refs_under(const bvhlab_tree *t, uint32_t n)
{
	const bvhlab_node *b = &t->nodes[n];
	return b->count ? b->count : refs_under(t, b->first) + refs_under(t, b->first + 1);
}

/*
 * Every set of at most `width` nodes whose subtrees make up n's subtree
 * ({n} itself, and each union of a left and a right one), listed one by
 * one, none merged with another; *best the least cost of n's subtree as
 * one wide node (a leaf, or an inner node over any of its children's sets).
 */
static struct cuts enumerate(const bvhlab_tree *t, const struct costs *k, uint32_t n,
                             double *best)
{
	const bvhlab_node *b = &t->nodes[n];
	double a = node_area(b), leaf = INFINITY, inner = INFINITY, bl, br;
	struct cuts out = { NULL, 0 };
	uint32_t refs = refs_under(t, n);
	if (b->count != 0 || refs <= k->max_leaf)
		leaf = a * k->c_isect * refs;
	if (b->count != 0) {
		*best = leaf;
	} else {
		struct cuts l = enumerate(t, k, b->first, &bl), r = enumerate(t, k, b->first + 1, &br);
		out.c = malloc((l.n * r.n + 1) * sizeof(*out.c));
		CHECK(out.c != NULL);
		for (size_t i = 0; out.c && i < l.n; i++)
			for (size_t j = 0; j < r.n; j++) {
				uint32_t size = l.c[i].size + r.c[j].size;
				if (size > k->width)
					continue;
				double sum = l.c[i].sum + r.c[j].sum;
				double v = sum + a * (k->c_node + k->c_trav * 0.5 * size);
				inner = v < inner ? v : inner;
				out.c[out.n++] = (struct cut){ size, sum };
			}
		free(l.c);
		free(r.c);
		*best = leaf < inner ? leaf : inner;
	}
	if (!out.c)
		out.c = malloc(sizeof(*out.c));
	CHECK(out.c != NULL);
	if (out.c)
		out.c[out.n++] = (struct cut){ 1, *best };
	return out;
}

/* The cost of a wide tree under the constants (collapse.h's formula). */
static double wide_cost(const bvhlab_tree *t, const struct costs *k)
{
	double sum = 0;
	for (uint32_t i = 0; i < t->node_count; i++) {
		const bvhlab_node *n = &t->nodes[i];
		bool inner = n->count == 0 || (n->count & BVHLAB_NODE_INNER);
		uint32_t c = n->count & BVHLAB_NODE_INNER ? n->count & ~BVHLAB_NODE_INNER : 2;
		sum += node_area(n) * (inner ? k->c_node + k->c_trav * 0.5 * c : k->c_isect * n->count);
	}
	return sum;
}

/* sah's tree over `count` triangles (lbvh's, leaves of one unless
 * `leaves`) costs the enumerated optimum, for each set of constants. */
static void test_optimum(uint32_t count, bool leaves, const struct costs *sets, size_t n_sets)
{
	bvhlab_scene *scene = generate("soup", count, 0, 0);
	bvhlab_plugin *lbvh = NULL;
	bvhlab_prims prims;
	bvhlab_tree bin = { 0 };
	bvhlab_error err = { { 0 } };
	const char *items[] = { leaves ? "max_leaf=4" : "collapse=false", NULL };
	if (!scene || !plugin_loads("lbvh", &lbvh))
		goto out;
	CHECK_INT(bvhlab_prims_init(&prims, scene, &err), 0);
	CHECK_INT(build_with(lbvh, items, &prims.input, 1, &bin, &err), 0);
	for (size_t s = 0; s < n_sets; s++) {
		bvhlab_tree wide;
		double best;
		struct cuts all = enumerate(&bin, &sets[s], 0, &best);
		free(all.c);
		tree_dup(&wide, &bin);
		CHECK_INT(collapse(sets[s].items, &prims.input, &wide, &err), 0);
		CHECK_INT(bvhlab_validate_tree(&wide, &prims.input, false, &err), 0);
		double got = wide_cost(&wide, &sets[s]);
		if (!(fabs(got - best) <= 1e-9 * best))
			fprintf(stderr, "%u triangles, set %zu: sah's tree costs %.12g, the optimum %.12g\n",
			        count, s, got, best);
		CHECK(fabs(got - best) <= 1e-9 * best);
		if (s == 0) { /* the default constants: the reported SAH */
			bvhlab_tree_stats st;
			bvhlab_tree_stats_compute(&wide, &st);
			CHECK(fabs(st.sah_cost * node_area(&wide.nodes[0]) - best) <= 1e-9 * best);
		}
		bvhlab_tree_finish(&wide);
	}
	bvhlab_tree_finish(&bin);
	bvhlab_prims_finish(&prims);
out:
	bvhlab_plugin_close(lbvh);
	bvhlab_scene_destroy(scene);
}

static void test_optima(void)
{
	static const struct costs sets[] = {
		{ { "width=4", NULL }, 0, 1, 1, 8, 4 },
		{ { "width=8", NULL }, 0, 1, 1, 8, 8 },
		{ { "width=4", "c_node=0.7", "c_trav=0.4", "c_isect=0.3", "max_leaf=3", NULL },
		  0.7, 0.4, 0.3, 3, 4 },
		{ { "width=8", "c_node=0.2", "c_trav=3", "c_isect=0.2", "max_leaf=5", NULL },
		  0.2, 3, 0.2, 5, 8 },
		{ { "width=4", "c_trav=0", "max_leaf=1", NULL }, 0, 0, 1, 1, 4 },
		{ { "width=8", "c_node=5", "c_trav=0.1", "c_isect=2", "max_leaf=2", NULL },
		  5, 0.1, 2, 2, 8 },
	};
	for (uint32_t count = 2; count <= 13; count++)
		test_optimum(count, false, sets, sizeof(sets) / sizeof(sets[0]));
	test_optimum(40, true, sets, sizeof(sets) / sizeof(sets[0]));
}

/* Out-of-range options are refused when read; a wide tree is refused. */
static void test_refusals(void)
{
	bvhlab_options opts;
	bvhlab_error err = { { 0 } };
	CHECK_INT(bvhlab_options_init(&opts, bvhlab_plugin_builder(collapser)), 0);
	CHECK(bvhlab_options_parse(&opts, "width=6", &err) < 0);
	CHECK_CONTAINS(err.message, "width");
	CHECK(bvhlab_options_parse(&opts, "method=optimal", &err) < 0);
	CHECK_CONTAINS(err.message, "sah|greedy");
	bvhlab_options_finish(&opts);

	bvhlab_scene *scene = generate("soup", 100, 0, 0);
	bvhlab_plugin *lbvh = NULL;
	bvhlab_prims prims;
	bvhlab_tree t = { 0 };
	const char *none[] = { NULL };
	if (scene && plugin_loads("lbvh", &lbvh)) {
		CHECK_INT(bvhlab_prims_init(&prims, scene, &err), 0);
		CHECK_INT(build_with(lbvh, none, &prims.input, 1, &t, &err), 0);
		CHECK_INT(collapse(none, &prims.input, &t, &err), 0);
		CHECK_INT(collapse(none, &prims.input, &t, &err), -ENOTSUP);
		CHECK_CONTAINS(err.message, "refinement 'collapse' takes binary trees only");
		bvhlab_tree_finish(&t);
		bvhlab_prims_finish(&prims);
	}
	bvhlab_plugin_close(lbvh);
	bvhlab_scene_destroy(scene);
}

int main(void)
{
	static const struct scene_sizes sizes = { 2000, 6, 1500, 24, 40 };
	static const char *const shared[] = { "stanford-bunny.obj" };
	if (!plugin_loads("collapse", &collapser))
		return test_finish();
	test_optima();
	test_refusals();
	for_scenes(&sizes, shared, 1, 0, test_scene);
	bvhlab_plugin_close(collapser);
	return test_finish();
}
