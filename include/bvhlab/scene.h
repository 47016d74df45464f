/*
 * bvhlab — triangle scenes: loading (OBJ, PLY), procedural generators,
 * subdivision, and the per-primitive data handed to builders.
 */
#ifndef BVHLAB_SCENE_H
#define BVHLAB_SCENE_H

#include <stdbool.h>
#include <stdint.h>

#include "builder.h"
#include "types.h"

BVHLAB_BEGIN_DECLS

/* An indexed triangle mesh. Owns all its arrays. */
typedef struct bvhlab_scene {
	char *name;               /* label used in reports */
	char *source;             /* file path, or generator description */
	float *vertices;          /* [3 * vertex_count] x, y, z */
	uint32_t vertex_count;
	uint32_t *indices;        /* [3 * triangle_count], each < vertex_count */
	uint32_t triangle_count;
	uint32_t degenerate_count; /* zero-area triangles (kept, counted) */
	bvhlab_aabb bounds;       /* of all referenced vertices */
	uint32_t part_count;      /* meshes merged into it: 1, more for a composite */
} bvhlab_scene;

/* Parameters of the procedural generators; unused fields are ignored. */
typedef struct bvhlab_gen_params {
	uint32_t frequency; /* icosphere: edge subdivisions, 20 * f^2 triangles */
	uint32_t count;     /* soup: triangles; stadium: triangles of the dense object */
	uint32_t size;      /* terrain: grid cells per side, 2 * size^2 triangles */
	uint64_t seed;      /* soup, stadium, terrain, needles: random seed */
	double width;       /* needles: distance of the third vertex from the first */
} bvhlab_gen_params;

/* Default generator parameters (frequency 16, count 10000, size 256, seed 1,
 * width 0.001). */
void bvhlab_gen_params_init(bvhlab_gen_params *params);

/*
 * Loads an OBJ or PLY file, chosen by extension (case-insensitive). On
 * failure returns a negative errno and err names the file and the line
 * (text) or byte offset (binary). name/source are set from the path.
 */
int bvhlab_scene_load(const char *path, bvhlab_scene **out, bvhlab_error *err);
int bvhlab_scene_load_obj(const char *path, bvhlab_scene **out, bvhlab_error *err);
int bvhlab_scene_load_ply(const char *path, bvhlab_scene **out, bvhlab_error *err);

/*
 * Generates "icosphere", "soup", "stadium", "terrain", "needles" (count
 * long thin triangles across the unit cube: each joins a random point of
 * one face to a random point of the opposite face, the face pair random,
 * the third vertex `width` from the first) or "room" (an open room of 12
 * huge triangles in the cube -1..1, no parameters). An unknown
 * generator is -EINVAL with a message listing the known ones.
 */
int bvhlab_scene_generate(const char *generator, const bvhlab_gen_params *params,
                          bvhlab_scene **out, bvhlab_error *err);

/* Splits every triangle into 4 (edge midpoints), `levels` times. */
int bvhlab_scene_subdivide(bvhlab_scene *scene, unsigned levels, bvhlab_error *err);

/*
 * Where a part of a composite scene goes: scaled by `scale` about the
 * origin, rotated by rotate[0], [1], [2] degrees about x, then y, then z
 * (right-handed), then moved by `translate`.
 */
typedef struct bvhlab_transform {
	double scale;
	double rotate[3];
	double translate[3];
} bvhlab_transform;

/* Identity: scale 1, no rotation, no translation. */
void bvhlab_transform_init(bvhlab_transform *xf);

/* Applies xf to every vertex and recomputes the bounds. */
void bvhlab_scene_transform(bvhlab_scene *scene, const bvhlab_transform *xf);

/*
 * One scene holding the triangles of parts[0 .. count) in order (their
 * vertices concatenated, indices offset), part_count the sum of theirs,
 * named `name`. The parts are left as they are. 0, -ENOMEM or -EOVERFLOW
 * (more than UINT32_MAX vertices or triangles in all), explained in err.
 */
int bvhlab_scene_merge(bvhlab_scene *const *parts, uint32_t count, const char *name,
                       bvhlab_scene **out, bvhlab_error *err);

/* Recomputes bounds and degenerate_count from the arrays. */
void bvhlab_scene_update(bvhlab_scene *scene);

/* Sets name (copied). 0 or -ENOMEM. */
int bvhlab_scene_set_name(bvhlab_scene *scene, const char *name);

/* Frees the scene; NULL is fine. */
void bvhlab_scene_destroy(bvhlab_scene *scene);

/*
 * Per-primitive boxes and centroids of a scene, in the form builders take.
 * init fills `input` (threads = 1) and owns its arrays until finish.
 */
typedef struct bvhlab_prims {
	bvhlab_build_input input;
	bvhlab_aabb *bounds_storage;
	float *centroid_storage;
} bvhlab_prims;

int bvhlab_prims_init(bvhlab_prims *prims, const bvhlab_scene *scene, bvhlab_error *err);
/* The input of a build over boxes (prim_kind BVHLAB_PRIM_BOXES, ABI 1.5):
 * primitive i is boxes[i], its id i, e.g. an instance's world box for a
 * top-level tree. The boxes are copied. 0, -EINVAL (no box, or an empty
 * or non-finite one, named), -ENOMEM. */
int bvhlab_prims_init_boxes(bvhlab_prims *prims, const bvhlab_aabb *boxes, uint32_t count,
                            bvhlab_error *err);
void bvhlab_prims_finish(bvhlab_prims *prims);

BVHLAB_END_DECLS

#endif /* BVHLAB_SCENE_H */
