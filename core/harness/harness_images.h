/*
 * The sweep's images (harness_images.c): whether to draw them, raw data a
 * run's child could not leave, and a scene's PNGs once its runs are done.
 * An image asked for that cannot be written is named on stderr and
 * counted, never lost silently (a full disk).
 */
#ifndef BVHLAB_CORE_HARNESS_IMAGES_H
#define BVHLAB_CORE_HARNESS_IMAGES_H

#include <stdbool.h>
#include <stddef.h>

#include <bvhlab/bvhlab.h>

#include "config/config.h"
#include "output/results.h"
#include "plan/plan.h"

/* Images asked for and drawable; a bundle without the images module says
 * so in one line and runs on. */
bool harness_want_images(const struct config *cfg);

/* A raw file at `path` the child of a run of `builder` (NULL: the scene's
 * shaded render) could not write, `error` a negative errno (0: written or
 * never tried): said on stderr naming the file. 1 when lost, else 0. */
int harness_image_lost(const char *scene, const char *builder, const char *path, int error,
                       bool tty);

/* Turns the raw files of scene number s into its PNGs, records them and
 * rewrites the results; what cannot be written is said on stderr. How many
 * images were lost (the results not written count as one). */
size_t harness_scene_images(struct results *res, const struct config *cfg,
                         const struct run_list *list, const bvhlab_scene *scene, size_t s,
                         bool tty);

#endif
