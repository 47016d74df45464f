/*
 * The output folder as a whole: one writer at a time (an advisory lock on
 * DIR/.bvhlab.lock, held for the life of the process), and a new folder
 * made whole (a temporary sibling, renamed into place) under a name that
 * nothing reading parts or results can mistake for a results folder.
 */
#include <dirent.h>
#include <errno.h>
#include <fcntl.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/file.h>
#include <sys/stat.h>
#include <time.h>
#include <unistd.h>

#include "output/results.h"
#include "util/util.h"

#define LOCK_NAME ".bvhlab.lock"
/* A new folder's temporary sibling: hidden (shell globs such as
 * `parts/NAME`, `plan --missing` and merge's listing skip it) and of a fixed
 * length, so any folder name that fits NAME_MAX can be made. */
#define TEMP_PREFIX ".bvhlab-new-"
/* A temporary folder without a lock file yet is another process's, just
 * made, unless it is older than this. */
#define UNLOCKED_GRACE_S 600

int results_make_dirs(const char *path, bvhlab_error *err)
{
	char buf[4096];
	if ((size_t)snprintf(buf, sizeof(buf), "%s", path) >= sizeof(buf)) {
		error_set(err, "output folder name too long: %s", path);
		return -ENAMETOOLONG;
	}
	for (char *p = buf + 1;; p++) {
		char c = *p;
		if (c != '/' && c != '\0')
			continue;
		*p = '\0';
		if (mkdir(buf, 0777) < 0 && errno != EEXIST) {
			int e = errno;
			error_set(err, "cannot create output folder %s: %s", buf, strerror(e));
			return -e;
		}
		*p = c;
		if (c == '\0')
			return 0;
	}
}

void results_normalise_dir(char *dir)
{
	size_t n = strlen(dir);
	for (;;) {
		while (n > 1 && dir[n - 1] == '/')
			dir[--n] = '\0';
		if (n > 2 && strcmp(dir + n - 2, "/.") == 0)
			dir[n -= 2] = '\0';
		else if (n == 1 && dir[0] == '.')
			return;
		else
			break;
	}
}

/* The pid the holder of the lock wrote into it, as text ("?" if none). */
static void holder_pid(int fd, char *buf, size_t size)
{
	ssize_t n = pread(fd, buf, size - 1, 0);
	buf[n > 0 ? n : 0] = '\0';
	buf[strcspn(buf, "\n")] = '\0';
	if (!buf[0])
		snprintf(buf, size, "?");
}

/* Locks the open lock file fd (without waiting) and writes our pid into it. */
static int take(int fd, const char *dir, bvhlab_error *err)
{
	char pid[32];
	if (flock(fd, LOCK_EX | LOCK_NB) < 0) {
		int e = errno;
		if (e != EWOULDBLOCK) {
			error_set(err, "cannot lock output folder %s: %s", dir, strerror(e));
			return -e;
		}
		holder_pid(fd, pid, sizeof(pid));
		error_set(err, "output folder %s is in use by another bvhlab (pid %s): one writer "
		          "per folder; wait for it to end or write elsewhere (--out)", dir, pid);
		return -EBUSY;
	}
	int n = snprintf(pid, sizeof(pid), "%ld\n", (long)getpid());
	if (ftruncate(fd, 0) < 0 || pwrite(fd, pid, (size_t)n, 0) != n) {
		int e = errno ? errno : EIO;
		error_set(err, "cannot write the lock of output folder %s: %s", dir, strerror(e));
		return -e;
	}
	return 0;
}

/* dir's lock into *fd; -ENOENT quietly when dir does not exist. */
static int lock_existing(const char *dir, int *fd, bvhlab_error *err)
{
	char path[4096];
	if ((size_t)snprintf(path, sizeof(path), "%s/" LOCK_NAME, dir) >= sizeof(path)) {
		error_set(err, "output folder name too long: %s", dir);
		return -ENAMETOOLONG;
	}
	*fd = open(path, O_RDWR | O_CREAT | O_NOFOLLOW | O_CLOEXEC, 0644);
	if (*fd < 0) {
		int e = errno;
		if (e != ENOENT)
			error_set(err, "cannot lock output folder %s: %s", dir, strerror(e));
		return -e;
	}
	int r = take(*fd, dir, err);
	if (r < 0) {
		close(*fd);
		*fd = -1;
	}
	return r;
}

int results_lock(struct results *res, bvhlab_error *err)
{
	if (res->locked)
		return 0;
	int r = lock_existing(res->dir, &res->lock_fd, err);
	res->locked = r == 0;
	return r == -ENOENT ? 0 : r;
}

void results_unlock(struct results *res)
{
	if (res->locked)
		close(res->lock_fd);
	res->locked = false;
}

/*
 * The lock of a folder being made, created already locked (as a unique
 * name, renamed to the lock's), so that no sweep ever sees it unlocked
 * while its owner lives.
 */
static int lock_new(const char *tmp, int *fd, bvhlab_error *err)
{
	char path[4096], final[4096];
	if ((size_t)snprintf(path, sizeof(path), "%s/.lock-XXXXXX", tmp) >= sizeof(path) ||
	    (size_t)snprintf(final, sizeof(final), "%s/" LOCK_NAME, tmp) >= sizeof(final)) {
		error_set(err, "output folder name too long: %s", tmp);
		return -ENAMETOOLONG;
	}
	*fd = mkostemp(path, O_CLOEXEC);
	int r = *fd < 0 ? -errno : take(*fd, tmp, err);
	if (r == 0 && rename(path, final) < 0)
		r = -errno;
	if (r < 0 && !err->message[0])
		error_set(err, "cannot lock new output folder %s: %s", tmp, strerror(-r));
	return r;
}

/* Removes a temporary folder's files (only plain files: what bvhlab writes
 * there) and the folder; a part that will not go is left. */
static void remove_temp(const char *path)
{
	char file[4096];
	DIR *d = opendir(path);
	for (struct dirent *e; d && (e = readdir(d));)
		if (strcmp(e->d_name, ".") && strcmp(e->d_name, "..") &&
		    (size_t)snprintf(file, sizeof(file), "%s/%s", path, e->d_name) < sizeof(file))
			unlink(file);
	if (d)
		closedir(d);
	rmdir(path);
}

/* A temporary folder whose maker is gone: its lock is free, or it has
 * none and is old. Checked under the lock, which is then kept until the
 * folder is gone. */
static bool abandoned(const char *path, int *fd)
{
	char lock[4096];
	struct stat st;
	if ((size_t)snprintf(lock, sizeof(lock), "%s/" LOCK_NAME, path) >= sizeof(lock))
		return false;
	*fd = open(lock, O_RDWR | O_NOFOLLOW | O_CLOEXEC);
	if (*fd >= 0)
		return flock(*fd, LOCK_EX | LOCK_NB) == 0;
	return errno == ENOENT && lstat(path, &st) == 0 && S_ISDIR(st.st_mode) &&
	       time(NULL) - st.st_mtime > UNLOCKED_GRACE_S;
}

void results_sweep_temps(const char *parent)
{
	char path[4096];
	DIR *d = opendir(parent);
	for (struct dirent *e; d && (e = readdir(d));) {
		int fd = -1;
		if (strncmp(e->d_name, TEMP_PREFIX, strlen(TEMP_PREFIX)) != 0 ||
		    (size_t)snprintf(path, sizeof(path), "%s/%s", parent, e->d_name) >= sizeof(path))
			continue;
		if (abandoned(path, &fd))
			remove_temp(path);
		if (fd >= 0)
			close(fd);
	}
	if (d)
		closedir(d);
}

/* The parent of dir ("." for a bare name) into buf. */
static void parent_of(const char *dir, char *buf, size_t size)
{
	const char *slash = strrchr(dir, '/');
	if (!slash)
		snprintf(buf, size, ".");
	else if (slash == dir)
		snprintf(buf, size, "/");
	else
		snprintf(buf, size, "%.*s", (int)(slash - dir), dir);
}

/* The temporary folder tmp did not become dir: another process made dir
 * first, or the rename failed. */
static int not_renamed(struct results *res, int e, bvhlab_error *err)
{
	int fd = -1;
	if (e == ENOTEMPTY || e == EEXIST) {
		int r = lock_existing(res->dir, &fd, err);
		if (fd >= 0)
			close(fd);
		if (r == -EBUSY)
			return r;
		error_set(err, "output folder %s was made by another process while this one "
		          "started; run again (--resume or --force)", res->dir);
		return -EEXIST;
	}
	error_set(err, "cannot create output folder %s: %s", res->dir, strerror(e));
	return -e;
}

/*
 * A new results folder appears whole: written as a temporary sibling and
 * renamed into place (over an empty folder too). A sweep killed while it
 * starts (GNU parallel stopping its jobs) leaves no folder, or one with a
 * results.json that says which plan it belongs to, never a bare folder
 * that `bvhlab merge` must refuse; its hidden temporary folder is swept by
 * the next sweep that starts beside it.
 */
static int write_fresh(struct results *res, bvhlab_error *err)
{
	char tmp[4096], parent[4096];
	parent_of(res->dir, parent, sizeof(parent));
	if ((size_t)snprintf(tmp, sizeof(tmp), "%s/" TEMP_PREFIX "XXXXXX", parent) >= sizeof(tmp)) {
		error_set(err, "output folder name too long: %s", res->dir);
		return -ENAMETOOLONG;
	}
	int r = results_make_dirs(parent, err);
	results_sweep_temps(parent);
	if (r == 0 && !mkdtemp(tmp)) {
		r = -errno;
		error_set(err, "cannot create output folder %s: %s", res->dir, strerror(-r));
	}
	if (r < 0)
		return r;
	int fd = -1;
	r = lock_new(tmp, &fd, err);
	struct results t = *res;
	t.dir = tmp;
	if (r == 0)
		r = results_write_renderings(&t, err);
	if (r == 0 && rename(tmp, res->dir) < 0)
		r = not_renamed(res, errno, err);
	if (r < 0) {
		remove_temp(tmp);
		if (fd >= 0)
			close(fd);
		return r;
	}
	res->lock_fd = fd;
	res->locked = true;
	return 0;
}

int results_write(struct results *res, bvhlab_error *err)
{
	struct stat st;
	if (!res->locked && stat(res->dir, &st) < 0 && errno == ENOENT)
		return write_fresh(res, err);
	int r = results_lock(res, err);
	return r < 0 ? r : results_write_renderings(res, err);
}
