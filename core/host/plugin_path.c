/*
 * The plugin search path: $BVHLAB_PLUGIN_PATH, the build tree's plugins/
 * (only for a binary that runs from a build tree) and the install folder.
 *
 * The build tree is found from /proc/self/exe, never compiled in: an
 * installed binary that searched a compiled-in build path would load
 * whatever anyone who can recreate that path puts there. A folder counts
 * as the binary's build tree when it is the binary's folder or one of its
 * two parents (app/, tests/, tests/cli/), holds meson-private/ and
 * plugins/, and all three belong to the binary's owner: a folder someone
 * else made (a planted /tmp/meson-private) is not trusted.
 */
#include <dlfcn.h>
#include <errno.h>
#include <limits.h>
#include <stdbool.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>
#include <unistd.h>

#include <bvhlab/host.h>

#include "host/plugin_search.h"

/*
 * Where an install keeps its plugins, relative to the install prefix, and
 * where the bvhlab command and the library sit relative to it (meson's
 * libdir/bvhlab/plugins, bindir, libdir). The prefix itself is found at run
 * time from the binary's own file, so an install staged with --destdir or
 * moved elsewhere finds its plugins; an absolute bindir or libdir (outside
 * the prefix) leaves the install folder as configured.
 */
#ifndef BVHLAB_INSTALL_PLUGIN_DIR
#define BVHLAB_INSTALL_PLUGIN_DIR ""
#endif
#ifndef BVHLAB_INSTALL_PREFIX
#define BVHLAB_INSTALL_PREFIX ""
#endif
#ifndef BVHLAB_INSTALL_BINDIR
#define BVHLAB_INSTALL_BINDIR "bin"
#endif
#ifndef BVHLAB_INSTALL_LIBDIR
#define BVHLAB_INSTALL_LIBDIR "lib"
#endif

#define TREE_LEVELS 3 /* the binary's folder and two parents */

static bool owned_dir(const char *path, uid_t owner)
{
	struct stat st;
	return lstat(path, &st) == 0 && S_ISDIR(st.st_mode) && st.st_uid == owner;
}

static bool is_build_root(const char *dir, uid_t owner)
{
	char sub[PATH_MAX + 32];
	if (!owned_dir(dir, owner))
		return false;
	snprintf(sub, sizeof(sub), "%s/meson-private", dir);
	if (!owned_dir(sub, owner))
		return false;
	snprintf(sub, sizeof(sub), "%s/plugins", dir);
	return owned_dir(sub, owner);
}

/* <build root>/plugins when this binary runs from a build tree, else "". */
static void build_tree_plugins(char *out, size_t size)
{
	char exe[PATH_MAX];
	struct stat st;
	ssize_t n = readlink("/proc/self/exe", exe, sizeof(exe) - 1);
	out[0] = '\0';
	if (n <= 0 || stat("/proc/self/exe", &st) != 0)
		return;
	exe[n] = '\0';
	for (int level = 0; level < TREE_LEVELS; level++) {
		char *slash = strrchr(exe, '/');
		if (!slash || slash == exe)
			return;
		*slash = '\0';
		if (is_build_root(exe, st.st_uid)) {
			snprintf(out, size, "%s/plugins", exe);
			return;
		}
	}
}

/* How many folders deep a relative path is ("lib/x86_64-linux-gnu": 2). */
static int depth(const char *rel)
{
	int n = 0;
	for (const char *p = rel; *p; p++)
		if (*p != '/' && (p == rel || p[-1] == '/'))
			n++;
	return n;
}

/* Removes the last `levels` components of path in place; false if too few. */
static bool strip_levels(char *path, int levels)
{
	for (int k = 0; k <= levels; k++) { /* the file's own name, then the folders */
		char *slash = strrchr(path, '/');
		if (!slash || slash == path)
			return false;
		*slash = '\0';
	}
	return true;
}

/*
 * The install's plugin folder from where this code was loaded: the shared
 * library (LIBDIR/libbvhlab.so.*) or, linked statically, the command
 * (BINDIR/bvhlab). Their folder less LIBDIR's or BINDIR's depth is the
 * prefix.
 */
static void install_plugins(char *out, size_t size)
{
	Dl_info info;
	char self[PATH_MAX];
	const char *plugins = BVHLAB_INSTALL_PLUGIN_DIR;
	if (plugins[0] == '/') {
		snprintf(out, size, "%s", plugins);
		return;
	}
	snprintf(out, size, "%s/%s", BVHLAB_INSTALL_PREFIX, plugins); /* as configured */
	if (BVHLAB_INSTALL_BINDIR[0] == '/' || BVHLAB_INSTALL_LIBDIR[0] == '/')
		return;
	bool in_library = dladdr((void *)bvhlab_plugin_search_path, &info) && info.dli_fname &&
	                  strstr(info.dli_fname, ".so") && realpath(info.dli_fname, self);
	if (!in_library) {
		ssize_t n = readlink("/proc/self/exe", self, sizeof(self) - 1);
		if (n <= 0)
			return;
		self[n] = '\0';
	}
	if (!strip_levels(self, depth(in_library ? BVHLAB_INSTALL_LIBDIR : BVHLAB_INSTALL_BINDIR)))
		return;
	int n = snprintf(out, size, "%s/%s", self, plugins);
	if (n < 0 || (size_t)n >= size) /* no usable path: none rather than a cut one */
		out[0] = '\0';
}

/* The build tree's plugins/ when this binary runs from one, else the
 * install's plugin folder. */
static void home_plugins(char *out, size_t size)
{
	build_tree_plugins(out, size);
	if (!*out)
		install_plugins(out, size);
}

int plugin_home_file(const char *name, char *out, size_t size)
{
	char dir[PATH_MAX + 16];
	home_plugins(dir, sizeof(dir));
	char *slash = strrchr(dir, '/');
	if (!slash)
		return -ENOENT;
	*slash = '\0';
	int n = snprintf(out, size, "%s/%s", dir, name);
	return n < 0 || (size_t)n >= size ? -ENAMETOOLONG : 0;
}

/* $BVHLAB_PLUGIN_PATH, then the build tree's plugins/ when this binary runs
 * from one, else the install's. */
const char *bvhlab_plugin_search_path(void)
{
	static char path[3 * PATH_MAX];
	char tree[PATH_MAX + 16];
	const char *env = getenv("BVHLAB_PLUGIN_PATH");
	home_plugins(tree, sizeof(tree));
	snprintf(path, sizeof(path), "%s%s%s", env ? env : "", env && *env && *tree ? ":" : "",
	         tree);
	return path;
}
