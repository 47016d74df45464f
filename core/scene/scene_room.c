/*
 * The "room" generator: an open room of 12 huge triangles in the cube
 * (-1,-1,-1)-(1,1,1), the large, axis-aligned and leaning triangles that
 * composite scenes put around their objects (configs/composite.json's
 * courtyard). The floor, full-height walls at x = -1 and z = -1 (away from
 * the default camera, which looks from +x, +y, +z), low walls at x = 1 and
 * z = 1 that the camera sees over, and two triangles leaning across the
 * back corner. It takes no parameters: its size comes from a part's scale.
 */
#include <stdio.h>
#include <string.h>

#include "scene/scene_private.h"

static const float room_vertices[][3] = {
	{ -1, -1, -1 }, { 1, -1, -1 }, { 1, 1, -1 },      { -1, 1, -1 },
	{ -1, -1, 1 },  { 1, -1, 1 },  { -1, 1, 1 },      { 1, -0.8f, -1 },
	{ 1, -0.8f, 1 }, { -1, -0.8f, 1 }, { 0.2f, -1, -1 }, { -1, -1, 0.2f },
};

static const uint32_t room_triangles[][3] = {
	{ 0, 1, 5 }, { 0, 5, 4 },  /* floor */
	{ 0, 4, 6 }, { 0, 6, 3 },  /* wall x = -1 */
	{ 0, 3, 2 }, { 0, 2, 1 },  /* wall z = -1 */
	{ 1, 7, 8 }, { 1, 8, 5 },  /* low wall x = 1 */
	{ 4, 5, 8 }, { 4, 8, 9 },  /* low wall z = 1 */
	{ 10, 3, 11 }, { 10, 2, 6 }, /* leaning across the back corner */
};

#define ROOM_VERTICES (sizeof(room_vertices) / sizeof(room_vertices[0]))
#define ROOM_TRIANGLES (sizeof(room_triangles) / sizeof(room_triangles[0]))

int scene_gen_room(const bvhlab_gen_params *params, bvhlab_scene **out, char *source,
                   size_t source_size, bvhlab_error *err)
{
	bvhlab_scene *scene = NULL;
	int ret;

	(void)params;
	ret = scene_alloc(ROOM_VERTICES, ROOM_TRIANGLES, &scene, err);
	if (ret)
		return ret;
	memcpy(scene->vertices, room_vertices, sizeof(room_vertices));
	memcpy(scene->indices, room_triangles, sizeof(room_triangles));
	snprintf(source, source_size, "room");
	*out = scene;
	return 0;
}
