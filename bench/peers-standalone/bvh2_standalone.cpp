// madmann91/bvh v2 alone: its builders timed as its example calls them,
// from its own input (a BBox and a centre per triangle, made before
// timing; the centre is the box's, as bvhlab hands the plugin, so both
// build the same tree), on one ThreadPool of `threads` workers made
// before timing (none at 1 thread: the library's single-thread path, as
// the plugin's default). The library returns a new Bvh per build; there
// is no object to reuse. Variants as the plugin's `builder` option names
// them.
#include <bvh/v2/binned_sah_builder.h>
#include <bvh/v2/bvh.h>
#include <bvh/v2/default_builder.h>
#include <bvh/v2/node.h>
#include <bvh/v2/sweep_sah_builder.h>
#include <bvh/v2/thread_pool.h>
#include <bvh/v2/tri.h>

#include <cstdio>
#include <memory>
#include <vector>

#include "standalone.h"

namespace {

using Node = bvh::v2::Node<float, 3>;
using Bvh = bvh::v2::Bvh<Node>;
using Vec3 = bvh::v2::Vec<float, 3>;
using BBox = bvh::v2::BBox<float, 3>;
using Tri = bvh::v2::Tri<float, 3>;
using Default = bvh::v2::DefaultBuilder<Node>;

struct Job {
	std::vector<BBox> boxes;
	std::vector<Vec3> centers;
	std::unique_ptr<bvh::v2::ThreadPool> pool;
	Default::Config config;
	int variant; // Variant
	Bvh bvh;
};

void inputs(const bvhlab_scene *s, Job &j)
{
	auto vertex = [s](uint32_t k) {
		const float *p = &s->vertices[3 * static_cast<size_t>(s->indices[k])];
		return Vec3(p[0], p[1], p[2]);
	};
	for (uint32_t t = 0; t < s->triangle_count; t++) {
		BBox b = Tri(vertex(3 * t), vertex(3 * t + 1), vertex(3 * t + 2)).get_bbox();
		j.boxes.push_back(b);
		j.centers.push_back(b.get_center());
	}
}

// By index in the program's list of variants (main).
enum Variant { low, medium, high, sweep, binned };

int build(void *user)
{
	Job &j = *static_cast<Job *>(user);
	if (j.variant == sweep)
		j.bvh = bvh::v2::SweepSahBuilder<Node>::build(j.boxes, j.centers, j.config);
	else if (j.variant == binned)
		j.bvh = bvh::v2::BinnedSahBuilder<Node>::build(j.boxes, j.centers, j.config);
	else if (j.pool)
		j.bvh = Default::build(*j.pool, j.boxes, j.centers, j.config);
	else
		j.bvh = Default::build(j.boxes, j.centers, j.config);
	return 0;
}

} // namespace

int main(int argc, char **argv)
{
	sa_args a;
	bvhlab_scene *scene;
	if (int rc = sa_start(argc, argv, "low|medium|high|sweep|binned", "medium", &a, &scene))
		return rc;
	if (a.input_each >= 0) {
		std::fprintf(stderr, "bvh2-standalone: --input is tinybvh-standalone's only\n");
		bvhlab_scene_destroy(scene);
		return 2;
	}
	Job job;
	inputs(scene, job);
	bvhlab_scene_destroy(scene);
	job.variant = a.which;
	job.config.quality = a.which == low    ? Default::Quality::Low
	                     : a.which == high ? Default::Quality::High
	                                       : Default::Quality::Medium;
	if (a.threads > 1 && a.which != sweep && a.which != binned)
		job.pool = std::make_unique<bvh::v2::ThreadPool>(a.threads);
	return sa_time("bvh2", &a, nullptr, build, &job) < 0 ? 1 : 0;
}
