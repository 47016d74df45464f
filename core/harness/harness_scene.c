/*
 * A config scene made real: loaded from its file or generated (a composite:
 * each part loaded, placed and merged), subdivided and named; `bvhlab build`/`render` and the sweep share it.
 */
#include <errno.h>
#include <stdio.h>
#include <stdlib.h>

#include "harness/harness.h"
#include "util/util.h"

/* Prefixes err's message with the part it came from. */
static void part_error(bvhlab_error *err, const char *scene, size_t part)
{
	char msg[sizeof(err->message)];
	if (!err)
		return;
	snprintf(msg, sizeof(msg), "%s", err->message);
	error_set(err, "scene '%s' part %zu: %s", scene, part, msg);
}

/* Loads, places and merges a composite scene's parts. */
static int load_parts(const struct config_scene *cs, bvhlab_scene **out, bvhlab_error *err)
{
	bvhlab_scene **parts = calloc(cs->part_count, sizeof(*parts));
	const char *name = cs->name ? cs->name : "composite";
	int r = parts ? 0 : -ENOMEM;
	for (size_t i = 0; r == 0 && i < cs->part_count; i++) {
		r = harness_load_scene(&cs->parts[i].src, &parts[i], err);
		if (r < 0)
			part_error(err, name, i);
		else
			bvhlab_scene_transform(parts[i], &cs->parts[i].xf);
	}
	if (r == 0)
		r = bvhlab_scene_merge(parts, (uint32_t)cs->part_count, name, out, err);
	for (size_t i = 0; parts && i < cs->part_count; i++)
		bvhlab_scene_destroy(parts[i]);
	free(parts);
	return r;
}

int harness_load_scene(const struct config_scene *cs, bvhlab_scene **out, bvhlab_error *err)
{
	int r = cs->parts  ? load_parts(cs, out, err)
	        : cs->path ? bvhlab_scene_load(cs->path, out, err)
	                   : bvhlab_scene_generate(cs->generator, &cs->gen, out, err);
	if (r < 0)
		return r;
	if (cs->subdivide > 0)
		r = bvhlab_scene_subdivide(*out, cs->subdivide, err);
	if (r == 0 && cs->name)
		r = bvhlab_scene_set_name(*out, cs->name);
	if (r < 0) {
		if (r == -ENOMEM && err && !err->message[0])
			error_set(err, "scene '%s': out of memory", cs->name);
		bvhlab_scene_destroy(*out);
		*out = NULL;
	}
	return r;
}
