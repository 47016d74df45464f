// template_cpp: a bvhlab builder plugin in C++17, to copy when your BVH code
// is C++. A small binned SAH builder: each node's primitives are binned by
// centroid on all three axes, split where the binned SAH is lowest, and the
// two halves of the top levels are built by std::threads. Each subtree is
// built into its own std::vector of nodes, then written out in the standard
// layout (children as adjacent pairs) by one thread.
//
// The bvhlab headers are C and C++ alike (extern "C"); the only rule C++
// adds is that no exception may cross into the host. <bvhlab/builder.hpp>
// (optional) takes care of that: bvhlab::guarded_build<build> turns any
// exception build() lets out into host->set_error(what()) and a negative
// errno; it also gives named option constructors and make_builder.
// Build it out of tree against an installed bvhlab (meson.build beside this
// file), then:  bvhlab build ./build/template_cpp.so icosphere:frequency=64
#include <algorithm>
#include <array>
#include <cerrno>
#include <cstdint>
#include <functional>
#include <memory>
#include <system_error>
#include <thread>
#include <vector>

#include <bvhlab/aabb.h>
#include <bvhlab/builder.hpp>

namespace {

constexpr uint32_t max_bins = 256;

const bvhlab_option_decl options[] = {
	// name, help, default, min, max
	bvhlab::int_option("bins", "centroid bins per axis", 16, 2, max_bins),
	bvhlab::int_option("max_leaf", "most primitives in a leaf", 4, 1, 64),
};

struct Subtree;

// A node of one subtree. An inner node's children are nodes of the same
// subtree (child[k] indexes its vector), except a left child built by
// another thread: that one is the root of `left`, a subtree of its own, so
// no two threads ever grow the same vector.
struct Node {
	bvhlab_aabb box;
	uint32_t begin = 0, end = 0;    // the primitive range, in Builder::ids
	int32_t child[2] = {-1, -1};    // -1, -1: a leaf
	std::unique_ptr<Subtree> left; // set when the left child was built apart
};

struct Subtree {
	std::vector<Node> nodes; // nodes[0] is this subtree's root
};

struct Builder {
	const bvhlab_build_input *in;
	std::vector<uint32_t> ids; // primitive ids, partitioned in place (disjoint ranges per thread)
	uint32_t bins, max_leaf;
};

struct Split {
	int axis = -1;
	uint32_t bin = 0; // primitives in bins < bin go left
	float cost = 0;
};

float centroid(const Builder &b, uint32_t id, int axis)
{
	return b.in->centroids[3 * static_cast<size_t>(id) + axis];
}

uint32_t bin_of(float c, float lo, float scale, uint32_t bins)
{
	auto k = static_cast<int64_t>((c - lo) * scale);
	return static_cast<uint32_t>(std::clamp<int64_t>(k, 0, bins - 1));
}

// The cheapest binned split of [begin, end) on any axis (axis -1: none).
Split find_split(const Builder &b, uint32_t begin, uint32_t end, const bvhlab_aabb &cbox)
{
	Split best;
	std::array<bvhlab_aabb, max_bins> box;
	std::array<uint32_t, max_bins> count;
	std::array<float, max_bins> right_cost;
	for (int axis = 0; axis < 3; axis++) {
		float extent = cbox.hi[axis] - cbox.lo[axis];
		if (!(extent > 0))
			continue;
		float scale = static_cast<float>(b.bins) / extent;
		for (uint32_t k = 0; k < b.bins; k++) {
			bvhlab_aabb_empty(&box[k]);
			count[k] = 0;
		}
		for (uint32_t i = begin; i < end; i++) {
			uint32_t k = bin_of(centroid(b, b.ids[i], axis), cbox.lo[axis], scale, b.bins);
			bvhlab_aabb_grow(&box[k], &b.in->prim_bounds[b.ids[i]]);
			count[k]++;
		}
		// Right-to-left areas, then a left-to-right sweep over the cut positions.
		bvhlab_aabb acc;
		bvhlab_aabb_empty(&acc);
		uint32_t n = 0;
		for (uint32_t k = b.bins - 1; k > 0; k--) {
			bvhlab_aabb_grow(&acc, &box[k]);
			n += count[k];
			right_cost[k] = n ? bvhlab_aabb_half_area(&acc) * static_cast<float>(n) : 0;
		}
		bvhlab_aabb_empty(&acc);
		n = 0;
		for (uint32_t k = 1; k < b.bins; k++) {
			bvhlab_aabb_grow(&acc, &box[k - 1]);
			n += count[k - 1];
			if (n == 0 || n == end - begin)
				continue;
			float cost = bvhlab_aabb_half_area(&acc) * static_cast<float>(n) + right_cost[k];
			if (best.axis < 0 || cost < best.cost)
				best = Split{axis, k, cost};
		}
	}
	return best;
}

// Builds [begin, end) into t.nodes[index]; spawns a thread for the left
// half while `spawn` levels remain.
void build_node(Builder &b, Subtree &t, size_t index, uint32_t begin, uint32_t end,
                unsigned spawn);

void build_children(Builder &b, Subtree &t, size_t index, uint32_t mid, unsigned spawn)
{
	uint32_t begin = t.nodes[index].begin, end = t.nodes[index].end;
	std::unique_ptr<Subtree> left;
	std::thread worker;
	if (spawn > 0) {
		left = std::make_unique<Subtree>();
		left->nodes.emplace_back();
		try {
			worker = std::thread(build_node, std::ref(b), std::ref(*left), size_t{0}, begin,
			                     mid, spawn - 1);
		} catch (const std::system_error &) {
			build_node(b, *left, 0, begin, mid, spawn - 1); // no thread: do it here
		}
	} else {
		t.nodes[index].child[0] = static_cast<int32_t>(t.nodes.size());
		t.nodes.emplace_back();
		build_node(b, t, t.nodes.size() - 1, begin, mid, 0);
	}
	size_t right = t.nodes.size();
	t.nodes[index].child[1] = static_cast<int32_t>(right);
	t.nodes.emplace_back();
	build_node(b, t, right, mid, end, spawn > 0 ? spawn - 1 : 0);
	if (worker.joinable())
		worker.join();
	t.nodes[index].left = std::move(left);
}

void build_node(Builder &b, Subtree &t, size_t index, uint32_t begin, uint32_t end,
                unsigned spawn)
{
	bvhlab_aabb box, cbox;
	bvhlab_aabb_empty(&box);
	bvhlab_aabb_empty(&cbox);
	for (uint32_t i = begin; i < end; i++) {
		bvhlab_aabb_grow(&box, &b.in->prim_bounds[b.ids[i]]);
		bvhlab_aabb_grow_point(&cbox, &b.in->centroids[3 * static_cast<size_t>(b.ids[i])]);
	}
	t.nodes[index].box = box;
	t.nodes[index].begin = begin;
	t.nodes[index].end = end;
	uint32_t count = end - begin;
	Split s = count > 1 ? find_split(b, begin, end, cbox) : Split{};
	// c_trav = c_isect = 1: split only when it beats a leaf (or the leaf is too big).
	float leaf_cost = bvhlab_aabb_half_area(&box) * static_cast<float>(count);
	if (s.axis < 0 ||
	    (count <= b.max_leaf && leaf_cost <= bvhlab_aabb_half_area(&box) + s.cost))
		return; // a leaf; one of more than max_leaf only when all centroids coincide
	float scale = static_cast<float>(b.bins) / (cbox.hi[s.axis] - cbox.lo[s.axis]);
	auto first = b.ids.begin() + begin, last = b.ids.begin() + end;
	auto mid = std::partition(first, last, [&](uint32_t id) {
		return bin_of(centroid(b, id, s.axis), cbox.lo[s.axis], scale, b.bins) < s.bin;
	});
	build_children(b, t, index, static_cast<uint32_t>(mid - b.ids.begin()), spawn);
}

// Writes the tree depth first, children as adjacent pairs after their parent.
struct Writer {
	bvhlab_build_output *out;
	uint32_t next = 1;

	void write(const Subtree &t, size_t index, uint32_t slot)
	{
		const Node &n = t.nodes[index];
		bvhlab_node &o = out->nodes[slot];
		std::copy(n.box.lo, n.box.lo + 3, o.lo);
		std::copy(n.box.hi, n.box.hi + 3, o.hi);
		if (n.child[1] < 0) { // a leaf
			o.first = n.begin;
			o.count = n.end - n.begin;
			return;
		}
		uint32_t pair = next;
		next += 2;
		o.first = pair;
		o.count = 0;
		if (n.left)
			write(*n.left, 0, pair);
		else
			write(t, static_cast<size_t>(n.child[0]), pair);
		write(t, static_cast<size_t>(n.child[1]), pair + 1);
	}
};

unsigned spawn_levels(uint32_t threads)
{
	unsigned levels = 0;
	while (levels < 16 && (1u << levels) < threads)
		levels++;
	return levels;
}

// May throw (std::bad_alloc, std::system_error from std::thread, ...):
// the descriptor names bvhlab::guarded_build<build>, which catches it.
int build(const bvhlab_host *host, bvhlab_build_ctx *ctx, const bvhlab_build_input *input,
          bvhlab_build_output *output)
{
	int64_t bins = 16, max_leaf = 4;
	host->option_int(ctx, "bins", &bins);
	host->option_int(ctx, "max_leaf", &max_leaf);
	Builder b{input, std::vector<uint32_t>(input->prim_count), static_cast<uint32_t>(bins),
	          static_cast<uint32_t>(max_leaf)};
	for (uint32_t i = 0; i < input->prim_count; i++)
		b.ids[i] = i;
	unsigned levels = spawn_levels(input->threads);
	Subtree root;
	root.nodes.emplace_back();
	build_node(b, root, 0, 0, input->prim_count, levels);
	Writer w{output};
	w.write(root, 0, 0);
	std::copy(b.ids.begin(), b.ids.end(), output->prim_index);
	output->node_count = w.next;
	output->index_count = input->prim_count;
	return 0;
}

const bvhlab_builder descriptor = bvhlab::make_builder(
	"template_cpp", "C++17 template: binned SAH, top levels on std::threads",
	BVHLAB_BUILDER_PARALLEL | BVHLAB_BUILDER_DETERMINISTIC, options,
	bvhlab::guarded_build<build>);

} // namespace

BVHLAB_PLUGIN_EXPORT(descriptor)
