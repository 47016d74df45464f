// fake_throw: a C++ builder whose build() throws, wrapped by
// bvhlab::guarded_build (include/bvhlab/builder.hpp). Option "throw" picks
// what it throws: "runtime" (std::runtime_error with a message the tests look
// for), "bad_alloc", "int" (not a std::exception) or "none" (builds a
// one-leaf tree, to show the wrapper passes results through); "escape"
// throws where no wrapper can catch it (a noexcept function), as an
// unwrapped build() would: std::terminate prints the message and aborts,
// and the harness quotes the end of the child's stderr.
#include <cstring>
#include <new>
#include <stdexcept>

#include <bvhlab/builder.hpp>

namespace {

const bvhlab_option_decl options[] = {
	bvhlab::string_option("throw", "what build() throws", "runtime",
	                      "runtime|bad_alloc|int|escape|none"),
};

void thrower()
{
	throw std::runtime_error("fake_throw: escaped build() unguarded");
}

// Through a pointer, so the compiler cannot see (and refuse) the throw.
void (*volatile throw_fn)() = thrower;

void escape() noexcept
{
	throw_fn();
}

// A valid tree without exceptions: the root a leaf of every primitive.
int build_leaf(const bvhlab_build_input *input, bvhlab_build_output *output)
{
	bvhlab_node &root = output->nodes[0];
	for (int k = 0; k < 3; k++) {
		root.lo[k] = input->bounds.lo[k];
		root.hi[k] = input->bounds.hi[k];
	}
	root.first = 0;
	root.count = input->prim_count;
	for (uint32_t i = 0; i < input->prim_count; i++)
		output->prim_index[i] = i;
	output->node_count = 1;
	output->index_count = input->prim_count;
	return 0;
}

int build(const bvhlab_host *host, bvhlab_build_ctx *ctx, const bvhlab_build_input *input,
          bvhlab_build_output *output)
{
	const char *what = "runtime";
	host->option_string(ctx, "throw", &what);
	if (std::strcmp(what, "runtime") == 0)
		throw std::runtime_error("fake_throw: thrown from build() on purpose");
	if (std::strcmp(what, "bad_alloc") == 0)
		throw std::bad_alloc();
	if (std::strcmp(what, "int") == 0)
		throw 42;
	if (std::strcmp(what, "escape") == 0)
		escape();
	return build_leaf(input, output);
}

const bvhlab_builder descriptor = bvhlab::make_builder(
	"fake_throw", "C++ builder that throws from build() (bvhlab::guarded_build)", 0, options,
	bvhlab::guarded_build<build>);

#ifdef FAKE_THROW_IN_CONSTRUCTOR
// A static object whose constructor throws (tests/fake/loadcrash): loading
// the plugin ends in std::terminate, before any entry point is asked.
struct ThrowsOnLoad {
	ThrowsOnLoad() { throw_fn(); }
} throws_on_load;
#endif

} // namespace

BVHLAB_PLUGIN_EXPORT(descriptor)
