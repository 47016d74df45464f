/*
 * Pixels from traced rays. The shaded render is only there to show what a
 * scene looks like; the heat map is the measurement: nodes visited per
 * primary ray, on a scale the caller fixes so that maps compare.
 */
#include <errno.h>
#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "output/image.h"
#include "util/util.h"

#define BACKGROUND 96
#define AMBIENT 0.15f

void image_shade(const bvhlab_scene *scene, const bvhlab_ray *rays, const bvhlab_hit *hits,
                 size_t count, uint8_t *rgb)
{
	/* A light over the camera's shoulder keeps most visible faces lit. */
	static const float light[3] = {0.40824829f, 0.81649658f, 0.40824829f};
	for (size_t i = 0; i < count; i++) {
		uint8_t *px = rgb + 3 * i;
		if (hits[i].prim == BVHLAB_NO_HIT) {
			px[0] = px[1] = px[2] = BACKGROUND;
			continue;
		}
		float n[3];
		bvhlab_triangle_normal(scene, hits[i].prim, n);
		/* Two-sided: the face toward the viewer is the one that is lit. */
		float facing = n[0] * rays[i].dir[0] + n[1] * rays[i].dir[1] + n[2] * rays[i].dir[2];
		if (facing > 0.0f)
			for (int k = 0; k < 3; k++)
				n[k] = -n[k];
		float d = fmaxf(0.0f, n[0] * light[0] + n[1] * light[1] + n[2] * light[2]);
		float v = fminf(1.0f, AMBIENT + (1.0f - AMBIENT) * d);
		px[0] = (uint8_t)(v * 235.0f + 0.5f);
		px[1] = (uint8_t)(v * 225.0f + 0.5f);
		px[2] = (uint8_t)(v * 205.0f + 0.5f);
	}
}

void image_heat_color(float t, uint8_t rgb[3])
{
	/* Dark blue, blue, cyan, yellow, red: monotonic in lightness up to yellow. */
	static const float stops[5][3] = {
		{0.02f, 0.02f, 0.20f}, {0.10f, 0.30f, 0.90f}, {0.10f, 0.85f, 0.85f},
		{0.98f, 0.90f, 0.15f}, {0.85f, 0.08f, 0.05f}};
	if (!(t > 0.0f))
		t = 0.0f;
	if (t > 1.0f)
		t = 1.0f;
	float x = t * 4.0f;
	int k = x >= 4.0f ? 3 : (int)x;
	float f = x - (float)k;
	for (int c = 0; c < 3; c++) {
		float v = stops[k][c] + f * (stops[k + 1][c] - stops[k][c]);
		rgb[c] = (uint8_t)(v * 255.0f + 0.5f);
	}
}

void image_heat(const uint32_t *counts, size_t count, uint32_t lo, uint32_t hi, uint8_t *rgb)
{
	float span = log1pf(hi > lo ? (float)(hi - lo) : 1.0f);
	for (size_t i = 0; i < count; i++) {
		float t = counts[i] > lo ? log1pf((float)(counts[i] - lo)) / span : 0.0f;
		image_heat_color(t, rgb + 3 * i);
	}
}

int image_write_legend(const char *path, int width, int height, bvhlab_error *err)
{
	uint8_t *rgb = malloc((size_t)width * (size_t)height * 3);
	if (!rgb) {
		error_set(err, "out of memory for %s", path);
		return -ENOMEM;
	}
	for (int x = 0; x < width; x++) {
		uint8_t c[3];
		image_heat_color(width > 1 ? (float)x / (float)(width - 1) : 0.0f, c);
		for (int y = 0; y < height; y++)
			memcpy(rgb + 3 * ((size_t)y * width + x), c, 3);
	}
	int r = image_write_rgb8(path, width, height, rgb, err);
	free(rgb);
	return r;
}

void image_sanitise(const char *name, char *out, size_t size)
{
	size_t k = 0;
	if (size == 0)
		return;
	for (; name[k] && k + 1 < size; k++) {
		char c = name[k];
		bool ok = (c >= 'a' && c <= 'z') || (c >= 'A' && c <= 'Z') || (c >= '0' && c <= '9') ||
		          c == '_' || c == '.' || c == '-';
		out[k] = ok ? c : '_';
	}
	out[k] = '\0';
	/* "." and ".." would name folders, not files. */
	if (strcmp(out, ".") == 0 || strcmp(out, "..") == 0)
		out[0] = '_';
}
