/*
 * Creating, replacing and moving aside the files of an output folder
 * without following links and without losing a complete file.
 */
#include <dirent.h>
#include <errno.h>
#include <fcntl.h>
#include <stdbool.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>
#include <unistd.h>

#include "output/safe_file.h"
#include "util/util.h"

#define PATH_SIZE 4096
/* Far more generations than anyone keeps; the bound only stops a loop. */
#define MAX_GENERATION 100000u

int safe_create(const char *path)
{
	/* Two tries: a link planted between unlink and open is refused, once. */
	for (int attempt = 0; attempt < 2; attempt++) {
		if (unlink(path) < 0 && errno != ENOENT)
			return -errno;
		int fd = open(path, O_WRONLY | O_CREAT | O_EXCL | O_NOFOLLOW | O_CLOEXEC, 0644);
		if (fd >= 0)
			return fd;
		if (errno != EEXIST)
			return -errno;
	}
	return -EEXIST;
}

int safe_write_all(int fd, const void *data, size_t len)
{
	const char *p = data;
	while (len > 0) {
		ssize_t n = write(fd, p, len);
		if (n < 0 && errno == EINTR)
			continue;
		if (n < 0)
			return -errno;
		if (n == 0)
			return -EIO;
		p += n;
		len -= (size_t)n;
	}
	return 0;
}

int safe_write_parts(const char *path, const struct safe_part *parts, size_t count)
{
	int fd = safe_create(path);
	if (fd < 0)
		return fd;
	int r = 0;
	for (size_t k = 0; r == 0 && k < count; k++)
		r = safe_write_all(fd, parts[k].data, parts[k].len);
	if (close(fd) < 0 && r == 0)
		r = -errno;
	if (r < 0)
		unlink(path);
	return r;
}

/* Data, then fsync: on disk before the rename makes it visible. */
static int fill(const char *tmp, const void *data, size_t len)
{
	int fd = safe_create(tmp);
	if (fd < 0)
		return fd;
	int r = safe_write_all(fd, data, len);
	if (r == 0 && fsync(fd) < 0)
		r = -errno;
	if (close(fd) < 0 && r == 0)
		r = -errno;
	return r;
}

int safe_write_file(const char *dir, const char *name, const void *data, size_t len,
                    bvhlab_error *err)
{
	char path[PATH_SIZE], tmp[PATH_SIZE];
	if ((size_t)snprintf(path, sizeof(path), "%s/%s", dir, name) >= sizeof(path) ||
	    (size_t)snprintf(tmp, sizeof(tmp), "%s/.%s.tmp", dir, name) >= sizeof(tmp)) {
		error_set(err, "path too long: %s/%s", dir, name);
		return -ENAMETOOLONG;
	}
	int r = fill(tmp, data, len);
	if (r == 0 && rename(tmp, path) < 0)
		r = -errno;
	if (r == 0)
		return 0;
	error_set(err, "cannot write %s: %s", path, strerror(-r));
	unlink(tmp);
	return r;
}

static bool exists(const char *path)
{
	struct stat st;
	return lstat(path, &st) == 0 || errno != ENOENT;
}

/* The smallest N for which no dir/LAST.N exists, LAST the commit name. */
static unsigned free_generation(const char *dir, const char *last)
{
	char path[PATH_SIZE];
	for (unsigned n = 1; n < MAX_GENERATION; n++) {
		snprintf(path, sizeof(path), "%s/%s.%u", dir, last, n);
		if (!exists(path))
			return n;
	}
	return 0;
}

static int move_one(const char *from, const char *to);

/* A folder onto one an interrupted move began: its entries one by one. */
static int merge_dir(const char *from, const char *to)
{
	char a[PATH_SIZE], b[PATH_SIZE];
	DIR *d = opendir(from);
	int r = d ? 0 : -errno;
	for (struct dirent *e; r >= 0 && d && (e = readdir(d));) {
		if (!strcmp(e->d_name, ".") || !strcmp(e->d_name, ".."))
			continue;
		if ((size_t)snprintf(a, sizeof(a), "%s/%s", from, e->d_name) >= sizeof(a) ||
		    (size_t)snprintf(b, sizeof(b), "%s/%s", to, e->d_name) >= sizeof(b))
			r = -ENAMETOOLONG;
		else
			r = move_one(a, b);
	}
	if (d)
		closedir(d);
	return r < 0 ? r : rmdir(from) < 0 ? -errno : 1;
}

/*
 * Files by link + unlink (link never overwrites), folders by rename. A
 * target already there is what an interrupted move of the same
 * generation left (its commit file had not moved yet, so nothing newer
 * was written): a file is replaced, a folder joined.
 */
static int move_one(const char *from, const char *to)
{
	struct stat st, old;
	if (lstat(from, &st) < 0)
		return errno == ENOENT ? 0 : -errno;
	bool there = lstat(to, &old) == 0;
	if (S_ISDIR(st.st_mode) && there && S_ISDIR(old.st_mode))
		return merge_dir(from, to);
	if (S_ISDIR(st.st_mode) || there)
		return rename(from, to) < 0 ? -errno : 1;
	if (link(from, to) < 0 || unlink(from) < 0)
		return -errno;
	return 1;
}

int safe_move_aside(const char *dir, const char *const *names, unsigned *moved_to,
                    bvhlab_error *err)
{
	char from[PATH_SIZE], to[PATH_SIZE];
	const char *const *last = names;
	while (last[0] && last[1])
		last++;
	unsigned n = *last ? free_generation(dir, *last) : 1;
	*moved_to = 0;
	if (n == 0) {
		error_set(err, "%s: no free NAME.N to move the old results to", dir);
		return -EEXIST;
	}
	for (const char *const *p = names; *p; p++) {
		if ((size_t)snprintf(from, sizeof(from), "%s/%s", dir, *p) >= sizeof(from) ||
		    (size_t)snprintf(to, sizeof(to), "%s/%s.%u", dir, *p, n) >= sizeof(to)) {
			error_set(err, "path too long: %s/%s", dir, *p);
			return -ENAMETOOLONG;
		}
		int r = move_one(from, to);
		if (r < 0) {
			error_set(err, "cannot move %s aside to %s: %s", from, to, strerror(-r));
			return r;
		}
		if (r > 0)
			*moved_to = n;
	}
	return 0;
}

/* The folder's real path is "/": results.json there would be /results.json. */
static bool is_root(const char *dir)
{
	char *real = realpath(dir, NULL);
	bool root = real && strcmp(real, "/") == 0;
	free(real);
	return root;
}

int safe_claim_output(const char *dir, bool force, bvhlab_error *err)
{
	/* results.json last: while it is in place the folder still holds the
	 * old sweep, so a kill in between leaves nothing a new sweep writes over. */
	static const char *const old[] = {"results.csv", "report.md", "report.html", "images",
	                                  "results.json", NULL};
	char path[PATH_SIZE];
	unsigned moved;
	if (is_root(dir)) {
		error_set(err, "output folder %s is the file system root; name a folder of its own",
		          dir);
		return -EINVAL;
	}
	if ((size_t)snprintf(path, sizeof(path), "%s/results.json", dir) >= sizeof(path)) {
		error_set(err, "output folder name too long: %s", dir);
		return -ENAMETOOLONG;
	}
	if (!exists(path))
		return 0;
	if (!force) {
		error_set(err, "output folder %s already holds a results.json: --resume continues "
		          "that sweep, --force starts afresh (moving the old files aside to "
		          "results.json.N, ...)", dir);
		return -EEXIST;
	}
	int r = safe_move_aside(dir, old, &moved, err);
	if (r == 0 && moved)
		fprintf(stderr, "bvhlab: --force: the old results of %s/ are now results.json.%u "
		        "(and the CSV, reports and images with .%u)\n", dir, moved, moved);
	return r;
}
