/*
 * Loading a scene file: the loader is chosen by the file's extension.
 */
#include <errno.h>
#include <string.h>
#include <strings.h>

#include "scene/scene_private.h"

int bvhlab_scene_load(const char *path, bvhlab_scene **out, bvhlab_error *err)
{
	const char *base = strrchr(path, '/');
	const char *dot;

	base = base ? base + 1 : path;
	dot = strrchr(base, '.');
	if (dot && strcasecmp(dot, ".obj") == 0)
		return bvhlab_scene_load_obj(path, out, err);
	if (dot && strcasecmp(dot, ".ply") == 0)
		return bvhlab_scene_load_ply(path, out, err);
	scene_error(err, "%s: unknown scene file type (expected a .obj or .ply extension)", path);
	return -EINVAL;
}
