// bvh2: madmann91/bvh v2's builders as a peer in the same harness.
//
// builder: low, medium, high are its DefaultBuilder at that quality. With
// a thread pool (2 threads or more) that is its mini-tree builder (pruning
// off for low, on for medium and high; high then runs its reinsertion
// optimizer); at 1 thread it is the library's single-thread path, a
// different algorithm: binned SAH for low, sweep SAH for medium, sweep SAH
// and reinsertion for high (one_thread: pool runs the mini-tree builder on
// a pool of one thread instead). sweep and binned are its top-down SAH
// builders, single-threaded in the library whatever the thread count.
// reinsertion: its ReinsertionOptimizer after the build (on the pool).
//
// Threads: the pool (bvh::v2::ThreadPool) has exactly input->threads
// workers; the calling thread only waits while they run, so at most
// input->threads threads work at a time. At 1 thread no pool is made.
// The pool is kept between builds (Kept, below), as the library's own
// benchmark makes one pool for all its builds.
//
// The inputs are the host's boxes and centroids, copied into the
// library's types (phase "input"); its tree is turned into the standard
// layout last (phase "convert"); both are inside build_ms.
#include <bvh/v2/binned_sah_builder.h>
#include <bvh/v2/bvh.h>
#include <bvh/v2/default_builder.h>
#include <bvh/v2/node.h>
#include <bvh/v2/reinsertion_optimizer.h>
#include <bvh/v2/sweep_sah_builder.h>
#include <bvh/v2/thread_pool.h>

#include <cerrno>
#include <chrono>
#include <exception>
#include <memory>
#include <mutex>
#include <new>
#include <system_error>
#include <vector>

#include <sched.h>

#include <bvhlab/builder.hpp>

#include "peer_tree.hpp"
#include "plugin_options.h"

namespace {

using Node = bvh::v2::Node<float, 3>;
using Bvh = bvh::v2::Bvh<Node>;
using Vec3 = bvh::v2::Vec<float, 3>;
using BBox = bvh::v2::BBox<float, 3>;
using Default = bvh::v2::DefaultBuilder<Node>;
using clk = std::chrono::steady_clock;

// The node's 4-bit primitive count caps a leaf at 15.
constexpr int64_t max_leaf_cap = Node::Index::max_prim_count;

// builder's and one_thread's choices, by index.
enum Builder { low, medium, high, sweep, binned };
enum OneThread { sequential, pool_of_one };

// What each builder choice runs (the option's help).
constexpr const char *builder_help =
	"low, medium, high (DefaultBuilder: mini-tree on a pool of the run's threads; at 1 "
	"thread the library's single-thread path), sweep, binned (top-down SAH, 1 thread)";

struct Settings {
	int builder = medium; // Builder
	bool reinsertion = false;
	int one_thread = sequential; // OneThread
	int64_t min_leaf = 1, max_leaf = 8;
	double cost_ratio = 1;
};

// The options and where they go (plugin_options.h): the host has checked them.
const plugin_option options[] = {
	PLUGIN_OPTION(Settings, builder, CHOICE,
	              bvhlab::string_option("builder", builder_help, "medium",
	                                    "low|medium|high|sweep|binned")),
	PLUGIN_OPTION(Settings, reinsertion, BOOL,
	              bvhlab::bool_option("reinsertion",
	                                  "run its ReinsertionOptimizer after the build (high "
	                                  "already runs it once)",
	                                  false)),
	PLUGIN_OPTION(Settings, one_thread, CHOICE,
	              bvhlab::string_option("one_thread",
	                                    "low/medium/high at 1 thread: sequential (the library's "
	                                    "single-thread path) or pool (the mini-tree builder on "
	                                    "a one-thread pool)",
	                                    "sequential", "sequential|pool")),
	PLUGIN_OPTION(Settings, min_leaf, I64,
	              bvhlab::int_option("min_leaf", "nodes this small are never split", 1, 1,
	                                 max_leaf_cap)),
	PLUGIN_OPTION(Settings, max_leaf, I64,
	              bvhlab::int_option("max_leaf", "larger nodes are split even against the SAH",
	                                 8, 1, max_leaf_cap)),
	PLUGIN_OPTION(Settings, cost_ratio, DOUBLE,
	              bvhlab::float_option("cost_ratio",
	                                   "SAH cost of a node over that of a primitive (the "
	                                   "library's cost_ratio)",
	                                   1.0, 1e-6, 1e6)),
};
// min_leaf <= max_leaf is the host's rule for min_/max_ pairs.
PLUGIN_DECLS(options, Settings, nullptr)

Default::Config config_of(const Settings &s)
{
	Default::Config c;
	c.sah = bvh::v2::SplitHeuristic<float>(0, static_cast<float>(s.cost_ratio));
	c.min_leaf_size = static_cast<size_t>(s.min_leaf);
	c.max_leaf_size = static_cast<size_t>(s.max_leaf);
	c.quality = s.builder == low    ? Default::Quality::Low
	            : s.builder == high ? Default::Quality::High
	                                : Default::Quality::Medium;
	return c;
}

// The library's call; `pool` is null for the single-thread paths.
Bvh run_builder(const Settings &s, bvh::v2::ThreadPool *pool, const std::vector<BBox> &boxes,
                const std::vector<Vec3> &centers)
{
	Default::Config c = config_of(s);
	Bvh bvh;
	if (s.builder == sweep)
		bvh = bvh::v2::SweepSahBuilder<Node>::build(boxes, centers, c);
	else if (s.builder == binned)
		bvh = bvh::v2::BinnedSahBuilder<Node>::build(boxes, centers, c);
	else if (pool)
		bvh = Default::build(*pool, boxes, centers, c);
	else
		bvh = Default::build(boxes, centers, c);
	if (s.reinsertion && pool)
		bvh::v2::ReinsertionOptimizer<Node>::optimize(*pool, bvh);
	else if (s.reinsertion)
		bvh::v2::ReinsertionOptimizer<Node>::optimize(bvh);
	return bvh;
}

// The library's tree as peer::write_tree reads it.
struct View {
	const Bvh &b;
	uint64_t max_nodes() const { return b.nodes.size(); }
	uint64_t max_refs() const { return b.prim_ids.size(); }
	uint32_t root() const { return 0; }
	bool leaf(uint32_t n) const { return b.nodes[n].is_leaf(); }
	uint32_t child(uint32_t n, int k) const
	{
		return static_cast<uint32_t>(b.nodes[n].index.first_id()) + k;
	}
	uint32_t prim_count(uint32_t n) const
	{
		return static_cast<uint32_t>(b.nodes[n].index.prim_count());
	}
	uint32_t prim(uint32_t n, uint32_t k) const
	{
		return static_cast<uint32_t>(b.prim_ids[b.nodes[n].index.first_id() + k]);
	}
	void box(uint32_t n, float lo[3], float hi[3]) const
	{
		BBox x = b.nodes[n].get_bbox();
		for (int a = 0; a < 3; a++)
			lo[a] = x.min[a], hi[a] = x.max[a];
	}
};

// What a run's builds share, as the harness keeps a builder's output
// between repeats: the library's input arrays (refilled, not remade) and
// the thread pool. Starting and joining the workers on every build
// put thread starts, and the first touches of their stacks and malloc
// arenas, inside the timed call where the library's benchmark has none.
// Its workers took the CPU mask of the thread that made it, so it is
// remade when the thread count or the caller's mask changes; it is joined
// when the plugin is unloaded (or at exit). The lock serialises builds in
// one process (the tests'), as tinybvh's and embree's keeps do.
struct Kept {
	std::mutex lock;
	std::unique_ptr<bvh::v2::ThreadPool> pool;
	size_t threads = 0;
	cpu_set_t mask;
	std::vector<BBox> boxes;
	std::vector<Vec3> centers;
};
Kept kept;

// The kept pool of `threads` workers on the caller's CPUs, made if needed.
bvh::v2::ThreadPool &pool_for(size_t threads)
{
	cpu_set_t mask;
	CPU_ZERO(&mask);
	sched_getaffinity(0, sizeof(mask), &mask);
	if (!kept.pool || kept.threads != threads || !CPU_EQUAL(&mask, &kept.mask)) {
		kept.pool.reset(); // joins the old workers first
		kept.pool = std::make_unique<bvh::v2::ThreadPool>(threads);
		kept.threads = threads;
		kept.mask = mask;
	}
	return *kept.pool;
}

int build_tree(const bvhlab_host *host, bvhlab_build_ctx *ctx, const bvhlab_build_input *in,
               const Settings &s, bvhlab_build_output *out)
{
	std::lock_guard<std::mutex> hold(kept.lock);
	auto t0 = clk::now();
	std::vector<BBox> &boxes = kept.boxes;
	std::vector<Vec3> &centers = kept.centers;
	boxes.resize(in->prim_count);
	centers.resize(in->prim_count);
	for (size_t i = 0; i < in->prim_count; i++) {
		const bvhlab_aabb &b = in->prim_bounds[i];
		const float *c = &in->centroids[3 * i];
		boxes[i] = BBox(Vec3(b.lo[0], b.lo[1], b.lo[2]), Vec3(b.hi[0], b.hi[1], b.hi[2]));
		centers[i] = Vec3(c[0], c[1], c[2]);
	}
	peer::report_phase(host, ctx, "input", peer::ms_since(t0));
	// sweep and binned are single-threaded: a pool only for what uses one.
	bool top_down = s.builder == sweep || s.builder == binned;
	bool pooled = (in->threads > 1 || s.one_thread == pool_of_one) && (!top_down || s.reinsertion);
	Bvh bvh = run_builder(s, pooled ? &pool_for(in->threads) : nullptr, boxes, centers);
	return peer::convert(host, ctx, View{bvh}, out);
}

// 28 bits of the node's index address children and primitives.
PEER_BUILD_FN(Node::Index::max_first_id / 2)

// Any exception out of build() becomes the run's error (bvhlab::guarded_build).
// Peak bytes per triangle (issue 44): measured 140-203, high at 2 threads the most.
const bvhlab_builder descriptor = bvhlab::with_peak_bytes(bvhlab::with_fill_options(
	bvhlab::make_builder("bvh2",
	                     "madmann91/bvh v2 (ac41ab8): DefaultBuilder low/medium/high (mini-tree "
	                     "on a pool of the run's threads), sweep and binned SAH, optional "
	                     "reinsertion",
	                     BVHLAB_BUILDER_PARALLEL, plugin_decls, bvhlab::guarded_build<build>),
	plugin_fill_options, sizeof(Settings)), 240);

} // namespace

PLUGIN_EXPORT(descriptor)
