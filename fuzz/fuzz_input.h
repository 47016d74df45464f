/*
 * Helpers shared by the fuzz targets. The scene loaders read files, so
 * every input goes through one temporary file per process, rewritten in
 * place; a successful load must then satisfy what the rest of the core
 * relies on, or the target aborts (a finding).
 */
#ifndef BVHLAB_FUZZ_INPUT_H
#define BVHLAB_FUZZ_INPUT_H

#include <math.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <unistd.h>

#include <bvhlab/scene.h>

static char fuzz_path[256];
static int fuzz_fd = -1;

static void fuzz_remove_file(void)
{
	if (fuzz_fd >= 0)
		unlink(fuzz_path);
}

/* Writes the input to the temporary file (suffix ".obj", ".ply") and returns its path. */
static const char *fuzz_write_file(const uint8_t *data, size_t size, const char *suffix)
{
	if (fuzz_fd < 0) {
		const char *dir = getenv("TMPDIR");
		snprintf(fuzz_path, sizeof(fuzz_path), "%s/bvhlab-fuzz-XXXXXX%s",
		         dir && *dir ? dir : "/tmp", suffix);
		fuzz_fd = mkstemps(fuzz_path, (int)strlen(suffix));
		if (fuzz_fd < 0) {
			perror(fuzz_path);
			abort();
		}
		atexit(fuzz_remove_file);
	}
	if (ftruncate(fuzz_fd, 0) != 0 || pwrite(fuzz_fd, data, size, 0) != (ssize_t)size) {
		perror(fuzz_path);
		abort();
	}
	return fuzz_path;
}

/* A loaded scene's invariants: what the BVH code indexes without checking. */
static void fuzz_check_scene(int ret, const bvhlab_scene *s, const bvhlab_error *err)
{
	if (ret != 0) {
		if (s != NULL || err->message[0] == '\0')
			abort(); /* a failure must leave no scene and say why */
		return;
	}
	if (!s || s->triangle_count == 0 || !s->name || !s->source)
		abort();
	for (size_t i = 0; i < 3 * (size_t)s->vertex_count; i++)
		if (!isfinite(s->vertices[i]))
			abort();
	for (size_t i = 0; i < 3 * (size_t)s->triangle_count; i++)
		if (s->indices[i] >= s->vertex_count)
			abort();
	for (int k = 0; k < 3; k++)
		if (!(s->bounds.lo[k] <= s->bounds.hi[k]))
			abort();
	if (s->degenerate_count > s->triangle_count)
		abort();
}

#endif
