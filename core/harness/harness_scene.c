/*
 * A config scene made real: loaded from its file or generated, subdivided
 * and named; `bvhlab build`/`render` and the sweep share it.
 */
#include <errno.h>

#include "harness/harness.h"
#include "util/util.h"

int harness_load_scene(const struct config_scene *cs, bvhlab_scene **out, bvhlab_error *err)
{
	int r = cs->path ? bvhlab_scene_load(cs->path, out, err)
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
