/*
 * An animated two-level scene (docs/instances.md, "Animated instances"):
 * every instance with an "animate" moves rigidly over the frames. At
 * t = f / (frames - 1) it is scaled by 1 + (scale - 1) t and turned by
 * t rotate degrees (about x, then y, then z, as a part's "rotate") about
 * its own origin, after its placement, and moved by t translate. The
 * meshes never change, so their bottom trees hold for every frame; only
 * the instances' matrices (and the top level over their boxes) do.
 */
#include <errno.h>
#include <stdlib.h>
#include <string.h>

#include "harness/harness_anim.h"
#include "util/util.h"

void harness_anim_instanced(const struct config_scene *cs, const struct scene_instanced *inst,
                            struct harness_anim *a)
{
	*a = (struct harness_anim){0};
	if (harness_anim_on(cs))
		*a = (struct harness_anim){.cs = cs, .frames = cs->frames, .inst = inst};
}

/* rest's placement followed by motion m at t: [Q A | p + t translate]. */
static void pose_matrix(const double rest[12], const struct config_motion *m, double t,
                        double out[12])
{
	bvhlab_transform turn;
	double q[12];
	bvhlab_transform_init(&turn);
	turn.scale = 1 + (m->scale - 1) * t;
	for (int k = 0; k < 3; k++)
		turn.rotate[k] = t * m->rotate[k];
	scene_transform_matrix(&turn, q);
	for (int r = 0; r < 3; r++) {
		for (int c = 0; c < 3; c++)
			out[4 * r + c] = q[4 * r] * rest[c] + q[4 * r + 1] * rest[4 + c] +
			                 q[4 * r + 2] * rest[8 + c];
		out[4 * r + 3] = rest[4 * r + 3] + t * m->translate[r];
	}
}

int harness_anim_pose_instances(const struct harness_anim *a, uint32_t f,
                                struct scene_instanced *out, bvhlab_error *err)
{
	const struct scene_instanced *rest = a->inst;
	double t = a->frames > 1 ? (double)f / (a->frames - 1) : 0;
	uint32_t i = 0;
	*out = (struct scene_instanced){.meshes = rest->meshes, .mesh_count = rest->mesh_count};
	out->instances = malloc((size_t)rest->instance_count * sizeof(*out->instances));
	if (!out->instances) {
		error_set(err, "scene '%s': out of memory for frame %u's instances", a->cs->name, f);
		return -ENOMEM;
	}
	memcpy(out->instances, rest->instances, rest->instance_count * sizeof(*out->instances));
	out->instance_count = out->instance_capacity = rest->instance_count;
	/* The config's entries expand, in order, into the scene's instances. */
	for (size_t e = 0; e < a->cs->instance_count; e++) {
		const struct config_instance *ci = &a->cs->instances[e];
		for (uint32_t k = 0; k < ci->count && i < rest->instance_count; k++, i++) {
			struct scene_instance *in = &out->instances[i];
			if (!ci->motion.animate || f == 0) /* frame 0: the rest, bit for bit */
				continue;
			pose_matrix(rest->instances[i].xf, &ci->motion, t, in->xf);
			if (scene_matrix_invert(in->xf, in->inv)) {
				error_set(err, "scene '%s' frame %u: instance %u's matrix is singular",
				          a->cs->name, f, i);
				harness_anim_posed_finish(out);
				return -EINVAL;
			}
		}
	}
	return 0;
}

void harness_anim_posed_finish(struct scene_instanced *posed)
{
	free(posed->instances);
	*posed = (struct scene_instanced){0};
}

int harness_anim_flat_frame(const struct harness_anim *a, uint32_t f, bvhlab_scene **out,
                            bvhlab_error *err)
{
	struct scene_instanced posed;
	int r = harness_anim_pose_instances(a, f, &posed, err);
	if (r == 0)
		r = scene_instanced_flatten(&posed, a->cs->name, out, err);
	harness_anim_posed_finish(&posed);
	return r;
}
