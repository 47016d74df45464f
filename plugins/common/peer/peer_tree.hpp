// peer_tree.hpp: a peer library's tree, binary or wide (tinybvh's 4- and
// 8-wide), written out in bvhlab's standard layout (tinybvh, bvh2),
// header-only C++.
//
// The library's tree is read through a small view (see peer_write_tree)
// and written depth first with the children of each inner node adjacent,
// so the output's order is the same whatever order the
// library's threads numbered its nodes in. Boxes are copied as the library
// made them, never recomputed: the validator judges the library's own tree
// (a box that misses its contents is the library's finding, not fixed up).
#ifndef BVHLAB_PEER_TREE_HPP
#define BVHLAB_PEER_TREE_HPP

#include <cerrno>
#include <chrono>
#include <cstdint>
#include <utility>
#include <vector>

#include <bvhlab/builder.h>

namespace peer {

// Milliseconds since `t0` on the steady clock, for host->phase.
inline double ms_since(std::chrono::steady_clock::time_point t0)
{
	using ms = std::chrono::duration<double, std::milli>;
	return ms(std::chrono::steady_clock::now() - t0).count();
}

// Adds `ms` to phase `name` when the host has ABI 1.3's phases.
inline void report_phase(const bvhlab_host *host, bvhlab_build_ctx *ctx, const char *name,
                         double ms)
{
	if (BVHLAB_HOST_HAS(host, phase))
		host->phase(ctx, name, ms);
}

// Room for `nodes` nodes and `refs` references (one grow, from upper bounds
// the view gives, so the writer never grows mid-way).
inline int reserve(const bvhlab_host *host, bvhlab_build_ctx *ctx, bvhlab_build_output *out,
                   uint64_t nodes, uint64_t refs)
{
	if (nodes <= out->node_capacity && refs <= out->index_capacity)
		return 0;
	if (nodes > UINT32_MAX || refs > UINT32_MAX ||
	    host->grow_output(ctx, out, static_cast<uint32_t>(nodes),
	                      static_cast<uint32_t>(refs)) < 0) {
		host->set_error(ctx, "cannot grow the output to %llu nodes, %llu references",
		                static_cast<unsigned long long>(nodes),
		                static_cast<unsigned long long>(refs));
		return -ENOMEM;
	}
	return 0;
}

// An inner node's children: the view's child_count(n) where it has one (a
// wide tree's), else 2.
template <class View>
auto child_count(const View &view, uint32_t n, int) -> decltype(view.child_count(n))
{
	return view.child_count(n);
}
template <class View> uint32_t child_count(const View &, uint32_t, long)
{
	return 2;
}

// Writes the tree seen through `view` into `out`. The view provides:
//   uint64_t max_nodes(), max_refs()   upper bounds of what will be written
//   uint32_t root()
//   bool leaf(n); uint32_t child(n, k) for k = 0, 1 (inner nodes), or
//   k < child_count(n) when it has child_count (2 to BVHLAB_MAX_WIDTH: a
//   node of more than 2 is written as ABI 1.5's BVHLAB_NODE_INNER | k; the
//   caller sets out->width)
//   uint32_t prim_count(n); uint32_t prim(n, k) (leaves)
//   void box(n, float lo[3], float hi[3])
// 0, or a negative errno after host->set_error (-EPROTO when the library's
// tree is not a tree of non-empty leaves within the bounds it stated).
template <class View>
int write_tree(const bvhlab_host *host, bvhlab_build_ctx *ctx, const View &view,
               bvhlab_build_output *out)
{
	int rc = reserve(host, ctx, out, view.max_nodes(), view.max_refs());
	if (rc < 0)
		return rc;
	std::vector<std::pair<uint32_t, uint32_t>> stack; // (library node, output slot)
	stack.reserve(128);
	stack.emplace_back(view.root(), 0);
	out->node_count = 1;
	out->index_count = 0;
	while (!stack.empty()) {
		auto [src, slot] = stack.back();
		stack.pop_back();
		bvhlab_node &n = out->nodes[slot];
		view.box(src, n.lo, n.hi);
		if (!view.leaf(src)) {
			uint32_t k = child_count(view, src, 0);
			if (k < 2 || k > BVHLAB_MAX_WIDTH ||
			    uint64_t{out->node_count} + k > view.max_nodes()) {
				host->set_error(ctx, "the library's node %u has %u children, or its tree "
				                "more nodes than its %llu (a cycle?)", src, k,
				                static_cast<unsigned long long>(view.max_nodes()));
				return -EPROTO;
			}
			n.first = out->node_count;
			n.count = k == 2 ? 0 : BVHLAB_NODE_INNER | k;
			out->node_count += k;
			for (uint32_t c = k; c-- > 0;)
				stack.emplace_back(view.child(src, static_cast<int>(c)), n.first + c);
			continue;
		}
		uint32_t count = view.prim_count(src);
		if (count == 0 || uint64_t{out->index_count} + count > view.max_refs()) {
			host->set_error(ctx, "the library's leaf %u holds %u primitives (%u written of "
			                "at most %llu)", src, count, out->index_count,
			                static_cast<unsigned long long>(view.max_refs()));
			return -EPROTO;
		}
		n.first = out->index_count;
		n.count = count;
		for (uint32_t k = 0; k < count; k++)
			out->prim_index[out->index_count++] = view.prim(src, k);
	}
	return 0;
}

// The tail of every peer build: the library's tree written out
// (write_tree), its time reported as phase "convert" (inside build_ms, as
// everything in the call is).
template <class View>
int convert(const bvhlab_host *host, bvhlab_build_ctx *ctx, const View &view,
            bvhlab_build_output *out)
{
	auto t0 = std::chrono::steady_clock::now();
	int rc = write_tree(host, ctx, view, out);
	report_phase(host, ctx, "convert", ms_since(t0));
	return rc;
}

// 0 when the library can take the build's primitives (1 to `max`), else
// -EINVAL after host->set_error.
inline int check_prims(const bvhlab_host *host, bvhlab_build_ctx *ctx,
                       const bvhlab_build_input *in, uint64_t max)
{
	if (in->prim_count != 0 && in->prim_count <= max)
		return 0;
	host->set_error(ctx, "cannot build over %u primitives", in->prim_count);
	return -EINVAL;
}

} // namespace peer

// A peer plugin's build(), after PLUGIN_DECLS(options, Settings, ...) and
// its build_tree(host, ctx, in, settings, out): the options first, then the
// primitive count against what the library's indices address (`max`,
// peer::check_prims), then the library's build.
#define PEER_BUILD_FN(max)                                                            \
	int build(const bvhlab_host *host, bvhlab_build_ctx *ctx,                        \
	          const bvhlab_build_input *in, bvhlab_build_output *out)                 \
	{                                                                              \
		Settings s;                                                            \
		int rc = PLUGIN_OPTIONS_GET(host, ctx, in, &s);                        \
		if (rc == 0)                                                           \
			rc = peer::check_prims(host, ctx, in, (max));                  \
		return rc < 0 ? rc : build_tree(host, ctx, in, s, out);                \
	}


#endif
