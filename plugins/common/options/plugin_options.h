/*
 * A plugin's options, each declared once together with the field of the
 * plugin's struct it fills: one table of plugin_option entries gives both
 * the descriptor's bvhlab_option_decl array (the ABI's, so `bvhlab list`
 * and the host's checks see nothing new) and the filling of the struct by
 * offset. The host has already checked every value against its
 * declaration (type, range, choices) and filled in the defaults, so
 * nothing here checks a value again; what a plugin still checks is only
 * what a declaration cannot say (lbvh's bits: 30 or 63, within 30..63).
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
 *     ... in build(): struct my_options opt;
 *         rc = plugin_options_fill(host, ctx, options, PLUGIN_OPTION_COUNT(options), &opt);
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
 *     PLUGIN_DECLS(options)
 *     const bvhlab_builder descriptor = bvhlab::make_builder(
 *             "mine", "...", 0, plugin_decls, bvhlab::guarded_build<build>);
 *     PLUGIN_EXPORT(descriptor)
 *     ... in build(): plugin_options_fill(host, ctx, options, settings);
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

BVHLAB_END_DECLS

/*
 * At file scope after `table`: plugin_decls, the descriptor's declarations
 * (bvhlab_option_decl[PLUGIN_OPTION_COUNT(table)]), filled from the table
 * by PLUGIN_EXPORT's entry point the first time it is called.
 */
#define PLUGIN_DECLS(table)                                                            \
	static bvhlab_option_decl plugin_decls[PLUGIN_OPTION_COUNT(table)];            \
	static void plugin_decls_fill(void)                                            \
	{                                                                              \
		plugin_options_decls(table, PLUGIN_OPTION_COUNT(table), plugin_decls); \
	}

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

/* C: BVHLAB_PLUGIN with the options of `table` (PLUGIN_DECLS and
 * PLUGIN_EXPORT around the descriptor); `...` are its other fields. */
#define PLUGIN_WITH_OPTIONS(table, ...)                                                   \
	PLUGIN_DECLS(table)                                                               \
	static const bvhlab_builder plugin_descriptor = {                                 \
		.abi_version = BVHLAB_ABI_CURRENT, .struct_size = sizeof(bvhlab_builder), \
		.option_count = PLUGIN_OPTION_COUNT(table), .options = plugin_decls,      \
		__VA_ARGS__};                                                             \
	PLUGIN_EXPORT(plugin_descriptor)

#ifdef __cplusplus
#include <type_traits>

/* The C++ form: the count from the array, and only a struct whose offsets
 * offsetof gives (standard layout; default member initialisers are fine,
 * every field of the table is filled anyway). */
template <class Options, size_t Count>
int plugin_options_fill(const bvhlab_host *host, bvhlab_build_ctx *ctx,
                        const plugin_option (&table)[Count], Options &out)
{
	static_assert(std::is_standard_layout<Options>::value,
	              "plugin_options_fill: offsetof needs a standard-layout struct");
	return plugin_options_fill(host, ctx, table, Count, &out);
}
#endif

#endif /* BVHLAB_PLUGIN_OPTIONS_H */
