/*
 * A sweep's scenes (harness_scene.c): loaded, generated and subdivided,
 * first tried in a forked probe.
 */
#ifndef BVHLAB_CORE_HARNESS_SCENE_H
#define BVHLAB_CORE_HARNESS_SCENE_H

#include <bvhlab/bvhlab.h>

#include "config/config.h"

/* Loads or generates one config scene, subdivides it and names it. */
int harness_load_scene(const struct config_scene *cs, bvhlab_scene **out, bvhlab_error *err);

/*
 * Loads the scene once in a forked child first, under timeout_s and the
 * largest memory limit of the config's builders (none if one has none):
 * a scene that hangs the loader, eats the machine's memory or crashes it
 * costs that scene only. Without a limit the child reads the files only,
 * not subdividing them. 0 when it loaded there; else a negative errno
 * and err saying why, naming the limit it ran into.
 */
int harness_probe_scene(const struct config *cfg, const struct config_scene *cs,
                        bvhlab_error *err);

/*
 * Tries every file the config's scenes name (meshes, composite parts, each
 * frame file of a pattern) with scene_check_file: one that is missing,
 * unreadable, not a regular file or of an unknown type, or a PLY whose
 * header does not parse, is printed as FILE:LINE:COLUMN: scene 'NAME': ...
 * Called before the output folder is touched: 0, or -EINVAL with err
 * counting the bad files.
 */
int harness_check_scene_files(const struct config *cfg, bvhlab_error *err);

#endif
