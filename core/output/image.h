/*
 * Images: PNG (or any format OpenImageIO knows by the file's extension)
 * through the optional module bvhlab-images.so (image_module.c loads
 * images_oiio.cpp's build), and the C helpers that turn traced rays into
 * pixels: shading, heat-map colours, the legend's gradient, file names.
 */
#ifndef BVHLAB_CORE_IMAGE_H
#define BVHLAB_CORE_IMAGE_H

#include <stdbool.h>
#include <stddef.h>
#include <stdint.h>

#include <bvhlab/trace.h>

#ifdef __cplusplus
extern "C" {
#endif

/* Whether bvhlab-images.so is there (opened on the first call); if not,
 * *why (when why is not NULL) says what was tried. */
bool image_module_ready(const char **why);
/* Writes 8-bit RGB pixels, row-major from the top. 0, or -EIO (-ENOTSUP
 * without the module) with err set. */
int image_write_rgb8(const char *path, int width, int height, const uint8_t *rgb,
                     bvhlab_error *err);
/* Reads an image as 8-bit RGB (*rgb malloc'd). 0 or -EIO / -ENOMEM /
 * -ENOTSUP with err set. */
int image_read_rgb8(const char *path, int *width, int *height, uint8_t **rgb,
                    bvhlab_error *err);

#ifdef __cplusplus
}
#endif

/* Grey-on-grey shading of primary hits: |normal . light| plus ambient,
 * misses in the background grey. rgb holds 3 * count bytes. */
void image_shade(const bvhlab_scene *scene, const bvhlab_ray *rays, const bvhlab_hit *hits,
                 size_t count, uint8_t *rgb);

/* Heat-map colours of per-pixel counts on a log scale over [lo, hi]:
 * t = log(1 + c - lo) / log(1 + hi - lo). Most pixels visit a few nodes
 * and a few visit hundreds; on a linear scale every map was the same dark
 * blue. The scale stays shared, so maps of one scene still compare. */
void image_heat(const uint32_t *counts, size_t count, uint32_t lo, uint32_t hi, uint8_t *rgb);

/* The heat map's colour at t in [0, 1]. */
void image_heat_color(float t, uint8_t rgb[3]);

/* A horizontal colour bar of the heat scale, low on the left. */
int image_write_legend(const char *path, int width, int height, bvhlab_error *err);

/* Copies name with every byte outside [A-Za-z0-9_.-] replaced by '_'. */
void image_sanitise(const char *name, char *out, size_t size);

#endif
