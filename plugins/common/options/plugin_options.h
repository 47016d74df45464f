/*
 * A plugin's options into its own struct, by table: each entry names a
 * declared option and the field (offsetof) and C type it goes to. The
 * host has already checked every value against its declaration (type,
 * range, choices) and filled in the defaults, so nothing here checks a
 * value again; what a plugin still checks is only what a declaration
 * cannot say (lbvh's bits: 30 or 63, within the range 30..63).
 *
 *     static const plugin_field fields[] = {
 *             PLUGIN_FIELD(struct my_options, bins, "bins", U32),
 *             PLUGIN_FIELD(struct my_options, method, "method", CHOICE),
 *     };
 *     rc = plugin_options_fill(host, ctx, options, OPTION_COUNT, fields,
 *                              FIELD_COUNT, &opt);
 *
 * C++ plugins (the peers) use the same table: PLUGIN_FIELD initialises by
 * position, which C11 and C++17 both take (C++17 has no designated
 * initializers), and the template at the end counts both arrays and
 * checks that the struct is one offsetof may be used on.
 *
 * A static library linked into each plugin that uses it.
 */
#ifndef BVHLAB_PLUGIN_OPTIONS_H
#define BVHLAB_PLUGIN_OPTIONS_H

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

typedef struct plugin_field {
	const char *name; /* the declared option */
	size_t offset;    /* of the field in the plugin's struct */
	int type;         /* enum plugin_field_type */
} plugin_field;

/* By position, in the order of plugin_field's members. */
#define PLUGIN_FIELD(struct_type, member, option_name, field_type) \
	{ option_name, offsetof(struct_type, member), PLUGIN_##field_type }

/*
 * Fills *out from this build's options, one field per entry. 0, or a
 * negative errno after host->set_error when the table does not match the
 * declarations (an undeclared name, a type that does not fit): a mistake
 * in the plugin, never in a config.
 */
int plugin_options_fill(const bvhlab_host *host, bvhlab_build_ctx *ctx,
                        const bvhlab_option_decl *decls, size_t decl_count,
                        const plugin_field *fields, size_t field_count, void *out);

BVHLAB_END_DECLS

#ifdef __cplusplus
#include <type_traits>

/* The C++ form: the counts from the arrays, and only a struct whose
 * offsets offsetof gives (standard layout; default member initialisers
 * are fine, every field of the table is filled anyway). */
template <class Options, size_t DeclCount, size_t FieldCount>
int plugin_options_fill(const bvhlab_host *host, bvhlab_build_ctx *ctx,
                        const bvhlab_option_decl (&decls)[DeclCount],
                        const plugin_field (&fields)[FieldCount], Options &out)
{
	static_assert(std::is_standard_layout<Options>::value,
	              "plugin_options_fill: offsetof needs a standard-layout struct");
	return plugin_options_fill(host, ctx, decls, DeclCount, fields, FieldCount, &out);
}
#endif

#endif /* BVHLAB_PLUGIN_OPTIONS_H */
