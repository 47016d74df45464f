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

#include <cstring>
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
	const char *variant;
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

int build(void *user)
{
	Job &j = *static_cast<Job *>(user);
	if (std::strcmp(j.variant, "sweep") == 0)
		j.bvh = bvh::v2::SweepSahBuilder<Node>::build(j.boxes, j.centers, j.config);
	else if (std::strcmp(j.variant, "binned") == 0)
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
	if (sa_parse(argc, argv, "low|medium|high|sweep|binned", "medium", &a) < 0)
		return 2;
	bvhlab_scene *scene = sa_load(&a);
	if (!scene)
		return 1;
	Job job;
	inputs(scene, job);
	bvhlab_scene_destroy(scene);
	job.variant = a.variant;
	job.config.quality = std::strcmp(a.variant, "low") == 0    ? Default::Quality::Low
	                     : std::strcmp(a.variant, "high") == 0 ? Default::Quality::High
	                                                           : Default::Quality::Medium;
	bool top_down = std::strcmp(a.variant, "sweep") == 0 || std::strcmp(a.variant, "binned") == 0;
	if (a.threads > 1 && !top_down)
		job.pool = std::make_unique<bvh::v2::ThreadPool>(a.threads);
	return sa_time("bvh2", &a, nullptr, build, &job) < 0 ? 1 : 0;
}
