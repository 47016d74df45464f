/*
 * A scene's images (images.c): the raw per-pixel files a run's child
 * writes, and the PNGs the parent makes of them.
 */
#ifndef BVHLAB_CORE_IMAGES_H
#define BVHLAB_CORE_IMAGES_H

#include <stddef.h>
#include <stdint.h>

#include <bvhlab/types.h>

/* dir/.KIND-SCENE-BUILDER.raw: per-pixel data a run's child hands back. */
int images_temp_path(char *buf, size_t size, const char *dir, const char *kind, size_t scene,
                      size_t builder);
int images_write_raw(const char *path, const void *data, size_t bytes);

/* "images/<scene>.png", "images/<scene>--<what>.png" (builder NULL) or
 * "images/<scene>--<builder>--<what>.png", names sanitised. */
void images_name(char *buf, size_t size, const char *scene, const char *builder,
                        const char *what);

struct results;
struct run_identity;
/* What the parent needs to turn a scene's temporary files into PNGs. */
struct scene_images {
	const char *dir;
	size_t scene_index;
	const char *scene;
	uint32_t width, height;
	/* [builder_count], by config index: the run that drew each heat map
	 * (each builder's first of the scene, from the run list; NULL for a
	 * builder that does not run on the scene) */
	const struct run_identity *const *heat_runs;
	size_t builder_count;
};

/* Writes the scene's PNGs (shaded, heat maps on one scale, legend),
 * removes the temporary files and records the names in the results. An
 * image that cannot be written does not stop the others: the first
 * failure is returned (err names its file), *lost counts them all. */
int images_write_scene(struct results *res, const struct scene_images *si, bvhlab_error *err,
                       size_t *lost);

#endif /* BVHLAB_CORE_IMAGES_H */
