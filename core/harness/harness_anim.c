/*
 * An animated config scene: the meshes are loaded at rest, each with its
 * motion, and a frame is posed from them (each part posed, the parts
 * merged in order, the scene's subdivision applied), so frame 0 is the
 * scene as a static config would load it and every frame has the same
 * triangles in the same order. Frame files are loaded one by one.
 */
#include <errno.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "harness/harness_scene.h"
#include "harness/harness_anim.h"
#include "util/util.h"

/* The seed of a mesh's explosion: the same for every run and machine. */
#define EXPLODE_SEED 0xe8910deULL

static void motion_of(const struct config_motion *cm, const bvhlab_transform *rest,
                      uint32_t index, struct scene_motion *m)
{
	*m = (struct scene_motion){.rest = *rest, .rigid = cm->animate, .scale = cm->scale,
	                           .deform = cm->deform == CONFIG_DEFORM_WAVE      ? SCENE_DEFORM_WAVE
	                                     : cm->deform == CONFIG_DEFORM_EXPLODE ? SCENE_DEFORM_EXPLODE
	                                                                            : SCENE_DEFORM_NONE,
	                           .amplitude = cm->amplitude, .seed = EXPLODE_SEED + index};
	memcpy(m->rotate, cm->rotate, sizeof(m->rotate));
	memcpy(m->translate, cm->translate, sizeof(m->translate));
}

/* One mesh at rest; an exploding one with its triangles apart. */
static int load_mesh(const struct config_scene *src, const struct scene_motion *m,
                     bvhlab_scene **out, bvhlab_error *err)
{
	bvhlab_scene *s = NULL;
	int r = harness_load_scene(src, &s, err);
	if (r == 0 && m->deform == SCENE_DEFORM_EXPLODE) {
		r = scene_anim_unshare(s, out, err);
		bvhlab_scene_destroy(s);
		return r;
	}
	*out = s;
	return r;
}

int harness_anim_open(const struct config_scene *cs, struct harness_anim *a, bvhlab_error *err)
{
	uint32_t n = cs->frame_pattern ? 0 : cs->parts ? (uint32_t)cs->part_count : 1;
	bvhlab_transform identity;
	*a = (struct harness_anim){.cs = cs, .frames = cs->frames, .mesh_count = n};
	if (n == 0)
		return 0;
	a->meshes = calloc(n, sizeof(*a->meshes));
	a->motions = calloc(n, sizeof(*a->motions));
	if (!a->meshes || !a->motions) {
		error_set(err, "scene '%s': out of memory", cs->name);
		return -ENOMEM;
	}
	bvhlab_transform_init(&identity);
	/* A whole scene is one mesh: loaded without its subdivision, which
	 * every frame gets after posing, as a composite does. */
	struct config_scene whole = *cs;
	whole.subdivide = 0;
	whole.frames = 0;
	for (uint32_t i = 0; i < n; i++) {
		const struct config_part *p = cs->parts ? &cs->parts[i] : NULL;
		motion_of(p ? &p->motion : &cs->motion, p ? &p->xf : &identity, i, &a->motions[i]);
		int r = load_mesh(p ? &p->src : &whole, &a->motions[i], &a->meshes[i], err);
		if (r < 0) {
			char msg[sizeof(err->message)];
			snprintf(msg, sizeof(msg), "%s", err->message);
			if (p)
				error_set(err, "scene '%s' part %u: %s", cs->name, i, msg);
			return r;
		}
	}
	return 0;
}

void harness_anim_close(struct harness_anim *a)
{
	for (uint32_t i = 0; a->meshes && i < a->mesh_count; i++)
		bvhlab_scene_destroy(a->meshes[i]);
	free(a->meshes);
	free(a->motions);
	*a = (struct harness_anim){0};
}

int harness_anim_load(const struct config_scene *cs, struct harness_anim *a,
                      bvhlab_scene **scene, bvhlab_error *err)
{
	*a = (struct harness_anim){0};
	if (!harness_anim_on(cs))
		return harness_load_scene(cs, scene, err);
	int r = harness_anim_open(cs, a, err);
	return r < 0 ? r : harness_anim_frame(a, 0, scene, err);
}

/* Frame file f: its path, loaded and subdivided as the scene says, and
 * the same triangles as the first frame's. */
static int frame_file(const struct harness_anim *a, uint32_t f, bvhlab_scene **out,
                      bvhlab_error *err)
{
	char path[4096];
	struct config_scene one = *a->cs;
	snprintf(path, sizeof(path), a->cs->frame_pattern, (int)(a->cs->frame_first + f));
	one.path = path;
	int r = harness_load_scene(&one, out, err);
	if (r < 0 || f == 0 || !a->first)
		return r;
	const bvhlab_scene *s = *out, *first = a->first;
	if (s->triangle_count != first->triangle_count || s->vertex_count != first->vertex_count ||
	    memcmp(s->indices, first->indices, 3 * (size_t)s->triangle_count * sizeof(uint32_t))) {
		error_set(err, "%s: frame %u of scene '%s' has other triangles than the first frame "
		          "(%u triangles over %u vertices, against %u over %u, or joined otherwise); "
		          "the frames of an animation keep their topology", path, f, a->cs->name,
		          s->triangle_count, s->vertex_count, first->triangle_count,
		          first->vertex_count);
		bvhlab_scene_destroy(*out);
		*out = NULL;
		return -EINVAL;
	}
	return 0;
}

static int posed(const struct harness_anim *a, uint32_t f, bvhlab_scene **out,
                 bvhlab_error *err)
{
	double t = a->frames > 1 ? (double)f / (a->frames - 1) : 0;
	bvhlab_scene **parts = calloc(a->mesh_count, sizeof(*parts));
	const char *name = a->cs->name ? a->cs->name : "animated";
	int r = parts ? 0 : -ENOMEM;
	for (uint32_t i = 0; r == 0 && i < a->mesh_count; i++)
		r = scene_anim_pose(a->meshes[i], &a->motions[i], t, &parts[i], err);
	if (r == 0 && a->mesh_count == 1) {
		*out = parts[0];
		parts[0] = NULL;
	} else if (r == 0) {
		r = bvhlab_scene_merge(parts, a->mesh_count, name, out, err);
	}
	for (uint32_t i = 0; parts && i < a->mesh_count; i++)
		bvhlab_scene_destroy(parts[i]);
	free(parts);
	if (r == -ENOMEM && !err->message[0])
		error_set(err, "scene '%s': out of memory for frame %u", name, f);
	if (r == 0 && a->cs->subdivide)
		r = bvhlab_scene_subdivide(*out, a->cs->subdivide, err);
	if (r == 0 && a->cs->name)
		r = bvhlab_scene_set_name(*out, a->cs->name);
	return r;
}

int harness_anim_frame(const struct harness_anim *a, uint32_t f, bvhlab_scene **out,
                       bvhlab_error *err)
{
	*out = NULL;
	if (a->inst)
		return harness_anim_flat_frame(a, f, out, err);
	int r = a->cs->frame_pattern ? frame_file(a, f, out, err) : posed(a, f, out, err);
	if (r < 0 && *out) {
		bvhlab_scene_destroy(*out);
		*out = NULL;
	}
	return r;
}
