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
static int temp_image(const char *dir, const char *name, char *tmp, char *path, size_t size)
{
	const char *base = strrchr(name, '/') ? strrchr(name, '/') + 1 : name;
	if ((size_t)snprintf(path, size, "%s/%s", dir, name) >= size ||
	    (size_t)snprintf(tmp, size, "%s/images/.tmp-%s", dir, base) >= size)
		return -ENAMETOOLONG;
	int fd = safe_create(tmp);
	if (fd < 0)
		return fd;
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
	int r = temp_image(dir, name, tmp, path, sizeof(path));
	if (r < 0)
		return r;
	r = image_write_rgb8(tmp, (int)w, (int)h, rgb, err);
	return image_into_place(tmp, path, r, err);
}

static int write_legend(const char *dir, const char *name, bvhlab_error *err)
{
	char path[4096], tmp[4096];
	int r = temp_image(dir, name, tmp, path, sizeof(path));
	if (r < 0)
		return r;
	r = image_write_legend(tmp, LEGEND_W, LEGEND_H, err);
	return image_into_place(tmp, path, r, err);
}

/* Loads every builder's heat file (NULL where there is none) and the range. */
static void load_heat(const struct scene_images *si, uint32_t **heat, uint32_t *lo,
                      uint32_t *hi)
{
	size_t n = (size_t)si->width * si->height;
	char path[4096];
	*lo = UINT32_MAX;
	*hi = 0;
	for (size_t b = 0; b < si->builder_count; b++) {
		heat[b] = NULL;
		if (images_temp_path(path, sizeof(path), si->dir, "heat", si->scene_index, b) < 0)
			continue;
		uint32_t *counts = malloc(n * sizeof(*counts));
		if (counts && read_raw(path, counts, n * sizeof(*counts)) == 0) {
			for (size_t i = 0; i < n; i++) {
				*lo = counts[i] < *lo ? counts[i] : *lo;
				*hi = counts[i] > *hi ? counts[i] : *hi;
			}
			heat[b] = counts;
		} else {
			free(counts);
		}
		unlink(path);
	}
}

static int heat_images(struct results *res, const struct scene_images *si, bvhlab_error *err)
{
	size_t n = (size_t)si->width * si->height;
	uint32_t **heat = calloc(si->builder_count ? si->builder_count : 1, sizeof(*heat));
	uint8_t *rgb = malloc(3 * n);
	uint32_t lo, hi;
	char name[512];
	int r = heat && rgb ? 0 : -ENOMEM, written = 0;
	if (r == 0)
		load_heat(si, heat, &lo, &hi);
	for (size_t b = 0; r == 0 && b < si->builder_count; b++) {
		if (!heat[b])
			continue;
		images_name(name, sizeof(name), si->scene, si->heat_runs[b]->builder, "heat");
		image_heat(heat[b], n, lo, hi, rgb);
		r = write_png(si->dir, name, si->width, si->height, rgb, err);
		if (r == 0)
			r = results_set_run_image(res, si->heat_runs[b], name);
		written++;
	}
	if (r == 0 && written) {
		images_name(name, sizeof(name), si->scene, NULL, "legend");
		r = write_legend(si->dir, name, err);
		if (r == 0)
			r = results_set_scene_image(res, si->scene, "legend", name, lo, hi);
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
		return -ENAMETOOLONG;
	uint8_t *rgb = malloc(bytes);
	if (!rgb)
		return -ENOMEM;
	int r = read_raw(path, rgb, bytes);
	unlink(path);
	if (r == 0) {
		images_name(name, sizeof(name), si->scene, NULL, NULL);
		r = write_png(si->dir, name, si->width, si->height, rgb, err);
		if (r == 0)
			r = results_set_scene_image(res, si->scene, "shaded", name, 0, 0);
	} else {
		r = 0; /* no run got far enough to render the scene */
	}
	free(rgb);
	return r;
}

int images_write_scene(struct results *res, const struct scene_images *si, bvhlab_error *err)
{
	char dir[4096];
	if ((size_t)snprintf(dir, sizeof(dir), "%s/images", si->dir) >= sizeof(dir))
		return -ENAMETOOLONG;
	if (mkdir(dir, 0777) < 0 && errno != EEXIST) {
		int e = errno;
		error_set(err, "cannot create %s: %s", dir, strerror(e));
		return -e;
	}
	int r = shaded_image(res, si, err);
	int r2 = heat_images(res, si, err);
	return r < 0 ? r : r2;
}
