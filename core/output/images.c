/*
 * A scene's images: per-pixel data leaves each run's child as raw temporary
 * files in the output folder; once every run of the scene is done the
 * parent turns them into PNGs (the shaded render, one heat map per
 * builder, the legend), because the heat maps share one colour scale.
 */
#include <errno.h>
#include <stdbool.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>
#include <unistd.h>

#include "output/image.h"
#include "output/results.h"
#include "output/safe_file.h"
#include "output/images.h"
#include "util/util.h"

#define LEGEND_W 256
#define LEGEND_H 16

int images_temp_path(char *buf, size_t size, const char *dir, const char *kind, size_t scene,
                      size_t builder)
{
	int n = snprintf(buf, size, "%s/.%s-%zu-%zu.raw", dir, kind, scene, builder);
	return n < 0 || (size_t)n >= size ? -ENAMETOOLONG : 0;
}

int images_write_raw(const char *path, const void *data, size_t bytes)
{
	return safe_write_parts(path, &(struct safe_part){data, bytes}, 1);
}

/* Exactly `bytes` bytes of the file, or an error (a short file is one). */
static int read_raw(const char *path, void *data, size_t bytes)
{
	FILE *f = fopen(path, "rb");
	if (!f)
		return -errno;
	bool ok = fread(data, 1, bytes, f) == bytes && fgetc(f) == EOF;
	fclose(f);
	return ok ? 0 : -EIO;
}

/* FNV-1a: a short, stable tag of a name that had to change. */
static uint32_t name_hash(const char *name)
{
	uint32_t h = 2166136261u;
	for (const unsigned char *p = (const unsigned char *)name; *p; p++)
		h = (h ^ *p) * 16777619u;
	return h;
}

/*
 * A file name part for `name`: kept as it is when it is already safe, else
 * sanitised plus "-" and the hash of the original, so that "a b", "a/b"
 * and "a_b" (or "ü" and "é") get images of their own. Never hidden (no
 * leading dot) and never with "--", which separates the parts.
 */
static void image_stem(const char *name, char *out, size_t size)
{
	const size_t tag = 10; /* "-" + 8 hex digits + NUL */
	image_sanitise(name, out, size - tag);
	bool changed = strcmp(out, name) != 0 || !*out || out[0] == '.' || strstr(out, "--");
	if (out[0] == '.')
		out[0] = '_';
	if (changed)
		snprintf(out + strlen(out), tag, "-%08x", (unsigned)name_hash(name));
}

/* images/<scene>--<builder>--<what>.png, relative to the output folder. */
void images_name(char *buf, size_t size, const char *scene, const char *builder,
                 const char *what)
{
	char s[128], b[128];
	image_stem(scene, s, sizeof(s));
	if (!builder) {
		snprintf(buf, size, "images/%s%s%s.png", s, what ? "--" : "", what ? what : "");
		return;
	}
	image_stem(builder, b, sizeof(b));
	snprintf(buf, size, "images/%s--%s--%s.png", s, b, what);
}

/*
 * dir/images/.tmp-NAME.png, created empty here (no link followed) for the
 * image writer to fill; the image is renamed into place once complete.
 */
static int temp_image(const char *dir, const char *name, char *tmp, char *path, size_t size,
                      bvhlab_error *err)
{
	const char *base = strrchr(name, '/') ? strrchr(name, '/') + 1 : name;
	if ((size_t)snprintf(path, size, "%s/%s", dir, name) >= size ||
	    (size_t)snprintf(tmp, size, "%s/images/.tmp-%s", dir, base) >= size)
		return error_set(err, "path too long: %s/%s", dir, name), -ENAMETOOLONG;
	int fd = safe_create(tmp);
	if (fd < 0)
		return error_set(err, "cannot write %s: %s", tmp, strerror(-fd)), fd;
	close(fd);
	return 0;
}

static int image_into_place(const char *tmp, const char *path, int r, bvhlab_error *err)
{
	if (r == 0 && rename(tmp, path) < 0) {
		r = -errno;
		error_set(err, "cannot write %s: %s", path, strerror(-r));
	}
	if (r < 0)
		unlink(tmp);
	return r;
}

/* Writes one PNG under dir; name is relative ("images/..."). */
static int write_png(const char *dir, const char *name, uint32_t w, uint32_t h,
                     const uint8_t *rgb, bvhlab_error *err)
{
	char path[4096], tmp[4096];
	int r = temp_image(dir, name, tmp, path, sizeof(path), err);
	if (r < 0)
		return r;
	r = image_write_rgb8(tmp, (int)w, (int)h, rgb, err);
	return image_into_place(tmp, path, r, err);
}

static int write_legend(const char *dir, const char *name, bvhlab_error *err)
{
	char path[4096], tmp[4096];
	int r = temp_image(dir, name, tmp, path, sizeof(path), err);
	if (r < 0)
		return r;
	r = image_write_legend(tmp, LEGEND_W, LEGEND_H, err);
	return image_into_place(tmp, path, r, err);
}

/* A raw file read whole; ENOENT where it is not there (its run never got
 * that far), else an error naming it (a full disk left it short). */
static int load_raw(const char *path, void *data, size_t bytes, bvhlab_error *err)
{
	int r = read_raw(path, data, bytes);
	if (r < 0 && r != -ENOENT)
		error_set(err, "cannot read %s: %s", path,
		          r == -EIO ? "not the image's size (cut short when written?)" : strerror(-r));
	unlink(path);
	return r;
}

/* Keeps the first failure and its message, counting them, so that one
 * image's failure neither hides nor stops the others. */
static int keep_first(int r, int next, const bvhlab_error *next_err, bvhlab_error *err,
                      size_t *lost)
{
	if (next >= 0)
		return r;
	++*lost;
	if (r < 0)
		return r;
	if (next_err->message[0])
		*err = *next_err;
	else
		error_set(err, "%s", strerror(-next));
	return next;
}

/* Loads every builder's heat file (NULL where there is none) and the range. */
static int load_heat(const struct scene_images *si, uint32_t **heat, uint32_t *lo,
                     uint32_t *hi, bvhlab_error *err, size_t *lost)
{
	size_t n = (size_t)si->width * si->height;
	char path[4096];
	int r = 0;
	*lo = UINT32_MAX;
	*hi = 0;
	for (size_t b = 0; b < si->builder_count; b++) {
		bvhlab_error e = {{0}};
		heat[b] = NULL;
		if (!si->heat_runs[b] || /* the builder does not run on the scene */
		    images_temp_path(path, sizeof(path), si->dir, "heat", si->scene_index, b) < 0)
			continue;
		uint32_t *counts = malloc(n * sizeof(*counts));
		int k = counts ? load_raw(path, counts, n * sizeof(*counts), &e)
		               : (unlink(path), -ENOMEM);
		if (k == 0) {
			for (size_t i = 0; i < n; i++) {
				*lo = counts[i] < *lo ? counts[i] : *lo;
				*hi = counts[i] > *hi ? counts[i] : *hi;
			}
			heat[b] = counts;
		} else {
			free(counts);
		}
		r = keep_first(r, k == -ENOENT ? 0 : k, &e, err, lost);
	}
	return r;
}

/* One heat map per builder whose data came back, then the legend. */
static int heat_images(struct results *res, const struct scene_images *si, bvhlab_error *err,
                       size_t *lost)
{
	size_t n = (size_t)si->width * si->height;
	uint32_t **heat = calloc(si->builder_count ? si->builder_count : 1, sizeof(*heat));
	uint8_t *rgb = malloc(3 * n);
	uint32_t lo, hi;
	char name[512];
	int written = 0, r = heat && rgb ? load_heat(si, heat, &lo, &hi, err, lost) : -ENOMEM;
	for (size_t b = 0; heat && rgb && b < si->builder_count; b++) {
		bvhlab_error e = {{0}};
		if (!heat[b])
			continue;
		images_name(name, sizeof(name), si->scene, si->heat_runs[b]->builder, "heat");
		image_heat(heat[b], n, lo, hi, rgb);
		int k = write_png(si->dir, name, si->width, si->height, rgb, &e);
		if (k == 0)
			k = results_set_run_image(res, si->heat_runs[b], name);
		written += k == 0;
		r = keep_first(r, k, &e, err, lost);
	}
	if (written) {
		bvhlab_error e = {{0}};
		images_name(name, sizeof(name), si->scene, NULL, "legend");
		int k = write_legend(si->dir, name, &e);
		if (k == 0)
			k = results_set_scene_image(res, si->scene, "legend", name, lo, hi);
		r = keep_first(r, k, &e, err, lost);
	}
	for (size_t b = 0; heat && b < si->builder_count; b++)
		free(heat[b]);
	free(heat);
	free(rgb);
	return r;
}

static int shaded_image(struct results *res, const struct scene_images *si, bvhlab_error *err)
{
	size_t bytes = (size_t)si->width * si->height * 3;
	char path[4096], name[512];
	if (images_temp_path(path, sizeof(path), si->dir, "shade", si->scene_index, 0) < 0)
		return error_set(err, "path too long: %s", si->dir), -ENAMETOOLONG;
	uint8_t *rgb = malloc(bytes);
	if (!rgb)
		return -ENOMEM;
	int r = load_raw(path, rgb, bytes, err);
	if (r == 0) {
		images_name(name, sizeof(name), si->scene, NULL, NULL);
		r = write_png(si->dir, name, si->width, si->height, rgb, err);
		if (r == 0)
			r = results_set_scene_image(res, si->scene, "shaded", name, 0, 0);
	} else if (r == -ENOENT) {
		r = 0; /* no run got far enough to render the scene */
	}
	free(rgb);
	return r;
}

int images_write_scene(struct results *res, const struct scene_images *si, bvhlab_error *err,
                       size_t *lost)
{
	char dir[4096];
	bvhlab_error e = {{0}};
	*lost = 0;
	if ((size_t)snprintf(dir, sizeof(dir), "%s/images", si->dir) >= sizeof(dir))
		return error_set(err, "path too long: %s/images", si->dir), ++*lost, -ENAMETOOLONG;
	if (mkdir(dir, 0777) < 0 && errno != EEXIST) {
		int k = errno;
		error_set(err, "cannot create %s: %s", dir, strerror(k));
		return ++*lost, -k;
	}
	int r = keep_first(0, shaded_image(res, si, &e), &e, err, lost);
	bvhlab_error heat_err = {{0}};
	int k = heat_images(res, si, &heat_err, lost);
	if (r == 0 && k < 0)
		*err = heat_err;
	size_t used = strlen(err->message);
	if (*lost > 1)
		snprintf(err->message + used, sizeof(err->message) - used,
		         " (and %zu more images lost)", *lost - 1);
	if ((r < 0 || k < 0) && *lost == 0)
		*lost = 1; /* out of memory before any image */
	return r < 0 ? r : k;
}
