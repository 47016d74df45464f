/*
 * The stackless and wide traversals against the stack traversal and brute
 * force: the same closest hit (triangle, and t, u, v bit for bit) on
 * hand-made trees with shared edges, coincident triangles (ties) and a
 * deep chain; on every shared mesh with trees of two builders and on the
 * degenerate generated scenes (brute force too there), with primary,
 * diffuse, shadow and AO rays (the last two any-hit: blocked or not). The
 * timed batch tracer: exact counters of one pass (the binary tree's for
 * every traversal), its repeats and its errors.
 */
#include <errno.h>
#include <math.h>
#include <string.h>
#include <sys/stat.h>

#include <bvhlab/bvhlab.h>
#include <bvhlab/trace.h>

#include "testutil.h"
#include "trace/trace_series.h"
#define FIXTURE_SEED 17 /* scene_fixture.h's generators are not used here */
#include "scene_fixture.h"
#include "tree_fixture.h"

static bool same_hit(const bvhlab_hit *a, const bvhlab_hit *b)
{
	return a->prim == b->prim && memcmp(a, b, sizeof(*a)) == 0;
}

/* Rays from above a z = 0 grid, through cell corners, edges and insides. */
static bvhlab_ray grid_ray(uint64_t *seed, float size)
{
	bvhlab_ray r = {.tmin = 0, .tmax = INFINITY};
	float quant = (float)(fx_rand(seed) % 4) * 0.5f; /* 0, .5, 1, 1.5: on edges */
	r.org[0] = (float)(fx_rand(seed) % (uint64_t)size) + (fx_rand(seed) % 2 ? quant : fx_unit(seed));
	r.org[1] = (float)(fx_rand(seed) % (uint64_t)size) + (fx_rand(seed) % 2 ? quant : fx_unit(seed));
	r.org[2] = 3.0f;
	r.dir[0] = fx_rand(seed) % 2 ? 0.0f : fx_unit(seed) - 0.5f;
	r.dir[1] = fx_rand(seed) % 2 ? 0.0f : fx_unit(seed) - 0.5f;
	r.dir[2] = -1.0f;
	return r;
}

/* Every traversal and brute force agree on ray r over f's tree. */
static int agree(const fixture *f, const uint32_t *parents, const bvhlab_ray *r)
{
	bvhlab_hit a, b, c, d;
	bvhlab_trace_closest(&f->tree, &f->scene, r, &a, NULL);
	bvhlab_trace_stackless(&f->tree, parents, &f->scene, r, false, &b, NULL);
	bvhlab_trace_brute(&f->scene, r, &c);
	bool any = bvhlab_trace_stackless(&f->tree, parents, &f->scene, r, true, &d, NULL);
	return same_hit(&a, &b) && same_hit(&a, &c) && any == (a.prim != BVHLAB_NO_HIT);
}

/* The wide traversal (batches only) on n rays: closest hits as the stack
 * traversal's, any-hit rays hit exactly when those have a hit. Rays that
 * disagree. */
static int wide_disagrees(const fixture *f, const bvhlab_ray *rays, int n)
{
	bvhlab_hit *wide = calloc((size_t)n, sizeof(*wide));
	bvhlab_hit *any = calloc((size_t)n, sizeof(*any));
	bvhlab_trace_options o = {.traversal = BVHLAB_TRAVERSAL_WIDE, .threads = 2};
	bvhlab_trace_timing tm;
	int bad = 0;
	CHECK(wide && any);
	if (!wide || !any)
		goto out;
	CHECK_INT(bvhlab_trace_measure(&f->tree, &f->scene, rays, (size_t)n, &o, wide, NULL, &tm), 0);
	o.any_hit = true;
	CHECK_INT(bvhlab_trace_measure(&f->tree, &f->scene, rays, (size_t)n, &o, any, NULL, &tm), 0);
	for (int i = 0; i < n; i++) {
		bvhlab_hit h;
		bvhlab_trace_closest(&f->tree, &f->scene, &rays[i], &h, NULL);
		bad += !same_hit(&h, &wide[i]) ||
		       (any[i].prim != BVHLAB_NO_HIT) != (h.prim != BVHLAB_NO_HIT);
	}
out:
	free(wide);
	free(any);
	return bad;
}

static void check_tree(fixture *f, uint64_t seed, float size, int rays, const char *what)
{
	uint32_t *parents = NULL;
	bvhlab_ray *batch = calloc((size_t)rays, sizeof(*batch));
	int bad = 0;
	CHECK_INT(bvhlab_tree_parents(&f->tree, &parents), 0);
	if (!parents || !batch)
		goto out;
	CHECK(parents[0] == UINT32_MAX);
	for (int i = 0; i < rays; i++) {
		batch[i] = grid_ray(&seed, size);
		bad += !agree(f, parents, &batch[i]);
	}
	bad += wide_disagrees(f, batch, rays);
	if (bad)
		fprintf(stderr, "%s: %d of %d rays disagree\n", what, bad, rays);
	CHECK_INT(bad, 0);
out:
	free(batch);
	free(parents);
}

/* A grid with shared edges (rays through edges and corners tie between
 * neighbours), leaves of 1, 4 and 7 (two triangle groups of the wide
 * traversal), and the same trees with nodes and leaves shuffled: the
 * visiting order changes, the hits must not. */
static void test_grid(void)
{
	for (uint32_t leaf = 1; leaf <= 7; leaf += 3) {
		fixture f;
		bvhlab_tree shuffled;
		fixture_grid(&f, 12, 9, 0.0f);
		fixture_build(&f, leaf);
		check_tree(&f, 11 + leaf, 9, 4000, "grid");
		tree_permute(&shuffled, &f.tree, 5 + leaf, NULL);
		bvhlab_tree_finish(&f.tree);
		f.tree = shuffled;
		check_tree(&f, 17 + leaf, 9, 4000, "shuffled grid");
		fixture_free(&f);
	}
}

/* Two copies of every triangle: each ray hits both at the same t, and the
 * smaller id must win whatever order the leaves are visited in. */
static void test_ties(void)
{
	fixture f, g;
	bvhlab_tree shuffled;
	fixture_grid(&g, 4, 4, 0.1f);
	fixture_alloc(&f, 2 * g.scene.vertex_count, 2 * g.scene.triangle_count);
	for (uint32_t c = 0; c < 2; c++) {
		memcpy(f.scene.vertices + c * 3 * g.scene.vertex_count, g.scene.vertices,
		       3 * sizeof(float) * g.scene.vertex_count);
		for (uint32_t i = 0; i < 3 * g.scene.triangle_count; i++)
			f.scene.indices[c * 3 * g.scene.triangle_count + i] =
				g.scene.indices[i] + c * g.scene.vertex_count;
	}
	fixture_prepare(&f);
	fixture_build(&f, 1);
	tree_permute(&shuffled, &f.tree, 3, NULL);
	bvhlab_tree_finish(&f.tree);
	f.tree = shuffled;
	check_tree(&f, 23, 4, 2000, "coincident triangles");
	bvhlab_ray r = {{0.3f, 0.3f, 2.0f}, 0, {0, 0, -1}, INFINITY};
	bvhlab_hit h;
	bvhlab_trace_closest(&f.tree, &f.scene, &r, &h, NULL);
	CHECK(h.prim < g.scene.triangle_count); /* the first copy */
	fixture_free(&f);
	fixture_free(&g);
}

/* A chain 3000 deep: no stack at all, so no stack limit either. */
static void test_chain(void)
{
	fixture f;
	uint32_t *parents = NULL;
	fixture_chain(&f, 3000);
	CHECK_INT(bvhlab_tree_parents(&f.tree, &parents), 0);
	bvhlab_ray down = {{0, 0, 5000}, 0, {0, 0, -1}, INFINITY};
	bvhlab_ray up = {{0, 0, -5}, 0, {0, 0, 1}, INFINITY};
	bvhlab_hit h;
	bvhlab_trace_stats st = {0};
	bvhlab_trace_stackless(&f.tree, parents, &f.scene, &down, false, &h, &st);
	CHECK(h.prim == 2999 && h.t == 2001.0f);
	/* Near first: the chain's box is nearer than each level's leaf all the
	 * way down, and once the top triangle is hit every leaf below is culled
	 * on the way back up. */
	CHECK_INT(st.tris_tested, 1);
	CHECK_INT(st.nodes_visited, 3000);
	bvhlab_trace_stackless(&f.tree, parents, &f.scene, &up, false, &h, NULL);
	CHECK(h.prim == 0 && h.t == 5.0f);
	free(parents);
	/* Too deep for a wide ray's stack: the stack traversal takes over. */
	bvhlab_ray both[2] = {down, up};
	CHECK_INT(wide_disagrees(&f, both, 2), 0);
	/* Links that are not a tree: a child shared by two parents. */
	f.tree.nodes[2].first = 1;
	CHECK_INT(bvhlab_tree_parents(&f.tree, &parents), -EINVAL);
	CHECK(parents == NULL);
	bvhlab_trace_options o = {.traversal = BVHLAB_TRAVERSAL_WIDE};
	bvhlab_trace_timing tm;
	CHECK_INT(bvhlab_trace_measure(&f.tree, &f.scene, both, 2, &o, NULL, NULL, &tm), -EINVAL);
	fixture_free(&f);
}

/* One pass's counters are the per-ray traversal's; passes repeat. */
static void test_measure(void)
{
	fixture f;
	enum { N = 3000 };
	bvhlab_ray rays[N];
	bvhlab_hit hits[N], h;
	uint32_t nodes[N];
	uint64_t seed = 99;
	bvhlab_trace_stats ref = {0};
	fixture_grid(&f, 20, 20, 0.05f);
	fixture_build(&f, 2);
	for (int i = 0; i < N; i++)
		rays[i] = grid_ray(&seed, 20);
	for (int t = 0; t < BVHLAB_TRAVERSAL_DEVICE_STACK; t++) { /* the CPU's */
		bvhlab_trace_options o = {.traversal = t, .threads = 2, .min_repeats = 4, .min_ms = 20};
		bvhlab_trace_timing tm;
		CHECK_INT(bvhlab_trace_measure(&f.tree, &f.scene, rays, N, &o, hits, nodes, &tm), 0);
		CHECK(tm.repeats >= 4 && tm.stats.rays == N);
		CHECK(tm.mrays_min <= tm.mrays_median && tm.mrays_median <= tm.mrays_max);
		/* The tiles' best times are disjoint parts of every pass's CPU time,
		 * so their sum is at most the fastest pass's. */
		CHECK(tm.mrays_best >= tm.mrays_max * (1 - 1e-9));
		CHECK(tm.wall_mrays_min <= tm.wall_mrays_median && tm.mrays_median > 0);
		uint64_t node_sum = 0;
		bvhlab_trace_stats st = {0};
		for (int i = 0; i < N; i++) {
			bvhlab_trace_closest(&f.tree, &f.scene, &rays[i], &h, t == 0 ? &st : NULL);
			CHECK(same_hit(&h, &hits[i]));
			node_sum += nodes[i];
		}
		CHECK_INT(node_sum, tm.stats.nodes_visited);
		if (t == 0)
			ref = st;
		if (t != BVHLAB_TRAVERSAL_STACKLESS) { /* wide counts the binary tree too */
			CHECK_INT(tm.stats.nodes_visited, ref.nodes_visited);
			CHECK_INT(tm.stats.tris_tested, ref.tris_tested);
		}
	}
	bvhlab_trace_options bad = {.traversal = BVHLAB_TRAVERSAL_COUNT};
	bvhlab_trace_timing tm;
	CHECK_INT(bvhlab_trace_measure(&f.tree, &f.scene, rays, N, &bad, NULL, NULL, &tm), -EINVAL);
	CHECK(bvhlab_traversal_name(0) && !strcmp(bvhlab_traversal_name(1), "stackless"));
	CHECK(!strcmp(bvhlab_traversal_name(BVHLAB_TRAVERSAL_WIDE), "wide"));
	CHECK(!bvhlab_traversal_name(BVHLAB_TRAVERSAL_COUNT));
	fixture_free(&f);
}

/* A series adds up the passes of its slices; one "like" it borrows its
 * copies, times other rays and frees only its own (ASan checks). */
static void test_series(void)
{
	fixture f;
	enum { N = 2000 };
	bvhlab_ray rays[N];
	bvhlab_hit hits[N], h;
	uint64_t seed = 7;
	fixture_grid(&f, 16, 16, 0.05f);
	fixture_build(&f, 2);
	for (int i = 0; i < N; i++)
		rays[i] = grid_ray(&seed, 16);
	/* The CPU's traversals (the device ones: tests/cl/test-cl-trace.c). */
	for (int t = 0; t < BVHLAB_TRAVERSAL_DEVICE_STACK; t++) {
		/* min_repeats holds until a slice took 10 x min_ms: 200 ms, far
		 * more than 3 passes of 2000 rays take. */
		bvhlab_trace_options o = {.traversal = t, .threads = 2, .min_repeats = 3, .min_ms = 20};
		struct trace_series *s = NULL, *like = NULL;
		bvhlab_trace_timing tm;
		CHECK_INT(trace_series_create(&f.tree, &f.scene, rays, N, &o, hits, NULL, true, &s, NULL),
		          0);
		trace_series_timing(s, &tm);
		CHECK_INT(tm.repeats, 0);
		bvhlab_trace_options few = {.min_repeats = 2, .min_ms = 1e-6};
		bvhlab_trace_options many = {.min_repeats = 1000, .min_ms = 1e9};
		CHECK(!trace_series_done(s, &few));
		CHECK_INT(trace_series_slice(s, &o), 0);
		CHECK(trace_series_done(s, &few) && !trace_series_done(s, &many));
		trace_series_timing(s, &tm);
		uint32_t first = tm.repeats;
		CHECK(first >= 3);
		CHECK_INT(trace_series_slice(s, &o), 0);
		trace_series_timing(s, &tm);
		CHECK(tm.repeats >= first + 3);
		CHECK_INT(tm.stats.rays, N);
		CHECK(tm.mrays_best >= tm.mrays_max * (1 - 1e-9) && tm.mrays_median > 0);
		for (int i = 0; i < N; i++) {
			bvhlab_trace_closest(&f.tree, &f.scene, &rays[i], &h, NULL);
			CHECK(same_hit(&h, &hits[i]));
		}
		CHECK_INT(trace_series_create_like(s, rays + N / 2, N / 2, false, &like), 0);
		CHECK_INT(trace_series_slice(like, &o), 0);
		trace_series_timing(like, &tm);
		CHECK(tm.repeats >= 3 && tm.mrays_median > 0);
		CHECK_INT(tm.stats.rays, t == BVHLAB_TRAVERSAL_WIDE ? 0 : N / 2);
		trace_series_destroy(like);
		trace_series_destroy(s);
	}
	fixture_free(&f);
}

/* The kinds of rays a run may measure: primary, then from the primary
 * hits diffuse bounces, shadow rays and AO rays (the any-hit ones). */
enum { PRIMARY, DIFFUSE, SHADOW, AO, KINDS };
static const char *const kind_names[KINDS] = {"primary", "diffuse", "shadow", "ao"};

/* The secondary rays of a kind from the primary rays' hits. */
static void make_kind(const bvhlab_scene *s, int kind, const bvhlab_ray *primary,
                      const bvhlab_hit *hits, size_t n, bvhlab_ray **rays, size_t *count)
{
	float light[3];
	bvhlab_light_frame(&s->bounds, light);
	if (kind == DIFFUSE)
		CHECK_INT(bvhlab_rays_diffuse(s, primary, hits, n, 1, 5, rays, count), 0);
	else if (kind == SHADOW)
		CHECK_INT(bvhlab_rays_shadow(s, primary, hits, n, light, rays, count), 0);
	else
		CHECK_INT(bvhlab_rays_ao(s, primary, hits, n, 0.05f, 9, rays, count), 0);
}

/* Rays of a batch on which traversal t disagrees with the stack
 * traversal's closest hits ref: another closest hit (bit for bit), or
 * for the any-hit kinds a ray blocked when ref has no hit or the other way. */
static size_t kind_differs(const bvhlab_tree *tree, const bvhlab_scene *s, int t, bool any,
                           const bvhlab_ray *rays, size_t n, const bvhlab_hit *ref)
{
	bvhlab_trace_options o = {.traversal = t, .threads = 2, .any_hit = any};
	bvhlab_trace_timing tm;
	bvhlab_hit *b = calloc(n, sizeof(*b));
	size_t differ = 0;
	CHECK(b != NULL);
	if (!b)
		return n;
	CHECK_INT(bvhlab_trace_measure(tree, s, rays, n, &o, b, NULL, &tm), 0);
	for (size_t i = 0; i < n; i++)
		differ += any ? (b[i].prim == BVHLAB_NO_HIT) != (ref[i].prim == BVHLAB_NO_HIT)
		              : !same_hit(&ref[i], &b[i]);
	free(b);
	return differ;
}

/* Brute force against the stack traversal's closest hits. */
static size_t brute_differs(const bvhlab_scene *s, const bvhlab_ray *rays, size_t n,
                            const bvhlab_hit *ref)
{
	size_t differ = 0;
	for (size_t i = 0; i < n; i++) {
		bvhlab_hit h;
		bvhlab_trace_brute(s, &rays[i], &h);
		differ += !same_hit(&h, &ref[i]);
	}
	return differ;
}

/* One kind's batch on tree: stack closest hits as the reference (their
 * hits into ref), every traversal (any-hit for shadow and AO) and, when
 * brute, brute force against it. Rays blocked, for the caller's checks. */
static size_t check_kind(const bvhlab_tree *tree, const bvhlab_scene *s, int kind,
                         const bvhlab_ray *rays, size_t n, bvhlab_hit *ref, bool brute,
                         const char *what)
{
	static const int traversals[] = {BVHLAB_TRAVERSAL_STACK, BVHLAB_TRAVERSAL_STACKLESS,
	                                 BVHLAB_TRAVERSAL_WIDE, BVHLAB_TRAVERSAL_WIDE4,
	                                 BVHLAB_TRAVERSAL_WIDE8};
	bvhlab_trace_options o = {.traversal = BVHLAB_TRAVERSAL_STACK, .threads = 2};
	bvhlab_trace_timing tm;
	size_t blocked = 0;
	CHECK_INT(bvhlab_trace_measure(tree, s, rays, n, &o, ref, NULL, &tm), 0);
	for (size_t i = 0; i < n; i++)
		blocked += ref[i].prim != BVHLAB_NO_HIT;
	bool any = kind == SHADOW || kind == AO;
	for (size_t t = 0; t < sizeof(traversals) / sizeof(traversals[0]); t++) {
		if (!any && traversals[t] == BVHLAB_TRAVERSAL_STACK)
			continue;
		size_t d = kind_differs(tree, s, traversals[t], any, rays, n, ref);
		if (d)
			fprintf(stderr, "%s: %s rays: %zu of %zu differ by %s\n", what, kind_names[kind],
			        d, n, bvhlab_traversal_name(traversals[t]));
		CHECK_INT(d, 0);
	}
	if (brute)
		CHECK_INT(brute_differs(s, rays, n, ref), 0);
	return blocked;
}

/* Every kind of rays on a builder's tree of a scene, side x side primary
 * rays: each traversal as the stack one on every ray; brute force too
 * when brute. blocked[kind] gets the rays that hit something. */
static void check_scene(const bvhlab_scene *s, const char *plugin, uint32_t side, bool brute,
                        const char *what, size_t blocked[KINDS])
{
	bvhlab_plugin *p = NULL;
	bvhlab_options opts = {0};
	bvhlab_prims prims = {0};
	bvhlab_tree tree = {0};
	bvhlab_error err = {{0}};
	bvhlab_camera cam;
	bvhlab_ray *primary = NULL;
	size_t n = (size_t)side * side;
	bvhlab_hit *a = calloc(n, sizeof(*a)), *b = calloc(n, sizeof(*b));
	if (!s || !a || !b || bvhlab_prims_init(&prims, s, &err) < 0 ||
	    bvhlab_plugin_open(plugin, &p, &err) < 0 ||
	    bvhlab_options_init(&opts, bvhlab_plugin_builder(p)) < 0 ||
	    bvhlab_build(p, &opts, &prims.input, 1, &tree, &err) < 0) {
		fprintf(stderr, "%s, %s: %s\n", what, plugin, err.message);
		CHECK(0);
		goto out;
	}
	bvhlab_camera_frame(&s->bounds, &cam);
	CHECK_INT(bvhlab_rays_primary(&cam, side, side, &primary), 0);
	blocked[PRIMARY] = check_kind(&tree, s, PRIMARY, primary, n, a, brute, what);
	for (int kind = DIFFUSE; kind < KINDS; kind++) {
		bvhlab_ray *rays = NULL;
		size_t count = 0;
		make_kind(s, kind, primary, a, n, &rays, &count);
		CHECK(count <= n);
		blocked[kind] = count ? check_kind(&tree, s, kind, rays, count, b, brute, what) : 0;
		printf("%s, %s: %zu %s rays, %zu hit something\n", what, plugin, count,
		       kind_names[kind], blocked[kind]);
		free(rays);
	}
out:
	free(primary);
	free(a);
	free(b);
	bvhlab_tree_finish(&tree);
	if (opts.values)
		bvhlab_options_finish(&opts);
	bvhlab_plugin_close(p);
	bvhlab_prims_finish(&prims);
}

/* Stack, stackless and wide on two builders' trees of the shared meshes:
 * primary, diffuse, shadow and AO rays. */
static void test_shared_meshes(void)
{
	static const char *const files[] = {"stanford-bunny.obj", "ogre.obj", "nefertiti.obj",
	                                    "horse.ply", "igea.ply"};
	struct stat st;
	if (stat(BVHLAB_SHARED_SCENES, &st) != 0) {
		printf("no shared scenes at %s: that part skipped\n", BVHLAB_SHARED_SCENES);
		return;
	}
	/* Under TSan the bunny alone: the other meshes take the same threaded
	 * paths (ray batches) and cost 2.5 of its 3 minutes there. */
	size_t count = UNDER_TSAN ? 1 : sizeof(files) / sizeof(files[0]);
	for (size_t i = 0; i < count; i++) {
		bvhlab_scene *s = load_shared(files[i]);
		size_t blocked[KINDS];
		check_scene(s, "sah_seq", SCALE(160, 48), false, files[i], blocked);
		/* The default light is above and aside: a closed mesh shadows
		 * its own far side, so some shadow rays must be blocked. */
		CHECK(blocked[SHADOW] > 0);
		check_scene(s, "lbvh", SCALE(160, 48), false, files[i], blocked);
		bvhlab_scene_destroy(s);
	}
}

/* The degenerate generated scenes (needles, a sparse stadium, a soup of
 * crossing triangles, a room seen from outside), small enough for brute
 * force on every ray of every kind. */
static void test_generated(void)
{
	static const struct {
		const char *generator;
		uint32_t count;
	} scenes[] = {{"needles", 300}, {"stadium", 300}, {"soup", 400}, {"room", 0}};
	size_t any_blocked[KINDS] = {0};
	for (size_t i = 0; i < sizeof(scenes) / sizeof(scenes[0]); i++) {
		bvhlab_scene *s = NULL;
		bvhlab_error err = {{0}};
		size_t blocked[KINDS] = {0};
		bvhlab_gen_params params;
		bvhlab_gen_params_init(&params);
		params.count = scenes[i].count ? scenes[i].count : params.count;
		params.seed = 3 + i;
		if (bvhlab_scene_generate(scenes[i].generator, &params, &s, &err) < 0) {
			fprintf(stderr, "%s: %s\n", scenes[i].generator, err.message);
			CHECK(0);
			continue;
		}
		check_scene(s, "sah_seq", 40, true, scenes[i].generator, blocked);
		for (int k = 0; k < KINDS; k++)
			any_blocked[k] += blocked[k];
		bvhlab_scene_destroy(s);
	}
	/* Not vacuous: some rays of every kind hit something. */
	for (int k = 0; k < KINDS; k++)
		CHECK(any_blocked[k] > 0);
}

int main(void)
{
	test_grid();
	test_ties();
	test_chain();
	test_measure();
	test_series();
	test_generated();
	test_shared_meshes();
	return test_finish();
}
