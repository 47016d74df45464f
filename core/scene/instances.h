/*
 * Two-level scenes (instances.c; docs/instances.md): meshes kept once, and
 * instances placing them with a 3x4 object-to-world matrix. The bottom
 * level of a two-level build is one tree per mesh, the top one tree over
 * the instances' world boxes; flattening makes the one-level scene the
 * same triangles would be (for the builders that take one mesh, and to
 * check two-level hits against).
 */
#ifndef BVHLAB_CORE_SCENE_INSTANCES_H
#define BVHLAB_CORE_SCENE_INSTANCES_H

#include <stdbool.h>
#include <stdint.h>

#include <bvhlab/scene.h>

/* One placed mesh. world = xf * (local, 1); inv maps world to local. */
struct scene_instance {
	uint32_t mesh;
	double xf[12];  /* row-major 3x4 */
	double inv[12]; /* its inverse, for rays entering the instance */
};

struct scene_instanced {
	bvhlab_scene **meshes; /* owned */
	uint32_t mesh_count;
	struct scene_instance *instances;
	uint32_t instance_count, instance_capacity;
};

/* A scatter: count instances of one mesh, positions uniform in [lo, hi],
 * scale uniform in [scale[0], scale[1]], turned about y at random when
 * random_y; drawn from util_splitmix64(seed), so the same on every machine. */
struct scene_scatter {
	uint32_t mesh, count;
	uint64_t seed;
	double lo[3], hi[3], scale[2];
	bool random_y;
};

/* The row-major 3x4 matrix of a composite part's placement. */
void scene_transform_matrix(const bvhlab_transform *xf, double m[12]);
/* inv = m^-1 (as 3x4 affine maps); -EINVAL when m is singular or not finite. */
int scene_matrix_invert(const double m[12], double inv[12]);
/* p' = m * (p, w): w = 1 for a point, 0 for a direction. */
void scene_matrix_apply(const double m[12], const double p[3], double w, double out[3]);

/* Takes ownership of `meshes` (count of them, each non-NULL). */
void scene_instanced_init(struct scene_instanced *s, bvhlab_scene **meshes, uint32_t count);
/* Appends an instance: 0, -EINVAL (mesh out of range, singular matrix),
 * -EOVERFLOW (past UINT32_MAX instances) or -ENOMEM, explained in err. */
int scene_instanced_add(struct scene_instanced *s, uint32_t mesh, const double xf[12],
                        bvhlab_error *err);
int scene_instanced_scatter(struct scene_instanced *s, const struct scene_scatter *sc,
                            bvhlab_error *err);
/* Instance i's mesh box carried to world space (its 8 corners' box). */
void scene_instanced_box(const struct scene_instanced *s, uint32_t i, bvhlab_aabb *out);
/* Triangles of the meshes once each, and of every instance. */
uint64_t scene_instanced_unique_triangles(const struct scene_instanced *s);
uint64_t scene_instanced_triangles(const struct scene_instanced *s);
/* Every instance's triangles in world space, in instance order, as one
 * mesh named `name`: -EOVERFLOW past UINT32_MAX vertices or triangles. */
int scene_instanced_flatten(const struct scene_instanced *s, const char *name,
                            bvhlab_scene **out, bvhlab_error *err);
/* Frees the meshes and instances; a zeroed s is fine. */
void scene_instanced_finish(struct scene_instanced *s);

#endif
