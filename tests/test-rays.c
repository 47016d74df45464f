/*
 * Rays and images: every builder on the search path (fake and test
 * plugins aside) traced against brute force on primary and diffuse rays of
 * the core's generator, any-hit against closest-hit, reproducible ray
 * generation, and images that read back at their size and are not blank.
 */
#include <math.h>
#include <stdlib.h>
#include <string.h>
#include <unistd.h>

#include <bvhlab/bvhlab.h>

#include "output/image.h"
#include "testutil.h"

#define W 48
#define H 32

/* Embree runs on TBB, which is not sanitizer-instrumented (see test-embree's
 * own suite); in sanitizer builds it is left to test-embree. */
#if defined(__SANITIZE_ADDRESS__) || defined(__SANITIZE_THREAD__)
#define SKIP_EMBREE 1
#else
#define SKIP_EMBREE 0
#endif

static bool skipped(const char *name)
{
	return !strncmp(name, "fake_", 5) || !strcmp(name, "pin_probe") ||
	       (SKIP_EMBREE && !strcmp(name, "embree"));
}

/* Closest hits equal brute force; any-hit agrees on hit or miss. */
static void compare(const char *name, const bvhlab_tree *tree, const bvhlab_scene *scene,
                    const bvhlab_ray *rays, size_t n)
{
	size_t bad = 0, any_bad = 0;
	for (size_t i = 0; i < n; i++) {
		bvhlab_hit a, b, c;
		bvhlab_trace_closest(tree, scene, &rays[i], &a, NULL);
		bvhlab_trace_brute(scene, &rays[i], &b);
		bool hit = bvhlab_trace_any(tree, scene, &rays[i], &c, NULL);
		if ((a.prim == BVHLAB_NO_HIT) != (b.prim == BVHLAB_NO_HIT) ||
		    (a.prim != BVHLAB_NO_HIT && fabsf(a.t - b.t) > 1e-4f * fabsf(b.t)))
			bad++;
		any_bad += hit != (b.prim != BVHLAB_NO_HIT);
	}
	if (bad || any_bad)
		fprintf(stderr, "%s: %zu closest and %zu any-hit mismatches of %zu rays\n", name, bad,
		        any_bad, n);
	CHECK_INT(bad, 0);
	CHECK_INT(any_bad, 0);
}

static void check_plugin(const char *name, const bvhlab_scene *scene, const bvhlab_prims *prims)
{
	bvhlab_plugin *p = NULL;
	bvhlab_options opts = {0};
	bvhlab_tree tree = {0};
	bvhlab_error err = {{0}};
	bvhlab_camera cam;
	bvhlab_ray *primary = NULL, *diffuse = NULL;
	size_t nd = 0;
	if (bvhlab_plugin_open(name, &p, &err) == 0 && !bvhlab_plugin_builder(p)->build)
		goto out; /* refines only: test-reinsert traces its trees */
	if (!p || bvhlab_options_init(&opts, bvhlab_plugin_builder(p)) < 0 ||
	    bvhlab_build(p, &opts, &prims->input, 2, &tree, &err) < 0) {
		fprintf(stderr, "%s: %s\n", name, err.message);
		CHECK(0);
		goto out;
	}
	bvhlab_camera_frame(&scene->bounds, &cam);
	CHECK_INT(bvhlab_rays_primary(&cam, W, H, &primary), 0);
	bvhlab_hit hits[W * H];
	bvhlab_trace_stats st = {0};
	CHECK_INT(bvhlab_trace_batch(&tree, scene, primary, W * H, false, 2, hits, NULL, &st, NULL), 0);
	CHECK_INT(st.rays, W * H);
	CHECK_INT(bvhlab_rays_diffuse(scene, primary, hits, W * H, 2, 7, &diffuse, &nd), 0);
	CHECK(nd > 0);
	compare(name, &tree, scene, primary, W * H);
	compare(name, &tree, scene, diffuse, nd);
	printf("ok: %s (%d primary, %zu diffuse rays)\n", name, W * H, nd);
out:
	free(primary);
	free(diffuse);
	bvhlab_tree_finish(&tree);
	if (opts.values)
		bvhlab_options_finish(&opts);
	bvhlab_plugin_close(p);
}

static void test_every_builder(void)
{
	bvhlab_gen_params gp = {.frequency = 12, .count = 3000, .size = 24, .seed = 3};
	const char *gens[] = {"icosphere", "soup", "terrain"};
	char **names = NULL;
	bvhlab_error err = {{0}};
	int tested = 0;
	CHECK_INT(bvhlab_plugin_names(&names, &err), 0);
	for (int g = 0; g < 3; g++) {
		bvhlab_scene *scene = NULL;
		bvhlab_prims prims = {0};
		CHECK_INT(bvhlab_scene_generate(gens[g], &gp, &scene, &err), 0);
		CHECK_INT(bvhlab_prims_init(&prims, scene, &err), 0);
		for (char **n = names; n && *n; n++)
			if (!skipped(*n) && (check_plugin(*n, scene, &prims), g == 0))
				tested++;
		bvhlab_prims_finish(&prims);
		bvhlab_scene_destroy(scene);
	}
	CHECK(tested >= 1); /* sah_seq at least */
	bvhlab_plugin_names_free(names);
}

static void test_reproducible(void)
{
	bvhlab_gen_params gp = {.frequency = 8};
	bvhlab_scene *scene = NULL;
	bvhlab_error err = {{0}};
	bvhlab_camera cam;
	bvhlab_ray *p = NULL, *a = NULL, *b = NULL, *c = NULL;
	size_t na, nb, nc;
	CHECK_INT(bvhlab_scene_generate("icosphere", &gp, &scene, &err), 0);
	bvhlab_camera_frame(&scene->bounds, &cam);
	CHECK_INT(bvhlab_rays_primary(&cam, W, H, &p), 0);
	bvhlab_hit hits[W * H];
	for (int i = 0; i < W * H; i++)
		bvhlab_trace_brute(scene, &p[i], &hits[i]);
	CHECK_INT(bvhlab_rays_diffuse(scene, p, hits, W * H, 1, 42, &a, &na), 0);
	CHECK_INT(bvhlab_rays_diffuse(scene, p, hits, W * H, 1, 42, &b, &nb), 0);
	CHECK_INT(bvhlab_rays_diffuse(scene, p, hits, W * H, 1, 43, &c, &nc), 0);
	CHECK(na > 0 && na == nb && na == nc);
	CHECK(na == nb && !memcmp(a, b, na * sizeof(*a)));
	CHECK(na == nc && memcmp(a, c, na * sizeof(*a)) != 0);
	/* Bounces leave the surface: none starts inside the sphere's hull. */
	for (size_t i = 0; i < na; i++) {
		bvhlab_hit h;
		bvhlab_trace_brute(scene, &a[i], &h);
		CHECK(h.prim == BVHLAB_NO_HIT || h.t > 1e-4f);
	}
	free(p);
	free(a);
	free(b);
	free(c);
	bvhlab_scene_destroy(scene);
}

static void test_images(void)
{
	char path[] = "/tmp/bvhlab-img-XXXXXX.png";
	int fd = mkstemps(path, 4);
	uint8_t rgb[W * H * 3], *back = NULL;
	int w = 0, h = 0;
	bvhlab_error err = {{0}};
	CHECK(fd >= 0);
	close(fd);
	for (int i = 0; i < W * H; i++)
		image_heat_color((float)(i % W) / (W - 1), rgb + 3 * i);
	CHECK_INT(image_write_rgb8(path, W, H, rgb, &err), 0);
	CHECK_INT(image_read_rgb8(path, &w, &h, &back, &err), 0);
	CHECK_INT(w, W);
	CHECK_INT(h, H);
	CHECK(back && !memcmp(back, rgb, sizeof(rgb)));
	free(back);
	unlink(path);
	CHECK(image_write_rgb8("/nonexistent/x.png", W, H, rgb, &err) < 0);
	CHECK_CONTAINS(err.message, "/nonexistent/x.png");
	char name[64];
	image_sanitise("a b/../c<>.", name, sizeof(name));
	CHECK(!strcmp(name, "a_b_.._c__."));
}

int main(void)
{
	test_reproducible();
	test_images();
	test_every_builder();
	return test_finish();
}
