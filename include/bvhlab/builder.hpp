/*
 * bvhlab — C++17 helpers for builder plugins (optional; header only).
 *
 * builder.h is the ABI and is all a plugin needs; this header only spares
 * C++ the parts C++17 makes awkward:
 *
 *   - named option constructors, since C++17 has no designated
 *     initializers and a bvhlab_option_decl would otherwise be a
 *     10-field positional initializer:
 *
 *         const bvhlab_option_decl options[] = {
 *             bvhlab::int_option("bins", "centroid bins per axis", 16, 2, 256),
 *             bvhlab::string_option("method", "split search", "sweep", "sweep|binned"),
 *         };
 *
 *   - bvhlab::guarded_build<fn>, a build (or refine) function that may
 *     throw, wrapped so that no exception crosses into the host (which
 *     would abort the process): any exception becomes host->set_error
 *     with its what() and a negative errno (-ENOMEM for std::bad_alloc,
 *     -EIO otherwise);
 *
 *   - bvhlab::make_builder, the descriptor with abi_version and
 *     struct_size filled in and the option count taken from the array.
 *
 *         int build(const bvhlab_host *, bvhlab_build_ctx *,
 *                   const bvhlab_build_input *, bvhlab_build_output *);  // may throw
 *         const bvhlab_builder descriptor = bvhlab::make_builder(
 *             "mine", "one line for bvhlab list", BVHLAB_BUILDER_PARALLEL,
 *             options, bvhlab::guarded_build<build>);
 *         BVHLAB_PLUGIN_EXPORT(descriptor)
 *
 * examples/plugin-template-cpp/ uses all three.
 */
#ifndef BVHLAB_BUILDER_HPP
#define BVHLAB_BUILDER_HPP

#ifndef __cplusplus
#error "bvhlab/builder.hpp is C++ (C++17); C plugins use bvhlab/builder.h"
#endif

#include <cerrno>
#include <cstddef>
#include <cstdint>
#include <exception>
#include <new>

#include "builder.h"

namespace bvhlab {

/* An INT option: default def, values in [min, max]. */
constexpr bvhlab_option_decl int_option(const char *name, const char *help, int64_t def,
                                        int64_t min, int64_t max)
{
	return bvhlab_option_decl{name, BVHLAB_OPTION_INT, help, false, def, 0.0, nullptr,
	                          static_cast<double>(min), static_cast<double>(max), nullptr};
}

/* A FLOAT option: default def, values in [min, max]. */
constexpr bvhlab_option_decl float_option(const char *name, const char *help, double def,
                                          double min, double max)
{
	return bvhlab_option_decl{name, BVHLAB_OPTION_FLOAT, help, false, 0, def, nullptr,
	                          min, max, nullptr};
}

/* A BOOL option. */
constexpr bvhlab_option_decl bool_option(const char *name, const char *help, bool def)
{
	return bvhlab_option_decl{name, BVHLAB_OPTION_BOOL, help, def, 0, 0.0, nullptr,
	                          1.0, 0.0, nullptr};
}

/* A STRING option; choices "a|b|c" restricts it to those values. */
constexpr bvhlab_option_decl string_option(const char *name, const char *help,
                                           const char *def, const char *choices = nullptr)
{
	return bvhlab_option_decl{name, BVHLAB_OPTION_STRING, help, false, 0, 0.0, def,
	                          1.0, 0.0, choices};
}

/* The signature of build, refine and update (ABI 1.4). */
using build_fn = int (*)(const bvhlab_host *, bvhlab_build_ctx *, const bvhlab_build_input *,
                         bvhlab_build_output *);

/*
 * Calls fn and turns any exception it lets out into an error the host
 * records (host->set_error) and a negative errno: an exception that
 * reached the host's C frames would call std::terminate and abort the
 * run's process, its message lost.
 */
template <build_fn fn>
int guarded_build(const bvhlab_host *host, bvhlab_build_ctx *ctx,
                  const bvhlab_build_input *input, bvhlab_build_output *output) noexcept
{
	try {
		return fn(host, ctx, input, output);
	} catch (const std::bad_alloc &) {
		host->set_error(ctx, "out of memory (std::bad_alloc) for %u primitives",
		                input->prim_count);
		return -ENOMEM;
	} catch (const std::exception &e) {
		host->set_error(ctx, "%s", e.what());
		return -EIO;
	} catch (...) {
		host->set_error(ctx, "a C++ exception that is not a std::exception");
		return -EIO;
	}
}

/* The descriptor of a plugin whose options are the array `options`. */
template <std::size_t N>
constexpr bvhlab_builder make_builder(const char *name, const char *summary, uint32_t flags,
                                      const bvhlab_option_decl (&options)[N], build_fn build,
                                      build_fn refine = nullptr, build_fn update = nullptr)
{
	return bvhlab_builder{BVHLAB_ABI_CURRENT, sizeof(bvhlab_builder), name, summary, flags,
	                      static_cast<uint32_t>(N), options, build, refine, update,
	                      nullptr, 0, 0, 0, 0, nullptr};
}

/* The descriptor of a plugin without options. */
constexpr bvhlab_builder make_builder(const char *name, const char *summary, uint32_t flags,
                                      build_fn build, build_fn refine = nullptr,
                                      build_fn update = nullptr)
{
	return bvhlab_builder{BVHLAB_ABI_CURRENT, sizeof(bvhlab_builder), name, summary, flags,
	                      0, nullptr, build, refine, update, nullptr, 0, 0, 0, 0, nullptr};
}

/* The signature of fill_options (ABI 1.6). */
using fill_options_fn = int (*)(const bvhlab_host *, bvhlab_build_ctx *, void *);

/* `descriptor` with fill_options (ABI 1.6): the options read once, into a
 * struct of `size` bytes, when the config is read:
 *     const bvhlab_builder descriptor = bvhlab::with_fill_options(
 *         bvhlab::make_builder(...), fill, sizeof(Settings)); */
constexpr bvhlab_builder with_fill_options(bvhlab_builder descriptor, fill_options_fn fill,
                                           std::size_t size)
{
	descriptor.fill_options = fill;
	descriptor.options_size = static_cast<uint32_t>(size);
	return descriptor;
}

/* `descriptor` with peak_bytes_per_prim (ABI 1.7): what one build adds
 * per primitive at its peak (builder.h says what counts). */
constexpr bvhlab_builder with_peak_bytes(bvhlab_builder descriptor, uint32_t bytes_per_prim)
{
	descriptor.peak_bytes_per_prim = bytes_per_prim;
	return descriptor;
}

} // namespace bvhlab

#endif /* BVHLAB_BUILDER_HPP */
