// tinybvh: jbikker/tinybvh's builders as a peer in the same harness, so
// bvhlab's builders are measured against the most active BVH library of
// the day with the same timer, input and validation.
//
// builder: quick (BuildQuick: midpoint of the longest axis, one thread),
// binned (Build: 8-bin SAH), avx (BuildAVX: the same tree, AVX binning),
// sweep (Build with useFullSweep: full-sweep SAH), hq (BuildHQ: SBVH with
// spatial splits; a leaf's box may hold only the clipped part of a
// triangle, so the descriptor declares spatial splits, as embree's does;
// the other builders reference each triangle once, which the tests check).
// optimize: iterations of tinybvh's Optimize (reinsertion) after it.
// width 4 or 8: the library's own BVH4_CPU or BVH8_CPU, built by its Build
// (its default binary builder, BuildAVX, collapsed by its MBVH ConvertFrom,
// leaves combined and split to at most 4 triangles), written out from the
// MBVH<4>/<8> that layout traces: the tree tinybvh's wide traversal walks,
// judged as a bvhlab wide tree (builder and optimize are width 2's).
//
// Threads: see tinybvh_cpus.h (the library spawns a fixed tree of
// std::threads; the calling thread's CPU affinity holds them to the run's
// thread count; at one thread the threaded path is off).
//
// tinybvh takes 16-byte vertices; the plugin copies the indexed mesh into
// a triangle soup of them first (phase "input"), and the library's tree
// into the standard layout last (phase "convert"). Both are inside
// build_ms, as everything in the call is for every plugin; comparisons of
// the library's own time take both out. One BVH object serves every build
// of a run (Kept, below).
//
// Over boxes (BVHLAB_PRIM_BOXES: a two-level scene's top, over the
// instances' world boxes) the build is tinybvh's TLAS build,
// Build(BLASInstance*, ...), over one BLASInstance per box: its binned SAH
// (builder binned; the others need triangles), width 2, no Optimize.
#define TINYBVH_IMPLEMENTATION
#include <tiny_bvh.h>

#include <atomic>
#include <cerrno>
#include <chrono>
#include <cstring>
#include <exception>
#include <memory>
#include <mutex>
#include <new>
#include <system_error>
#include <vector>

#include <bvhlab/builder.hpp>

#include "peer_tree.hpp"
#include "plugin_options.h"
#include "tinybvh_cpus.h"

namespace {

using tinybvh::BVH;
using tinybvh::bvhvec4;
using clk = std::chrono::steady_clock;

// builder's choices, by index.
enum Method { quick, binned, avx, sweep, hq };

struct Settings {
	int method = avx; // Method
	int64_t optimize = 0, hq_bins = HQBVHBINS;
	bool extreme = false;
	double c_trav = 1, c_int = 1;
	int64_t width = 2;
};

// The options and where they go (plugin_options.h): the host has checked them.
const plugin_option options[] = {
	PLUGIN_OPTION(Settings, method, CHOICE,
	              bvhlab::string_option("builder",
	                                    "quick (BuildQuick, 1 thread), binned (Build), avx "
	                                    "(BuildAVX), sweep (full-sweep SAH), hq (BuildHQ, "
	                                    "spatial splits); threads: the caller's CPU affinity "
	                                    "is narrowed to the run's count around the call (the "
	                                    "threads tinybvh spawns inherit it), and at 1 thread "
	                                    "its threaded path is off",
	                                    "avx", "quick|binned|avx|sweep|hq")),
	PLUGIN_OPTION(Settings, optimize, I64,
	              bvhlab::int_option("optimize",
	                                 "iterations of tinybvh's Optimize (reinsertion, one "
	                                 "thread) after the build; 0: off",
	                                 0, 0, 1000)),
	PLUGIN_OPTION(Settings, extreme, BOOL,
	              bvhlab::bool_option("optimize_extreme",
	                                  "Optimize's 'extreme' mode (more candidates)", false)),
	PLUGIN_OPTION(Settings, c_trav, DOUBLE,
	              bvhlab::float_option("c_trav", "SAH cost of a traversal step (tinybvh's "
	                                   "c_trav)", 1.0, 1e-6, 1e6)),
	PLUGIN_OPTION(Settings, c_int, DOUBLE,
	              bvhlab::float_option("c_int", "SAH cost of a triangle test (tinybvh's c_int)",
	                                   1.0, 1e-6, 1e6)),
	PLUGIN_OPTION(Settings, hq_bins, I64,
	              bvhlab::int_option("hq_bins", "hq: bins per axis for object and spatial "
	                                 "splits", HQBVHBINS, 2, MAXHQBINS)),
	PLUGIN_OPTION(Settings, width, I64,
	              bvhlab_option_decl{"width", BVHLAB_OPTION_INT,
	                                 "2, or 4 and 8: the library's BVH4_CPU and BVH8_CPU (its "
	                                 "Build, its collapse and leaves of at most 4), written as "
	                                 "a bvhlab wide tree; builder and optimize are width 2's",
	                                 false, 2, 0.0, nullptr, 2.0, 8.0, "2|4|8"}),
};

// Optimize works on the binary tree only; the wide layouts build their own.
int check_width(const bvhlab_host *host, bvhlab_build_ctx *ctx, void *out)
{
	const Settings *s = static_cast<const Settings *>(out);
	if (s->width == 2 || (s->optimize == 0 && s->method == avx))
		return 0;
	host->set_error(ctx, "width %lld is the library's BVH%lld_CPU, built by its own Build: "
	                "leave builder (avx) and optimize (0) at their defaults",
	                static_cast<long long>(s->width), static_cast<long long>(s->width));
	return -EINVAL;
}
PLUGIN_DECLS(options, Settings, check_width)

// What a run keeps between its builds, as the harness keeps a builder's
// output ("host-kept output"): the BVH object, whose node and index arrays
// tinybvh reuses (as its own speedtest builds into one object), and the
// vertex soup. The object is kept only for the same builder over as many
// triangles, without Optimize: tinybvh sizes its reuse by the node array
// alone, which another builder's (hq's 3 nodes per triangle) or a larger
// scene's overflows, and Optimize may leave it not rebuildable (a fatal
// error). The harness runs one run per process, so a run's repeats reuse
// it; the lock serialises builds in one process (the tests'), as embree's.
struct Kept {
	std::mutex lock;
	std::unique_ptr<BVH> bvh;
	int method = -1; // what bvh was last built with
	uint32_t prims = 0;
	bool optimized = false;
	std::vector<bvhvec4> soup;
	// a two-level top's: its own object (a TLAS is a BVH over no
	// vertices) and its instance records, reused as a TLAS rebuilt per
	// frame reuses them
	std::unique_ptr<BVH> tlas;
	std::vector<tinybvh::BLASInstance> instances;
};
Kept kept;

// The kept object for this build, or a new one (see Kept).
BVH &object_for(const Settings &s, uint32_t prims)
{
	if (!kept.bvh || kept.method != s.method || kept.prims != prims || kept.optimized)
		kept.bvh = std::make_unique<BVH>();
	kept.method = s.method;
	kept.prims = prims;
	kept.optimized = s.optimize > 0;
	return *kept.bvh;
}

// Three 16-byte vertices per triangle, in primitive order, into `v`.
void soup(const bvhlab_build_input *in, std::vector<bvhvec4> &v)
{
	v.resize(3 * static_cast<size_t>(in->prim_count));
	for (size_t t = 0; t < in->prim_count; t++)
		for (size_t k = 0; k < 3; k++) {
			const float *p = &in->vertices[3 * static_cast<size_t>(in->indices[3 * t + k])];
			v[3 * t + k] = bvhvec4(p[0], p[1], p[2], 0.0f);
		}
}

// tinybvh 1.6.7's Build, BuildAVX and full sweep allocate their node
// counter (BVH::atomicNewNodePtr, private) on 50,000 triangles or more even
// with threadedBuild off, and free it only when it is on: 4 bytes leak per
// one-thread build. An explicit instantiation may name a private member
// ([temp.spec]), which is how the plugin reaches it to free it.
struct CounterTag {
	using type = std::atomic<uint32_t> *BVH::*;
#pragma GCC diagnostic push
#pragma GCC diagnostic ignored "-Wnon-template-friend"
	friend type counter_member(CounterTag);
#pragma GCC diagnostic pop
};
template <typename Tag, typename Tag::type M> struct Reach {
	friend typename Tag::type counter_member(Tag) { return M; }
};
template struct Reach<CounterTag, &BVH::atomicNewNodePtr>;

// The node counter a one-thread build left (see CounterTag).
void free_counter(BVH &bvh)
{
	if (!bvh.threadedBuild) {
		std::atomic<uint32_t> *&counter = bvh.*counter_member(CounterTag{});
		delete counter;
		counter = nullptr;
	}
}

// The library's call for `s`, on the calling thread (which may spawn more).
void run_builder(BVH &bvh, const Settings &s, const bvhvec4 *v, uint32_t n)
{
	switch (s.method) {
	case quick: bvh.BuildQuick(v, n); break;
	case binned: bvh.Build(v, n); break;
	case avx: bvh.BuildAVX(v, n); break;
	case sweep: bvh.useFullSweep = true; bvh.Build(v, n); break;
	case hq: bvh.BuildHQ(v, n); break;
	}
	free_counter(bvh);
}

// BVH::Optimize does exactly this, but with a BVH_Verbose it never frees
// (tinybvh 1.6.7 leaks one per call); this one lives on the stack. Optimize
// visits nodes by index, and a threaded build numbers them in the order
// its threads happened to take them: Compact renumbers them depth first
// first, so the same tree gives the same result at any thread count.
void optimize(BVH &bvh, const Settings &s)
{
	bvh.Compact();
	tinybvh::BVH_Verbose verbose;
	verbose.ConvertFrom(bvh);
	verbose.Optimize(static_cast<uint32_t>(s.optimize), s.extreme, false);
	bvh.ConvertFrom(verbose);
}

// tinybvh's tree as peer::write_tree reads it.
struct View {
	const BVH &b;
	uint64_t max_nodes() const { return b.usedNodes; }
	uint64_t max_refs() const { return b.idxCount; }
	uint32_t root() const { return 0; }
	bool leaf(uint32_t n) const { return b.bvhNode[n].isLeaf(); }
	uint32_t child(uint32_t n, int k) const { return b.bvhNode[n].leftFirst + k; }
	uint32_t prim_count(uint32_t n) const { return b.bvhNode[n].triCount; }
	uint32_t prim(uint32_t n, uint32_t k) const { return b.primIdx[b.bvhNode[n].leftFirst + k]; }
	void box(uint32_t n, float lo[3], float hi[3]) const
	{
		const BVH::BVHNode &x = b.bvhNode[n];
		lo[0] = x.aabbMin.x, lo[1] = x.aabbMin.y, lo[2] = x.aabbMin.z;
		hi[0] = x.aabbMax.x, hi[1] = x.aabbMax.y, hi[2] = x.aabbMax.z;
	}
};

// MBVH<M>'s tree (what BVH4_CPU and BVH8_CPU hold and trace) as
// peer::write_tree reads it; a root leaf sits under a one-child root.
template <int M> struct WideView {
	const tinybvh::MBVH<M> &m;
	uint64_t max_nodes() const { return m.usedNodes; }
	uint64_t max_refs() const { return m.bvh.idxCount; }
	uint32_t root() const { return m.mbvhNode[0].childCount == 1 ? m.mbvhNode[0].child[0] : 0; }
	bool leaf(uint32_t n) const { return m.mbvhNode[n].isLeaf(); }
	uint32_t child_count(uint32_t n) const { return m.mbvhNode[n].childCount; }
	uint32_t child(uint32_t n, int k) const { return m.mbvhNode[n].child[k]; }
	uint32_t prim_count(uint32_t n) const { return m.mbvhNode[n].triCount; }
	uint32_t prim(uint32_t n, uint32_t k) const
	{
		return m.bvh.primIdx[m.mbvhNode[n].firstTri + k];
	}
	void box(uint32_t n, float lo[3], float hi[3]) const
	{
		const auto &x = m.mbvhNode[n];
		lo[0] = x.aabbMin.x, lo[1] = x.aabbMin.y, lo[2] = x.aabbMin.z;
		hi[0] = x.aabbMax.x, hi[1] = x.aabbMax.y, hi[2] = x.aabbMax.z;
	}
};

// The MBVH each CPU layout keeps and traces.
tinybvh::MBVH<4> &wide_tree(tinybvh::BVH4_CPU &l) { return l.bvh4; }
tinybvh::MBVH<8> &wide_tree(tinybvh::BVH8_CPU &l) { return l.bvh8; }

// The library's M-wide CPU layout over the soup, converted: a fresh object
// per build (its Build allocates as it goes), its binary build threaded as
// a width-2 build is (the caller narrowed the CPUs).
template <class Layout, int M>
int build_wide(const bvhlab_host *host, bvhlab_build_ctx *ctx, const bvhlab_build_input *in,
               bvhlab_build_output *out)
{
	auto layout = std::make_unique<Layout>();
	wide_tree(*layout).bvh.threadedBuild = in->threads > 1;
	layout->Build(kept.soup.data(), in->prim_count);
	int rc = peer::convert(host, ctx, WideView<M>{wide_tree(*layout)}, out);
	if (rc == 0)
		out->width = M;
	return rc;
}

// The settings into the kept object: every field a build reads, since the
// previous build may have set them otherwise.
void configure(BVH &bvh, const Settings &s, uint32_t threads)
{
	bvh.c_trav = static_cast<float>(s.c_trav);
	bvh.c_int = static_cast<float>(s.c_int);
	bvh.hqbvhbins = static_cast<uint32_t>(s.hq_bins);
	bvh.threadedBuild = threads > 1;
	bvh.useFullSweep = false;
}

// The calling thread's CPUs narrowed to `threads` for the call (see
// tinybvh_cpus.h); none at 1 thread, where no thread is started.
int narrow(const bvhlab_host *host, bvhlab_build_ctx *ctx, tbvh::CpuLimit &cpus,
           uint32_t threads)
{
	int rc = threads > 1 ? cpus.limit(threads) : 0;
	if (rc < 0)
		host->set_error(ctx, "cannot narrow the CPU affinity to %u CPUs (%s)", threads,
		                std::strerror(-rc));
	return rc;
}

// A two-level top: the boxes as BLASInstance records whose world boxes
// are already set (Build's null BLAS list: "updated elsewhere", the
// library's own path for a TLAS over boxes it did not compute), built by
// the TLAS build. The caller holds the lock and has narrowed the CPUs.
int build_top(const bvhlab_host *host, bvhlab_build_ctx *ctx, const bvhlab_build_input *in,
              const Settings &s, bvhlab_build_output *out)
{
	if (s.method != binned || s.width != 2 || s.optimize > 0) {
		host->set_error(ctx, "over boxes (a two-level top) tinybvh builds its TLAS, "
		                "Build(BLASInstance*), a binned SAH: set builder 'binned' and "
		                "leave width (2) and optimize (0)");
		return -EINVAL;
	}
	auto t0 = clk::now();
	kept.instances.resize(in->prim_count);
	for (uint32_t i = 0; i < in->prim_count; i++) {
		const bvhlab_aabb &b = in->prim_bounds[i];
		kept.instances[i].aabbMin = tinybvh::bvhvec3(b.lo[0], b.lo[1], b.lo[2]);
		kept.instances[i].aabbMax = tinybvh::bvhvec3(b.hi[0], b.hi[1], b.hi[2]);
	}
	peer::report_phase(host, ctx, "input", peer::ms_since(t0));
	if (!kept.tlas)
		kept.tlas = std::make_unique<BVH>();
	BVH &tlas = *kept.tlas;
	configure(tlas, s, in->threads);
	tlas.Build(kept.instances.data(), in->prim_count, nullptr, 0);
	free_counter(tlas);
	return peer::convert(host, ctx, View{tlas}, out);
}

int build_tree(const bvhlab_host *host, bvhlab_build_ctx *ctx, const bvhlab_build_input *in,
               const Settings &s, bvhlab_build_output *out)
{
	std::lock_guard<std::mutex> hold(kept.lock);
	if (in->prim_kind == BVHLAB_PRIM_BOXES) {
		tbvh::CpuLimit cpus;
		int rc = narrow(host, ctx, cpus, in->threads);
		return rc < 0 ? rc : build_top(host, ctx, in, s, out);
	}
	auto t0 = clk::now();
	soup(in, kept.soup);
	peer::report_phase(host, ctx, "input", peer::ms_since(t0));
	BVH *bvh = nullptr;
	{
		tbvh::CpuLimit cpus;
		int rc = narrow(host, ctx, cpus, in->threads);
		if (rc < 0)
			return rc;
		if (s.width != 2)
			return s.width == 4 ? build_wide<tinybvh::BVH4_CPU, 4>(host, ctx, in, out)
			                    : build_wide<tinybvh::BVH8_CPU, 8>(host, ctx, in, out);
		bvh = &object_for(s, in->prim_count);
		configure(*bvh, s, in->threads);
		run_builder(*bvh, s, kept.soup.data(), in->prim_count);
	}
	if (s.optimize > 0)
		optimize(*bvh, s);
	return peer::convert(host, ctx, View{*bvh}, out);
}

// tinybvh's counts are 32-bit and hq keeps 3 nodes per triangle.
PEER_BUILD_FN(UINT32_MAX / 8)

// Any exception out of build() becomes the run's error (bvhlab::guarded_build).
// Peak bytes per triangle (issue 44): measured 160-254, hq on a soup the most.
const bvhlab_builder descriptor = bvhlab::with_peak_bytes(bvhlab::with_fill_options(
	bvhlab::make_builder("tinybvh",
	                     "jbikker/tinybvh 1.6.7: quick, binned, avx, sweep, hq (spatial "
	                     "splits), optional Optimize; over boxes its TLAS build (binned); "
	                     "thread count held by CPU affinity (see the builder option)",
	                     BVHLAB_BUILDER_PARALLEL | BVHLAB_BUILDER_DETERMINISTIC |
	                             BVHLAB_BUILDER_SPATIAL_SPLITS | BVHLAB_BUILDER_BOXES,
	                     plugin_decls, bvhlab::guarded_build<build>),
	plugin_fill_options, sizeof(Settings)), 288);

} // namespace

PLUGIN_EXPORT(descriptor)
