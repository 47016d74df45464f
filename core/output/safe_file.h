/*
 * Files the harness writes into an output folder, which it does not own
 * exclusively: anyone with write access there could plant a symlink where
 * a temporary file goes. Nothing here writes through a link or over a file
 * it did not create itself; finished files appear by rename only.
 */
#ifndef BVHLAB_CORE_SAFE_FILE_H
#define BVHLAB_CORE_SAFE_FILE_H

#include <stdbool.h>
#include <stddef.h>

#include <bvhlab/types.h>

/*
 * Creates `path` anew for writing (mode 0644) and returns its descriptor,
 * or a negative errno. Whatever was at `path` (a stale temporary file, a
 * planted symlink) is unlinked first, which removes the link and never
 * touches its target; the file is then made with O_CREAT | O_EXCL |
 * O_NOFOLLOW, so a link planted in between is refused, not followed.
 */
int safe_create(const char *path);

/* All of `len` bytes to fd (EINTR and short writes retried); 0 or -errno. */
int safe_write_all(int fd, const void *data, size_t len);

/* One piece of a file written by safe_write_parts. */
struct safe_part {
	const void *data;
	size_t len;
};

/*
 * `path` made anew (safe_create) holding the parts in order, for a
 * temporary file another process reads: not synced, and removed again
 * when any write fails. 0 or a negative errno.
 */
int safe_write_parts(const char *path, const struct safe_part *parts, size_t count);

/*
 * dir/name = data: written to dir/.name.tmp (safe_create), synced to disk,
 * then renamed over dir/name, so a crash at any moment leaves the old
 * complete file or the new one. 0, or a negative errno with err naming the
 * file.
 */
int safe_write_file(const char *dir, const char *name, const void *data, size_t len,
                    bvhlab_error *err);

/*
 * Moves the files `names` (NULL-terminated; missing ones are skipped) of
 * dir aside to NAME.N, one N for all of them, in order. The last name is
 * the commit point, moved last: N is the smallest that it does not use
 * yet, and a NAME.N of another name already there is what an interrupted
 * move of this generation left, replaced (a file) or joined (a folder).
 * Otherwise nothing is overwritten (link + unlink). *moved_to gets N, or 0
 * when there was nothing to move.
 */
int safe_move_aside(const char *dir, const char *const *names, unsigned *moved_to,
                    bvhlab_error *err);

/*
 * Makes `dir` (and its parents) the output folder of a fresh sweep. One
 * that already holds a results.json is refused (-EEXIST, err naming the
 * folder, --resume and --force) unless `force`, which moves the old
 * results, CSV, reports and images aside (safe_move_aside) instead of
 * deleting them. The file system root is refused outright.
 */
int safe_claim_output(const char *dir, bool force, bvhlab_error *err);

#endif
