/*
 * A scene file tried before a sweep starts (scene_load.c): a config that
 * names a file the loader cannot even open is refused before its output
 * folder exists, rather than failing every run of the scene.
 */
#ifndef BVHLAB_CORE_SCENE_CHECK_H
#define BVHLAB_CORE_SCENE_CHECK_H

#include <bvhlab/scene.h>

/*
 * Whether `path` is a scene file worth loading: a known extension, a
 * regular file that opens and reads, and for a PLY a header that parses
 * (an OBJ has none; its body is checked when it loads). 0, or a negative
 * errno with "PATH: ..." in err, as the loader says it.
 */
int scene_check_file(const char *path, bvhlab_error *err);

#endif
