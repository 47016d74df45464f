/*
 * The sweep's images: each run's child leaves raw per-pixel files in the
 * output folder (harness.c), the scene's PNGs are made of them once its
 * runs are done (output/images.c). A file that cannot be written (a full
 * disk) is named on stderr here; the caller counts it for the sweep's
 * last line and exit status.
 */
#include <errno.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "harness/harness_images.h"
#include "output/image.h"
#include "output/images.h"

bool harness_want_images(const struct config *cfg)
{
	const char *why;
	if (!cfg->images || cfg->ray_width == 0 || cfg->ray_height == 0)
		return false;
	if (image_module_ready(&why))
		return true;
	fprintf(stderr, "bvhlab: images skipped (%s); the run goes on\n", why);
	return false;
}

int harness_image_lost(const char *scene, const char *builder, const char *path, int error,
                       bool tty)
{
	if (!path || error >= 0)
		return 0;
	/* A progress line on a terminal has no newline yet. */
	fprintf(stderr, "%sbvhlab: images of scene '%s': %s%s%s lost: cannot write %s: %s\n",
	        tty ? "\n" : "", scene, builder ? "the heat map of builder '" : "the shaded render",
	        builder ? builder : "", builder ? "'" : "", path, strerror(-error));
	return 1;
}

size_t harness_scene_images(struct results *res, const struct config *cfg,
                         const struct run_list *list, const bvhlab_scene *scene, size_t s,
                         bool tty)
{
	size_t nb = cfg->builder_count;
	const struct run_identity **heat_runs = calloc(nb ? nb : 1, sizeof(*heat_runs));
	bvhlab_error err = {{0}};
	size_t lost = 0;
	if (!heat_runs)
		return fprintf(stderr, "bvhlab: images of scene '%s': out of memory\n", scene->name), 1;
	for (size_t b = 0; b < nb; b++) { /* NULL: the builder does not run on the scene */
		const struct plan_run *run = plan_list_first(list, s, b);
		heat_runs[b] = run ? &run->key : NULL;
	}
	struct scene_images si = {.dir = cfg->output, .scene_index = s, .scene = scene->name,
	                          .width = cfg->ray_width, .height = cfg->ray_height,
	                          .heat_runs = heat_runs, .builder_count = nb};
	int r = images_write_scene(res, &si, &err, &lost);
	/* The images that were written are recorded even when others were not. */
	bvhlab_error write_err = {{0}};
	int w = results_write(res, &write_err);
	if (r < 0)
		fprintf(stderr, "%sbvhlab: images of scene '%s': %s\n", tty ? "\n" : "", scene->name,
		        err.message[0] ? err.message : strerror(-r));
	if (w < 0)
		fprintf(stderr, "%sbvhlab: cannot write results: %s\n", tty ? "\n" : "",
		        write_err.message[0] ? write_err.message : strerror(-w));
	free(heat_runs);
	return lost + (w < 0);
}
