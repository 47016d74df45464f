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
#include <errno.h>
#include <limits.h>
#include <stdbool.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>
#include <unistd.h>

#include <bvhlab/host.h>

#ifndef BVHLAB_INSTALL_PLUGIN_DIR
#define BVHLAB_INSTALL_PLUGIN_DIR ""
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

const char *bvhlab_plugin_search_path(void)
{
	static char path[3 * PATH_MAX];
	char tree[PATH_MAX + 16];
	const char *env = getenv("BVHLAB_PLUGIN_PATH");
	build_tree_plugins(tree, sizeof(tree));
	snprintf(path, sizeof(path), "%s%s%s%s%s", env ? env : "", env && *env ? ":" : "", tree,
	         *tree ? ":" : "", BVHLAB_INSTALL_PLUGIN_DIR);
	return path;
}
