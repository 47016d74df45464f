/* Listing the plugins on the search path, for `bvhlab list` and messages. */
#include <dirent.h>
#include <errno.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>

#include <bvhlab/host.h>

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

/* NAME.so directly in dir, or NAME/NAME.so one level down. */
static int scan_entry(struct names *ns, const char *dir, const struct dirent *e)
{
	size_t stem;
	if (e->d_name[0] == '.')
		return 0;
	if (has_so_suffix(e->d_name, &stem))
		return add(ns, e->d_name, stem);
	char path[4096];
	struct stat st;
	int n = snprintf(path, sizeof(path), "%s/%s/%s.so", dir, e->d_name, e->d_name);
	if (n > 0 && (size_t)n < sizeof(path) && stat(path, &st) == 0 && S_ISREG(st.st_mode))
		return add(ns, e->d_name, strlen(e->d_name));
	return 0;
}

static int scan_dir(struct names *ns, const char *dir)
{
	DIR *d = opendir(dir);
	if (!d)
		return 0; /* a missing search folder is normal (not installed) */
	int r = 0;
	struct dirent *e;
	while (r == 0 && (e = readdir(d)))
		r = scan_entry(ns, dir, e);
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
			r = scan_dir(&ns, dir);
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
