/*
 * Two-level trees for tests (test-instances, cl/test-cl-two-level): the
 * trees of a two-level series made wider by the collapse plugin, so the
 * traversals walk bottoms and a top of more than two children. Include
 * after scene_fixture.h.
 */
#ifndef BVHLAB_TEST_TWO_LEVEL_FIXTURE_H
#define BVHLAB_TEST_TWO_LEVEL_FIXTURE_H

#include "harness/harness_two_level.h"

/* Every bottom tree of trees collapsed to `bottom` wide and the top to
 * `top` wide (4 or 8); false, with a failed check, when the collapse
 * plugin does not load. */
static inline bool collapse_levels(const struct scene_instanced *inst,
                                   struct two_level_trees *trees, int bottom, int top)
{
	bvhlab_plugin *collapser = NULL;
	bvhlab_error err = { { 0 } };
	char width[16];
	if (!plugin_loads("collapse", &collapser))
		return false;
	for (uint32_t m = 0; m <= inst->mesh_count; m++) {
		bvhlab_prims prims = { 0 };
		bvhlab_options o;
		bool is_top = m == inst->mesh_count;
		snprintf(width, sizeof(width), "width=%d", is_top ? top : bottom);
		CHECK_INT(bvhlab_options_init(&o, bvhlab_plugin_builder(collapser)), 0);
		CHECK_INT(bvhlab_options_parse(&o, width, &err), 0);
		if (!is_top)
			CHECK_INT(bvhlab_prims_init(&prims, inst->meshes[m], &err), 0);
		CHECK_INT(bvhlab_refine(collapser, &o, is_top ? &trees->top_prims.input : &prims.input,
		                        1, is_top ? &trees->top : &trees->bottom[m], &err), 0);
		bvhlab_prims_finish(&prims);
		bvhlab_options_finish(&o);
	}
	bvhlab_plugin_close(collapser);
	CHECK(trees->bottom[0].width == (uint32_t)bottom && trees->top.width == (uint32_t)top);
	return true;
}

#endif
