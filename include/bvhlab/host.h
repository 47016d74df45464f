/*
 * bvhlab — the host side of the plugin ABI (builder.h): finding and loading
 * builder plugins, resolving their options, and running one build. What
 * threads = 0 means and thread pinning are machine.h.
 */
#ifndef BVHLAB_HOST_H
#define BVHLAB_HOST_H

#include <stdbool.h>
#include <stdint.h>

#include "builder.h"
#include "tree.h"
#include "types.h"

BVHLAB_BEGIN_DECLS

/* A loaded, checked plugin. Opaque. */
typedef struct bvhlab_plugin bvhlab_plugin;

/*
 * Opens a plugin by file path (anything containing '/' or ending in ".so")
 * or by name, looked up as NAME.so and NAME/NAME.so in each folder of the
 * search path: $BVHLAB_PLUGIN_PATH (':'-separated), the build tree's plugin
 * folder, the install folder. Checks the entry symbol, the ABI major, the
 * descriptor's struct_size, its build function and option declarations.
 * Every failure is one message naming the plugin and the problem.
 */
int bvhlab_plugin_open(const char *name_or_path, bvhlab_plugin **out, bvhlab_error *err);
void bvhlab_plugin_close(bvhlab_plugin *plugin);

const bvhlab_builder *bvhlab_plugin_builder(const bvhlab_plugin *plugin);
/* A descriptor's refine function (ABI 1.2), or NULL: NULL too for a
 * plugin built against an older minor, whose descriptor has no such field. */
typedef int (*bvhlab_refine_fn)(const bvhlab_host *host, bvhlab_build_ctx *ctx,
                                const bvhlab_build_input *input, bvhlab_build_output *tree);
bvhlab_refine_fn bvhlab_builder_refine(const bvhlab_builder *b);
/* A descriptor's update function (ABI 1.4), or NULL: NULL too for a
 * plugin built against an older minor. Same signature as refine. */
bvhlab_refine_fn bvhlab_builder_update(const bvhlab_builder *b);
/* Whether the descriptor's build takes boxes (BVHLAB_BUILDER_BOXES, ABI
 * 1.5; false for a plugin built against an older minor). bvhlab_build
 * refuses a box input to any other by name. */
bool bvhlab_builder_takes_boxes(const bvhlab_builder *b);
/* A descriptor's fill_options (ABI 1.6), or NULL: NULL too for a plugin
 * built against an older minor. */
typedef int (*bvhlab_fill_options_fn)(const bvhlab_host *host, bvhlab_build_ctx *ctx, void *out);
bvhlab_fill_options_fn bvhlab_builder_fill_options(const bvhlab_builder *b);
/* Whether the descriptor's INT options' `choices` are meant (ABI 1.6). */
bool bvhlab_builder_int_choices(const bvhlab_builder *b);
/* The bytes per primitive a build with the options `filled` (its
 * fill_options struct, or NULL) declares: peak_bytes_for's answer, else
 * peak_bytes_per_prim (ABI 1.7), else BVHLAB_UNDECLARED_BYTES_PER_PRIM when
 * it declares none (0, or a plugin built against an older minor);
 * *declared says which. */
uint32_t bvhlab_builder_peak_bytes_per_prim(const bvhlab_builder *b, const void *filled,
                                            bool *declared);
/* The file the plugin was loaded from. */
const char *bvhlab_plugin_path(const bvhlab_plugin *plugin);

/*
 * Names of the plugins found on the search path, sorted, without duplicates
 * (the first folder wins). *names is a NULL-terminated array; free it with
 * bvhlab_plugin_names_free.
 */
int bvhlab_plugin_names(char ***names, bvhlab_error *err);
void bvhlab_plugin_names_free(char **names);

/* The search path as one ':'-separated string (static storage, not thread-safe). */
const char *bvhlab_plugin_search_path(void);

/* ---- options --------------------------------------------------------------- */

typedef struct bvhlab_option_value {
	uint32_t type; /* enum bvhlab_option_type */
	bool b;
	int64_t i;
	double f;
	char *s;
} bvhlab_option_value;

/* A builder's option values: one per declaration, defaults filled in. */
typedef struct bvhlab_options {
	const bvhlab_builder *builder;
	bvhlab_option_value *values; /* [builder->option_count] */
	/* The plugin's own options struct (ABI 1.6 fill_options), filled by
	 * bvhlab_options_check from these values and given to every build;
	 * NULL before the check, after any setter, or for a plugin without
	 * fill_options. */
	void *filled;
} bvhlab_options;

int bvhlab_options_init(bvhlab_options *opts, const bvhlab_builder *builder);
void bvhlab_options_finish(bvhlab_options *opts);

/* Index of a declared option, or -1. */
int bvhlab_options_find(const bvhlab_options *opts, const char *name);

/*
 * Typed setters: -ENOENT for an unknown key (message lists the declared
 * ones), -EINVAL for a wrong type, a value out of range or not a choice.
 * Messages name the key and the builder.
 */
int bvhlab_options_set_bool(bvhlab_options *opts, const char *key, bool v, bvhlab_error *err);
int bvhlab_options_set_int(bvhlab_options *opts, const char *key, int64_t v, bvhlab_error *err);
int bvhlab_options_set_float(bvhlab_options *opts, const char *key, double v, bvhlab_error *err);
int bvhlab_options_set_string(bvhlab_options *opts, const char *key, const char *v,
                              bvhlab_error *err);

/*
 * What no single declaration states, checked once all are set (when a
 * config or a command line is read): an INT or FLOAT pair min_NAME /
 * max_NAME needs min_NAME <= max_NAME; then the plugin's fill_options (ABI
 * 1.6) reads the values into its own struct, kept in opts->filled for
 * every build, and checks its own rules. -EINVAL with a message naming the
 * plugin and the option(s), -ENOMEM. (The setters refuse an empty string
 * for a STRING option whose default is not empty.)
 */
int bvhlab_options_check(bvhlab_options *opts, bvhlab_error *err);

/* Parses "key=value" text (command line), by the declared type. */
int bvhlab_options_parse(bvhlab_options *opts, const char *assignment, bvhlab_error *err);

/* Writes the value as JSON text ("sweep", 32, 1.5, true) into buf. */
void bvhlab_option_format(const bvhlab_option_value *v, char *buf, size_t size);

/* ---- building ---------------------------------------------------------- */

/*
 * Runs the plugin's build once on `input` with `threads` threads (0:
 * bvhlab_hardware_threads(), machine.h) into `tree`, which is (re)sized to the usual bound first.
 * Returns 0, or the plugin's negative errno with its message (or a generic
 * one naming the plugin) in err. Does not validate.
 */
int bvhlab_build(const bvhlab_plugin *plugin, const bvhlab_options *opts,
                 const bvhlab_build_input *input, uint32_t threads, bvhlab_tree *tree,
                 bvhlab_error *err);

/*
 * Runs the plugin's refine function (ABI 1.2) once on `tree`, a valid tree
 * over `input` (from bvhlab_build), with `threads` threads (0: all), in
 * place. -ENOTSUP when the plugin does not refine. Returns 0, or the
 * plugin's negative errno with its message in err. Does not validate.
 */
int bvhlab_refine(const bvhlab_plugin *plugin, const bvhlab_options *opts,
                  const bvhlab_build_input *input, uint32_t threads, bvhlab_tree *tree,
                  bvhlab_error *err);

/*
 * Runs the plugin's update function (ABI 1.4) once on `tree`, a valid tree
 * over primitives of the same count and order as `input`'s, which moved.
 * -ENOTSUP when the plugin has no update; -EINVAL, with a message naming
 * both counts, when the tree's references cannot be `input`'s primitives
 * (fewer references than primitives, or one past the last). Returns 0, or
 * the plugin's negative errno with its message in err. Does not validate.
 */
int bvhlab_update(const bvhlab_plugin *plugin, const bvhlab_options *opts,
                  const bvhlab_build_input *input, uint32_t threads, bvhlab_tree *tree,
                  bvhlab_error *err);

BVHLAB_END_DECLS

#endif /* BVHLAB_HOST_H */
