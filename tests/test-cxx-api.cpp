// The public API from C++17: every header through <bvhlab/bvhlab.h>, and a
// program that drives a build end to end with it. It links only if the
// headers give the library's functions C linkage (extern "C"); it passes
// only if the tree sah_seq builds through them is valid, traces like brute
// force and compares equal to a second build, and the aabb.h helpers agree
// with the scene's own bounds.
#include <cerrno>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <vector>

#include <bvhlab/bvhlab.h>

namespace {

int failures = 0;

void check(bool ok, const char *what, int line)
{
	if (!ok) {
		std::fprintf(stderr, "%s:%d: CHECK failed: %s\n", __FILE__, line, what);
		failures++;
	}
}
#define CHECK(expr) check((expr), #expr, __LINE__)

int build(const bvhlab_plugin *plugin, const bvhlab_build_input *in, uint32_t threads,
          bvhlab_tree *tree)
{
	bvhlab_options opts;
	bvhlab_error err{};
	if (bvhlab_options_init(&opts, bvhlab_plugin_builder(plugin)) < 0)
		return -ENOMEM;
	int rc = bvhlab_options_parse(&opts, "method=binned", &err);
	if (rc == 0)
		rc = bvhlab_build(plugin, &opts, in, threads, tree, &err);
	if (rc < 0)
		std::fprintf(stderr, "build: %s\n", err.message);
	bvhlab_options_finish(&opts);
	return rc;
}

// Closest hits through the tree and by brute force agree, ray by ray.
void check_rays(const bvhlab_tree *tree, const bvhlab_scene *scene)
{
	bvhlab_camera cam;
	bvhlab_ray *rays = nullptr;
	bvhlab_camera_frame(&scene->bounds, &cam);
	CHECK(bvhlab_rays_primary(&cam, 16, 16, &rays) == 0);
	if (!rays)
		return;
	std::vector<bvhlab_hit> hits(256);
	bvhlab_trace_stats stats{};
	CHECK(bvhlab_trace_batch(tree, scene, rays, 256, false, 2, hits.data(), nullptr, &stats,
	                         nullptr) == 0);
	uint32_t hit_count = 0;
	for (size_t i = 0; i < 256; i++) {
		bvhlab_hit brute;
		bvhlab_trace_brute(scene, &rays[i], &brute);
		CHECK(brute.prim == hits[i].prim);
		hit_count += hits[i].prim != BVHLAB_NO_HIT;
	}
	CHECK(hit_count > 0 && stats.rays == 256 && stats.nodes_visited > 0);
	std::free(rays);
}

void check_bounds(const bvhlab_scene *scene, const bvhlab_build_input *in)
{
	bvhlab_aabb box;
	bvhlab_aabb_empty(&box);
	CHECK(bvhlab_aabb_is_empty(&box));
	for (uint32_t i = 0; i < in->prim_count; i++)
		bvhlab_aabb_grow(&box, &in->prim_bounds[i]);
	CHECK(std::memcmp(&box, &in->bounds, sizeof(box)) == 0);
	CHECK(std::memcmp(&box, &scene->bounds, sizeof(box)) == 0);
	CHECK(bvhlab_aabb_half_area(&box) > 0.0f);
}

} // namespace

int main()
{
	CHECK(std::strlen(bvhlab_version()) > 0 && bvhlab_hardware_threads() >= 1);
	bvhlab_gen_params params;
	bvhlab_gen_params_init(&params);
	params.frequency = 12;
	bvhlab_scene *scene = nullptr;
	bvhlab_error err{};
	CHECK(bvhlab_scene_generate("icosphere", &params, &scene, &err) == 0);
	bvhlab_prims prims;
	CHECK(scene && bvhlab_prims_init(&prims, scene, &err) == 0);
	bvhlab_plugin *plugin = nullptr;
	CHECK(bvhlab_plugin_open("sah_seq", &plugin, &err) == 0);
	if (!scene || !plugin) {
		std::fprintf(stderr, "%s\n", err.message);
		return 1;
	}
	check_bounds(scene, &prims.input);
	bvhlab_tree a{}, b{};
	CHECK(build(plugin, &prims.input, 1, &a) == 0 && build(plugin, &prims.input, 2, &b) == 0);
	CHECK(bvhlab_validate_tree(&a, &prims.input, false, &err) == 0);
	uint64_t mismatches = 1;
	CHECK(bvhlab_validate_rays(&a, scene, 128, 7, &mismatches, &err) == 0 && mismatches == 0);
	bvhlab_tree_stats stats;
	bvhlab_tree_stats_compute(&a, &stats);
	CHECK(stats.nodes == a.node_count && stats.sah_cost > 1.0 && std::isfinite(stats.sah_cost));
	CHECK(bvhlab_tree_compare(&a, &b, &err) == 0);
	check_rays(&a, scene);
	bvhlab_tree_finish(&a);
	bvhlab_tree_finish(&b);
	bvhlab_plugin_close(plugin);
	bvhlab_prims_finish(&prims);
	bvhlab_scene_destroy(scene);
	if (failures)
		std::fprintf(stderr, "%d check(s) failed\n", failures);
	return failures ? 1 : 0;
}
