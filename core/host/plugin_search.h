/*
 * Finding a plugin's file on the search path (plugin_search.c); the public
 * side (bvhlab_plugin_search_path, bvhlab_plugin_names) is in host.h.
 */
#ifndef BVHLAB_CORE_PLUGIN_SEARCH_H
#define BVHLAB_CORE_PLUGIN_SEARCH_H

#include <stddef.h>

#include <bvhlab/types.h>

/*
 * The file to load for `name`: itself when it contains a '/', ./NAME.so
 * for a bare NAME.so, else NAME.so or NAME/NAME.so in the first folder of
 * the search path that has one. 0, -ENAMETOOLONG, or -ENOENT with a
 * message listing the plugins there are.
 */
int plugin_resolve(const char *name, char *out, size_t size, bvhlab_error *err);

/*
 * The file `name` in the plugin folder's parent, the build tree's root or
 * the install's <libdir>/bvhlab: where bvhlab keeps its own optional
 * modules (bvhlab-images.so), found as the plugins are, from the binary's
 * own file. 0, -ENOENT (no folder) or -ENAMETOOLONG.
 */
int plugin_home_file(const char *name, char *out, size_t size);

#endif /* BVHLAB_CORE_PLUGIN_SEARCH_H */
