/*
 * Loading a scene file, and trying one before a sweep (scene_check.h): the
 * loader is chosen by the file's extension.
 */
#include <errno.h>
#include <stdbool.h>
#include <stdlib.h>
#include <string.h>
#include <strings.h>

#include "scene/scene_check.h"
#include "scene/scene_ply.h"
#include "scene/scene_private.h"

/* Enough for any header a PLY writer makes: a few lines per element and
 * comments; past it the header counts as truncated. */
#define PLY_HEADER_MAX (1u << 20)
/* An OBJ is read this far: it opens and its data can be read. */
#define OBJ_HEAD 4096

/* ".obj", ".ply" (any case) or NULL. */
static const char *extension(const char *path)
{
	const char *base = strrchr(path, '/');
	const char *dot = strrchr(base ? base + 1 : path, '.');
	if (dot && (strcasecmp(dot, ".obj") == 0 || strcasecmp(dot, ".ply") == 0))
		return dot;
	return NULL;
}

static int unknown_type(const char *path, bvhlab_error *err)
{
	scene_error(err, "%s: unknown scene file type (expected a .obj or .ply extension)", path);
	return -EINVAL;
}

int scene_check_file(const char *path, bvhlab_error *err)
{
	const char *ext = extension(path);
	bool ply = ext && strcasecmp(ext, ".ply") == 0;
	char *data = NULL;
	size_t size = 0;
	struct ply_header header;
	if (!ext)
		return unknown_type(path, err);
	int r = scene_read_head(path, ply ? PLY_HEADER_MAX : OBJ_HEAD, &data, &size, err);
	if (r == 0 && ply) {
		r = ply_header_parse(path, data, size, &header, err);
		ply_header_free(&header);
	}
	free(data);
	return r;
}

int bvhlab_scene_load(const char *path, bvhlab_scene **out, bvhlab_error *err)
{
	const char *ext = extension(path);
	if (!ext)
		return unknown_type(path, err);
	if (strcasecmp(ext, ".obj") == 0)
		return bvhlab_scene_load_obj(path, out, err);
	return bvhlab_scene_load_ply(path, out, err);
}
