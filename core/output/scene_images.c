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
#include "output/scene_images.h"
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
	FILE *f = fopen(path, "wb");
	if (!f)
		return -errno;
	bool ok = fwrite(data, 1, bytes, f) == bytes;
	ok = fclose(f) == 0 && ok;
	if (!ok)
		unlink(path);
	return ok ? 0 : -EIO;
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

/* images/<scene>--<builder>--<what>.png, relative to the output folder. */
void images_name(char *buf, size_t size, const char *scene, const char *builder,
                        const char *what)
{
	char s[128], b[128];
	image_sanitise(scene, s, sizeof(s));
	if (!builder) {
		snprintf(buf, size, "images/%s%s%s.png", s, what ? "--" : "", what ? what : "");
		return;
	}
	image_sanitise(builder, b, sizeof(b));
	snprintf(buf, size, "images/%s--%s--%s.png", s, b, what);
}

/* Writes one PNG under dir; name is relative ("images/..."). */
static int write_png(const char *dir, const char *name, uint32_t w, uint32_t h,
                     const uint8_t *rgb, bvhlab_error *err)
{
	char path[4096];
	if ((size_t)snprintf(path, sizeof(path), "%s/%s", dir, name) >= sizeof(path))
		return -ENAMETOOLONG;
	return image_write_rgb8(path, (int)w, (int)h, rgb, err);
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
		images_name(name, sizeof(name), si->scene, si->builders[b], "heat");
		image_heat(heat[b], n, lo, hi, rgb);
		r = write_png(si->dir, name, si->width, si->height, rgb, err);
		if (r == 0)
			r = results_set_run_image(res, si->scene, si->builders[b], si->threads[b], name);
		written++;
	}
	if (r == 0 && written) {
		images_name(name, sizeof(name), si->scene, NULL, "legend");
		char path[4096];
		if ((size_t)snprintf(path, sizeof(path), "%s/%s", si->dir, name) >= sizeof(path))
			r = -ENAMETOOLONG;
		else
			r = image_write_legend(path, LEGEND_W, LEGEND_H, err);
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
