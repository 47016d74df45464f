// tinybvh alone: its builders timed as its own speedtest times them, from
// its own input (a soup of 16-byte vertices, made before timing), into
// one BVH object reused by every build (tinybvh keeps its node array when
// it is large enough). Threads as the plugin holds them (tinybvh_cpus.h):
// at 1 thread its threaded path is off, else the calling thread's CPU
// affinity bounds the threads it spawns. Variants as the plugin's
// `builder` option names them.
#define TINYBVH_IMPLEMENTATION
#include <tiny_bvh.h>

#include <cstdio>
#include <vector>

#include "standalone.h"
#include "tinybvh_cpus.h"

namespace {

using tinybvh::BVH;
using tinybvh::bvhvec4;

struct Job {
	BVH bvh;
	std::vector<bvhvec4> soup;
	const bvhlab_scene *scene; // kept for --input each
	int variant;               // Variant
};

void soup_of(const bvhlab_scene *s, std::vector<bvhvec4> &v)
{
	v.resize(3 * static_cast<size_t>(s->triangle_count));
	for (size_t k = 0; k < v.size(); k++) {
		const float *p = &s->vertices[3 * static_cast<size_t>(s->indices[k])];
		v[k] = bvhvec4(p[0], p[1], p[2], 0.0f);
	}
}

// --input each: the soup rewritten before every build, untimed.
int refill(void *user)
{
	Job &j = *static_cast<Job *>(user);
	soup_of(j.scene, j.soup);
	return 0;
}

// By index in the program's list of variants (main).
enum Variant { quick, binned, avx, sweep, hq };

int build(void *user)
{
	Job &j = *static_cast<Job *>(user);
	const bvhvec4 *v = j.soup.data();
	uint32_t n = static_cast<uint32_t>(j.soup.size() / 3);
	switch (j.variant) {
	case quick: j.bvh.BuildQuick(v, n); break;
	case binned: j.bvh.Build(v, n); break;
	case avx: j.bvh.BuildAVX(v, n); break;
	case sweep: j.bvh.useFullSweep = true, j.bvh.Build(v, n); break;
	default: j.bvh.BuildHQ(v, n); break;
	}
	return 0;
}

} // namespace

int main(int argc, char **argv)
{
	sa_args a;
	bvhlab_scene *scene;
	if (int rc = sa_start(argc, argv, "quick|binned|avx|sweep|hq", "avx", &a, &scene))
		return rc;
	Job job;
	soup_of(scene, job.soup);
	job.scene = scene;
	job.variant = a.which;
	job.bvh.threadedBuild = a.threads > 1;
	tbvh::CpuLimit cpus;
	if (a.threads > 1 && cpus.limit(a.threads) < 0) {
		std::perror("sched_setaffinity");
		return 1;
	}
	int rc = sa_time("tinybvh", &a, a.input_each == 1 ? refill : nullptr, build, &job);
	bvhlab_scene_destroy(scene);
	return rc < 0 ? 1 : 0;
}
