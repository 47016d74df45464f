/*
 * A plugin's options, each declared once together with the field of the
 * plugin's struct it fills: one table of plugin_option entries gives both
 * the descriptor's bvhlab_option_decl array (the ABI's, so `bvhlab list`
 * and the host's checks see nothing new) and the filling of the struct by
 * offset. The host checks every value against its declaration (type,
 * range, choices) when it reads the config and fills in the defaults, so
 * nothing here checks a value again; a plugin's `check` function only
 * states what a declaration cannot (sah's simd avx2 on a CPU without it)
 * and derives what its build uses (embree's quality enum).
 *
 * The struct is filled once per run (ABI 1.6): the descriptor's
 * fill_options, which PLUGIN_DECLS writes, runs when the host reads the
 * config, and each build gets a copy of the struct it filled
 * (PLUGIN_OPTIONS_GET); only an older host makes the plugin read its
 * options at each build.
 *
 * In C:
 *
 *     struct my_options { uint32_t bins; int method; };  // method: 0 sweep, 1 binned
 *     static const plugin_option options[] = {
 *             PLUGIN_OPTION(struct my_options, bins, U32, .name = "bins",
 *                           .help = "bins per axis", .def_int = 16, .min = 2, .max = 256),
 *             PLUGIN_OPTION(struct my_options, method, CHOICE, .name = "method",
 *                           .help = "split search", .def_string = "sweep",
 *                           .choices = "sweep|binned"),
 *     };
 *     PLUGIN_DECLS(options, struct my_options, NULL)   // or a check function
 *     ... in build(): struct my_options opt;
 *         rc = PLUGIN_OPTIONS_GET(host, ctx, input, &opt);
 *     PLUGIN_WITH_OPTIONS(options, .name = "mine", .summary = "...", .build = build)
 *
 * The declared type follows from the field's (U32 and I64 from INT, ...):
 * an entry that leaves .type 0 is declared with it.
 *
 * C++ plugins (the peers) use the same table; C++17 has no designated
 * initializers, so the declaration is bvhlab/builder.hpp's constructors:
 *
 *     const plugin_option options[] = {
 *             PLUGIN_OPTION(Settings, bins, I64,
 *                           bvhlab::int_option("bins", "bins per axis", 16, 2, 256)),
 *     };
 *     PLUGIN_DECLS(options, Settings, nullptr)
 *     const bvhlab_builder descriptor = bvhlab::with_fill_options(bvhlab::make_builder(
 *             "mine", "...", 0, plugin_decls, bvhlab::guarded_build<build>),
 *             plugin_fill_options, sizeof(Settings));
 *     PLUGIN_EXPORT(descriptor)
 *     ... in build(): PLUGIN_OPTIONS_GET(host, ctx, input, &settings);
 *
 * The descriptor's bvhlab_option_decl array must be contiguous, and an
 * entry here is longer than a declaration, so PLUGIN_DECLS keeps an array
 * of the table's size that the entry point fills once (pthread_once) before
 * it first returns the descriptor: the entry point still returns a static
 * descriptor, built before the host reads it, from any thread.
 *
 * A static library linked into each plugin that uses it.
 */
#ifndef BVHLAB_PLUGIN_OPTIONS_H
#define BVHLAB_PLUGIN_OPTIONS_H

#include <pthread.h>
#include <stddef.h>
#include <stdint.h>

#include <bvhlab/builder.h>

BVHLAB_BEGIN_DECLS

/* The C type of the field an option goes to. */
enum plugin_field_type {
	PLUGIN_BOOL = 1, /* bool, from a BOOL option */
	PLUGIN_I64,      /* int64_t, from an INT option */
	PLUGIN_U32,      /* uint32_t, from an INT option declared within 0..UINT32_MAX */
	PLUGIN_DOUBLE,   /* double, from a FLOAT option */
	PLUGIN_FLOAT,    /* float, from a FLOAT option (rounded) */
	PLUGIN_CHOICE,   /* int, from a STRING option with choices: the value's
	                  * index in them ("sweep|binned": sweep 0, binned 1) */
	PLUGIN_STRING,   /* const char *, from a STRING option; valid during build */
};

/* One option: what the host is told, and where its value goes. */
typedef struct plugin_option {
	bvhlab_option_decl decl; /* as the descriptor declares it; type 0: the field's */
	size_t offset;           /* of the field in the plugin's struct */
	int field;               /* enum plugin_field_type: the field's C type */
} plugin_option;

/*
 * One entry: the option that `...` declares (a bvhlab_option_decl's
 * initializer: designated in C, designated in member order in C++20, a
 * builder.hpp constructor or positional in C++17) fills `member` of
 * `struct_type`, of C type `field_type` (BOOL, I64, U32, ... of enum
 * plugin_field_type). The entry itself is initialised by position, which
 * C11 and C++ both take.
 */
#define PLUGIN_OPTION(struct_type, member, field_type, ...)                      \
	{ { __VA_ARGS__ },                                                       \
	  offsetof(struct_type, member) +                                        \
		  0 * PLUGIN_SIZE_CHECK(((struct_type *)0)->member, field_type), \
	  PLUGIN_##field_type }

/* The size of each field type: PLUGIN_OPTION refuses, at compile time, a
 * member of another size (an I64 entry on a uint32_t would write past it). */
#define PLUGIN_SIZE_BOOL sizeof(bool)
#define PLUGIN_SIZE_I64 sizeof(int64_t)
#define PLUGIN_SIZE_U32 sizeof(uint32_t)
#define PLUGIN_SIZE_DOUBLE sizeof(double)
#define PLUGIN_SIZE_FLOAT sizeof(float)
#define PLUGIN_SIZE_CHOICE sizeof(int)
#define PLUGIN_SIZE_STRING sizeof(const char *)
#define PLUGIN_SIZE_CHECK(lvalue, field_type) \
	sizeof(char[sizeof(lvalue) == PLUGIN_SIZE_##field_type ? 1 : -1])

#define PLUGIN_OPTION_COUNT(table) (sizeof(table) / sizeof((table)[0]))

/* C: the entry of "max_leaf", the most primitives (or references) in a
 * leaf, which every builder and stage of this tree offers with one name,
 * one default (8, so that they compare at one leaf size) and one floor (1);
 * `most` is the builder's own limit, `text` its help. */
#define PLUGIN_MAX_LEAF(struct_type, member, field_type, most, text)   \
	PLUGIN_OPTION(struct_type, member, field_type, .name = "max_leaf", \
	              .help = text, .def_int = 8, .min = 1, .max = most)

/* C: the entries of "c_trav" and "c_isect", the SAH's costs of an inner
 * node and of one primitive, which every builder and stage that weighs the
 * SAH offers with one name, one default (1, the reported SAH's) and one
 * ceiling (1e6); c_isect's floor is above 0, c_trav's `floor` 1e-6 where
 * the node's cost is c_trav alone, 0 where another cost prices it
 * (collapse's c_node); `text` is the help. */
#define PLUGIN_C_TRAV(struct_type, member, field_type, floor, text)      \
	PLUGIN_OPTION(struct_type, member, field_type, .name = "c_trav", \
	              .help = text, .def_float = 1.0, .min = floor, .max = 1e6)
#define PLUGIN_C_ISECT(struct_type, member, field_type, text)             \
	PLUGIN_OPTION(struct_type, member, field_type, .name = "c_isect", \
	              .help = text, .def_float = 1.0, .min = 1e-6, .max = 1e6)

/* Copies the declarations of table[0 .. count) into decls, in order. */
void plugin_options_decls(const plugin_option *table, size_t count, bvhlab_option_decl *decls);

/*
 * Fills *out from this build's options, one field per entry. 0, or a
 * negative errno after host->set_error when an entry's field does not fit
 * its declaration (a type that does not fit, a U32 for a range past 32
 * bits, a CHOICE without choices): a mistake in the plugin, never in a
 * config.
 */
int plugin_options_fill(const bvhlab_host *host, bvhlab_build_ctx *ctx,
                        const plugin_option *table, size_t count, void *out);

/* What a plugin's options must meet beyond their declarations, checked on
 * the struct just filled, which it may complete (a choice turned into what
 * the build uses). 0, or -EINVAL after host->set_error naming the option
 * and what it allows. */
typedef int (*plugin_check_fn)(const bvhlab_host *host, bvhlab_build_ctx *ctx, void *options);

/* fill_options's body: *out (size bytes) zeroed, filled by the table, then
 * checked by `check` (NULL: nothing beyond the declarations). */
int plugin_options_read(const bvhlab_host *host, bvhlab_build_ctx *ctx,
                        const plugin_option *table, size_t count, plugin_check_fn check,
                        size_t size, void *out);

/* This call's options into *out (size bytes): a copy of input->options,
 * the struct fill_options filled when the host read the config, or, from
 * an older host that has none, `fill` run now. 0, or fill's error. */
int plugin_options_get(const bvhlab_host *host, bvhlab_build_ctx *ctx,
                       const bvhlab_build_input *input,
                       int (*fill)(const bvhlab_host *, bvhlab_build_ctx *, void *),
                       size_t size, void *out);

BVHLAB_END_DECLS

/*
 * At file scope after `table`, whose entries fill a struct `options_type`:
 * plugin_decls, the descriptor's declarations
 * (bvhlab_option_decl[PLUGIN_OPTION_COUNT(table)]), filled from the table
 * by PLUGIN_EXPORT's entry point the first time it is called, and
 * plugin_fill_options, the descriptor's fill_options (the table, then
 * `check`, a plugin_check_fn or NULL).
 */
#define PLUGIN_DECLS(table, options_type, check)                                             \
	static bvhlab_option_decl plugin_decls[PLUGIN_OPTION_COUNT(table)];                  \
	static void plugin_decls_fill(void)                                                  \
	{                                                                                    \
		plugin_options_decls(table, PLUGIN_OPTION_COUNT(table), plugin_decls);       \
	}                                                                                    \
	typedef options_type plugin_options_type;                                            \
	static int plugin_fill_options(const bvhlab_host *host, bvhlab_build_ctx *ctx,       \
	                               void *out)                                            \
	{                                                                                    \
		return plugin_options_read(host, ctx, table, PLUGIN_OPTION_COUNT(table), check, \
		                           sizeof(options_type), out);                       \
	}

/* In build(), refine() or update(), after PLUGIN_DECLS: this call's options
 * into *out, a struct of PLUGIN_DECLS's options_type (plugin_options_get). */
#define PLUGIN_OPTIONS_GET(host, ctx, input, out)                                        \
	plugin_options_get(host, ctx, input, plugin_fill_options,                        \
	                   sizeof(plugin_options_type) +                                 \
	                           0 * sizeof((out) == (plugin_options_type *)0), \
	                   out)

/*
 * After PLUGIN_DECLS: a build() whose state is a struct `type` (PLUGIN_DECLS's
 * options_type, with members in and n) named b, its options first
 * (PLUGIN_OPTIONS_GET copies the whole struct), then the input and the
 * primitive count; the arguments after the type are the rest of its body,
 * which returns (the Morton builders' MORTON_BUILD_FN, the device
 * builders' CL_BUILD_FN).
 */
#define PLUGIN_BUILD_FN(type, ...)                                                    \
	static int build(const bvhlab_host *host, bvhlab_build_ctx *ctx,               \
	                 const bvhlab_build_input *input, bvhlab_build_output *output) \
	{                                                                              \
		type b;                                                                \
		int rc = PLUGIN_OPTIONS_GET(host, ctx, input, &b);                     \
		if (rc < 0)                                                            \
			return rc;                                                     \
		b.in = input, b.n = input->prim_count;                                 \
		__VA_ARGS__                                                            \
	}

/* The descriptor of a parallel, deterministic builder whose build() is
 * this file's `build` (the Morton builders: lbvh, ploc, hploc, hlbvh);
 * `more` adds flags to those two (0 for none), the rest is .name,
 * .summary and what else it sets. */
#define PLUGIN_PARALLEL_BUILDER(table, more, ...)                                       \
	PLUGIN_WITH_OPTIONS(table,                                                    \
	                    .flags = BVHLAB_BUILDER_PARALLEL | BVHLAB_BUILDER_DETERMINISTIC | (more), \
	                    .build = build, __VA_ARGS__)

/* The entry point (BVHLAB_PLUGIN_EXPORT's), after PLUGIN_DECLS and the
 * descriptor: plugin_decls filled, once, before the descriptor is returned
 * (NULL, as for another major, in the unlikely case pthread_once fails). */
#define PLUGIN_EXPORT(descriptor)                                             \
	BVHLAB_PLUGIN_ENTRY                                                   \
	{                                                                     \
		static pthread_once_t plugin_decls_once = PTHREAD_ONCE_INIT;  \
		if (host_abi_major != BVHLAB_ABI_MAJOR ||                     \
		    pthread_once(&plugin_decls_once, plugin_decls_fill) != 0) \
			return NULL;                                          \
		return &(descriptor);                                         \
	}

/* C: BVHLAB_PLUGIN with the options of `table` (after its PLUGIN_DECLS;
 * PLUGIN_EXPORT after the descriptor); `...` are its other fields. */
#define PLUGIN_WITH_OPTIONS(table, ...)                                                   \
	static const bvhlab_builder plugin_descriptor = {                                 \
		.abi_version = BVHLAB_ABI_CURRENT, .struct_size = sizeof(bvhlab_builder), \
		.option_count = PLUGIN_OPTION_COUNT(table), .options = plugin_decls,      \
		.fill_options = plugin_fill_options,                                      \
		.options_size = sizeof(plugin_options_type), __VA_ARGS__};                \
	PLUGIN_EXPORT(plugin_descriptor)


#endif /* BVHLAB_PLUGIN_OPTIONS_H */
