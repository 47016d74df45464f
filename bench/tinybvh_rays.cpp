// Single-ray throughput of tinybvh's BVH8_CPU traversal (BVH8_CPU::Intersect,
// AVX2 and FMA, its own 8-wide tree built by BVH8_CPU::Build) beside the
// core's traversals, one thread, the same primary and diffuse rays, in one
// process (issue 41's second yardstick). tinybvh comes from
// ../shared/peers/tinybvh as the tinybvh plugin finds it; nothing copied.
//
//   build/bench/tinybvh-rays SCENE [--subdivide K] [--size N] [--min-ms MS]
//                            [--builder PLUGIN] [--refine PLUGIN[:KEY=VALUE,...]] [--count]
//
// Rounds and clocks: rays_bench.c.
#define TINYBVH_IMPLEMENTATION
#include <tiny_bvh.h>

#include <cstdio>
#include <vector>

#include "rays_bench.h"

namespace {

using tinybvh::bvhvec3;
using tinybvh::bvhvec4;

struct Peer {
	tinybvh::BVH8_CPU bvh;
	std::vector<bvhvec4> soup;
};

size_t pass(void *user, const bvhlab_ray *rays, size_t n)
{
	const Peer &p = *static_cast<const Peer *>(user);
	size_t hits = 0;
	for (size_t i = 0; i < n; i++) {
		const bvhlab_ray &r = rays[i];
		// tinybvh's rays start at 0: bvhlab's generated rays do too.
		tinybvh::Ray ray(bvhvec3(r.org[0], r.org[1], r.org[2]),
		                 bvhvec3(r.dir[0], r.dir[1], r.dir[2]), r.tmax);
		p.bvh.Intersect(ray);
		hits += ray.hit.t < r.tmax;
	}
	return hits;
}

} // namespace

int main(int argc, char **argv)
{
	rb_args a;
	rb_setup s;
	bvhlab_error err = {{0}};
	if (rb_parse(argc, argv, "tinybvh-rays", &a) < 0)
		return 2;
	if (rb_setup_init(&a, &s, &err) < 0) {
		std::fprintf(stderr, "tinybvh-rays: %s\n", err.message);
		rb_setup_finish(&s);
		return 1;
	}
	static Peer p;
	p.soup.resize(3 * static_cast<size_t>(s.scene->triangle_count));
	for (size_t k = 0; k < p.soup.size(); k++) {
		const float *v = &s.scene->vertices[3 * static_cast<size_t>(s.scene->indices[k])];
		p.soup[k] = bvhvec4(v[0], v[1], v[2], 0.0f);
	}
	p.bvh.Build(p.soup.data(), s.scene->triangle_count);
	rb_run(&a, &s, "tinybvh BVH8_CPU Intersect", pass, &p);
	rb_setup_finish(&s);
	return 0;
}
