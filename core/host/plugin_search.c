/*
 * The plugin search path: finding a plugin's file by name, and listing the
 * names there are (for `bvhlab list` and for the message when a name is
 * not found). Loading what was found is plugin.c.
 */
#include <dirent.h>
#include <errno.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>

#include <bvhlab/host.h>

#include "host/plugin_search.h"
#include "util/util.h"

struct names {
	char **v;
	size_t n, cap;
};

static bool contains(const struct names *ns, const char *name)
{
	for (size_t k = 0; k < ns->n; k++)
		if (strcmp(ns->v[k], name) == 0)
			return true;
	return false;
}

static int add(struct names *ns, const char *name, size_t len)
{
	char buf[256];
	if (len == 0 || len >= sizeof(buf))
		return 0;
	memcpy(buf, name, len);
	buf[len] = '\0';
	if (contains(ns, buf))
		return 0;
	if (ns->n + 2 > ns->cap) {
		size_t cap = ns->cap ? 2 * ns->cap : 16;
		char **v = realloc(ns->v, cap * sizeof(*v));
		if (!v)
			return -ENOMEM;
		ns->v = v;
		ns->cap = cap;
	}
	if (!(ns->v[ns->n] = strdup(buf)))
		return -ENOMEM;
	ns->v[++ns->n] = NULL;
	return 0;
}

static bool has_so_suffix(const char *s, size_t *stem)
{
	size_t n = strlen(s);
	*stem = n > 3 ? n - 3 : 0;
	return n > 3 && strcmp(s + n - 3, ".so") == 0;
}

/*
 * A plugin one folder down is NAME/NAME.so, or a family's member: folder
 * FAMILY holds FAMILY_*.so (the build tree's plugins/sah/ holds sah_seq.so,
 * sah_even.so, ...). Other files there are not plugins (the tests' folders
 * of crashing and hanging libraries are not named after them).
 */
static bool in_family(const char *folder, const char *file, size_t stem)
{
	size_t n = strlen(folder);
	return strncmp(file, folder, n) == 0 && (stem == n || (stem > n + 1 && file[n] == '_'));
}

/* NAME.so directly in dir, or a plugin one folder down (in_family). */
static int scan_dir(struct names *ns, const char *dir, const char *family)
{
	DIR *d = opendir(dir);
	if (!d)
		return 0; /* a missing search folder is normal (not installed) */
	int r = 0;
	struct dirent *e;
	while (r == 0 && (e = readdir(d))) {
		size_t stem;
		char path[4096];
		if (e->d_name[0] == '.')
			continue;
		if (has_so_suffix(e->d_name, &stem)) {
			if (!family || in_family(family, e->d_name, stem))
				r = add(ns, e->d_name, stem);
			continue;
		}
		int n = snprintf(path, sizeof(path), "%s/%s", dir, e->d_name);
		if (!family && n > 0 && (size_t)n < sizeof(path))
			r = scan_dir(ns, path, e->d_name);
	}
	closedir(d);
	return r;
}

static int cmp_names(const void *a, const void *b)
{
	return strcmp(*(char *const *)a, *(char *const *)b);
}

int bvhlab_plugin_names(char ***out, bvhlab_error *err)
{
	/* Allocated up front so an empty result is still a NULL-terminated array. */
	struct names ns = {.v = calloc(16, sizeof(char *)), .cap = 16};
	const char *sp = bvhlab_plugin_search_path();
	int r = ns.v ? 0 : -ENOMEM;
	for (const char *p = sp; r == 0 && *p;) {
		const char *colon = strchr(p, ':');
		size_t len = colon ? (size_t)(colon - p) : strlen(p);
		char dir[4096];
		if (len > 0 && len < sizeof(dir)) {
			memcpy(dir, p, len);
			dir[len] = '\0';
			r = scan_dir(&ns, dir, NULL);
		}
		p += len + (colon ? 1 : 0);
	}
	if (r < 0 || !ns.v) {
		bvhlab_plugin_names_free(ns.v);
		error_set(err, "listing plugins: out of memory");
		return -ENOMEM;
	}
	qsort(ns.v, ns.n, sizeof(*ns.v), cmp_names);
	*out = ns.v;
	return 0;
}

void bvhlab_plugin_names_free(char **names)
{
	if (!names)
		return;
	for (char **p = names; *p; p++)
		free(*p);
	free(names);
}

/* ---- finding one plugin ------------------------------------------------------- */

/* bvhlab_plugin_search_path: plugin_path.c (where the build tree is). */

static bool is_file(const char *path)
{
	struct stat st;
	return stat(path, &st) == 0 && S_ISREG(st.st_mode);
}

static bool ends_in_so(const char *s)
{
	size_t n = strlen(s);
	return n > 3 && strcmp(s + n - 3, ".so") == 0;
}

/* Finds NAME.so, NAME/NAME.so or, for NAME = FAMILY_REST, FAMILY/NAME.so
 * (any '_' may end the family's name) in a search folder; 0 and *out, or
 * -ENOENT. */
static int find_in_dir(const char *dir, size_t dirlen, const char *name, char *out,
                       size_t size)
{
	if (dirlen == 0)
		return -ENOENT;
	int n = snprintf(out, size, "%.*s/%s.so", (int)dirlen, dir, name);
	if (n > 0 && (size_t)n < size && is_file(out))
		return 0;
	n = snprintf(out, size, "%.*s/%s/%s.so", (int)dirlen, dir, name, name);
	if (n > 0 && (size_t)n < size && is_file(out))
		return 0;
	for (const char *u = strchr(name, '_'); u; u = strchr(u + 1, '_')) {
		n = snprintf(out, size, "%.*s/%.*s/%s.so", (int)dirlen, dir, (int)(u - name),
		             name, name);
		if (u > name && n > 0 && (size_t)n < size && is_file(out))
			return 0;
	}
	return -ENOENT;
}

/* Names what there is to choose from: a typo is then plain to see. */
static void not_found(const char *name, bvhlab_error *err)
{
	char list[300] = "";
	char **names = NULL;
	size_t used = 0;
	if (bvhlab_plugin_names(&names, NULL) == 0) {
		for (char **p = names; *p && used < sizeof(list); p++)
			used += (size_t)snprintf(list + used, sizeof(list) - used, "%s%s",
			                         p == names ? "" : ", ", *p);
		if (used >= sizeof(list)) /* a long list: say it goes on */
			memcpy(list + sizeof(list) - 4, "...", 4);
		bvhlab_plugin_names_free(names);
	}
	error_set(err, "plugin '%s' not found on the search path %s (available: %s)", name,
	          bvhlab_plugin_search_path(), used ? list : "none");
}

/*
 * A name with a '/' is a path; a bare NAME.so is a file in the current
 * folder (as a config's is one in the config's folder), never left to
 * dlopen, which would look for it in LD_LIBRARY_PATH and the system's
 * library folders. Anything else is looked up on the search path.
 */
int plugin_resolve(const char *name, char *out, size_t size, bvhlab_error *err)
{
	if (strchr(name, '/') || ends_in_so(name)) {
		const char *here = strchr(name, '/') ? "" : "./";
		if ((size_t)snprintf(out, size, "%s%s", here, name) >= size) {
			error_set(err, "plugin '%s': path too long", name);
			return -ENAMETOOLONG;
		}
		return 0;
	}
	const char *sp = bvhlab_plugin_search_path();
	for (const char *p = sp; *p;) {
		const char *colon = strchr(p, ':');
		size_t len = colon ? (size_t)(colon - p) : strlen(p);
		if (find_in_dir(p, len, name, out, size) == 0)
			return 0;
		p += len + (colon ? 1 : 0);
	}
	not_found(name, err);
	return -ENOENT;
}
