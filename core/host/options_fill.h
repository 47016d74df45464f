/*
 * The plugin's own options struct (ABI 1.6 fill_options), filled once when
 * the options are checked: build.c holds the context a plugin's call needs,
 * options.c decides when.
 */
#ifndef BVHLAB_HOST_OPTIONS_FILL_H
#define BVHLAB_HOST_OPTIONS_FILL_H

#include <bvhlab/host.h>

/* Calls the plugin's fill_options on opts (nothing without one) into a
 * fresh opts->filled: 0, -EINVAL with the plugin's message naming it, or
 * -ENOMEM. */
int options_fill(bvhlab_options *opts, bvhlab_error *err);

#endif /* BVHLAB_HOST_OPTIONS_FILL_H */
