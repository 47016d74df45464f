/*
 * Scene internals shared by the loaders, the generators and scene.c
 * (private to the core).
 *
 * Loaders do not know their final sizes up front, so they collect geometry
 * in a growable scene_mesh and turn it into a bvhlab_scene at the end;
 * generators know their sizes and allocate the scene directly.
 */
#ifndef BVHLAB_CORE_SCENE_PRIVATE_H
#define BVHLAB_CORE_SCENE_PRIVATE_H

#include <stddef.h>
#include <stdint.h>

#include <bvhlab/scene.h>

/* printf into err->message; err may be NULL. */
void scene_error(bvhlab_error *err, const char *fmt, ...) BVHLAB_PRINTF(2, 3);

/* The largest coordinate magnitude a loader accepts: a box's surface area
 * (its extent squared, times 6) must stay finite in float for the SAH, and
 * (2 * 1e18)^2 * 6 is ~2.4e37, under FLT_MAX's 3.4e38. */
#define SCENE_MAX_COORD 1e18f

/*
 * A scene with uninitialised vertex and index arrays of the given sizes,
 * name and source NULL, bounds empty. 0, -ENOMEM or -EOVERFLOW.
 */
int scene_alloc(uint32_t vertex_count, uint32_t triangle_count, bvhlab_scene **out,
                bvhlab_error *err);

/* Sets source from a printf format. 0 or -ENOMEM. */
int scene_set_source(bvhlab_scene *scene, const char *fmt, ...) BVHLAB_PRINTF(2, 3);

/* Name = the file's stem ("dir/ogre.obj" -> "ogre"), source = path. */
int scene_set_path_names(bvhlab_scene *scene, const char *path);

/*
 * Reads a whole file into a NUL-terminated buffer (the NUL is not counted
 * in *size). On failure: -errno and "PATH: ..." in err.
 */
int scene_read_file(const char *path, char **data, size_t *size, bvhlab_error *err);
/* Same, for at most the first `max` bytes of the file (a header). */
int scene_read_head(const char *path, size_t max, char **data, size_t *size,
                    bvhlab_error *err);

/* Geometry collected by a loader; zero-initialise before use. */
struct scene_mesh {
	float *vertices;         /* [3 * vertex_cap] */
	size_t vertex_count, vertex_cap;
	uint32_t *indices;       /* [3 * triangle_cap] */
	size_t triangle_count, triangle_cap;
};

/* Makes room for `vertices` more vertices and `triangles` more triangles. */
int scene_mesh_reserve(struct scene_mesh *mesh, size_t vertices, size_t triangles);

/* Appends; the caller reserved room (hot paths of the loaders). */
static inline void scene_mesh_put_vertex(struct scene_mesh *mesh, float x, float y, float z)
{
	float *v = mesh->vertices + 3 * mesh->vertex_count++;
	v[0] = x;
	v[1] = y;
	v[2] = z;
}

static inline void scene_mesh_put_triangle(struct scene_mesh *mesh, uint32_t a, uint32_t b,
                                           uint32_t c)
{
	uint32_t *t = mesh->indices + 3 * mesh->triangle_count++;
	t[0] = a;
	t[1] = b;
	t[2] = c;
}

/*
 * Moves the mesh into a new scene named after `path` and computes its
 * bounds; the mesh is left empty. Fails (-EOVERFLOW) when a count does not
 * fit in uint32_t; the mesh is freed either way.
 */
int scene_mesh_finish(struct scene_mesh *mesh, const char *path, bvhlab_scene **out,
                      bvhlab_error *err);

void scene_mesh_free(struct scene_mesh *mesh);

/* What a loader skipped without failing (for tests and diagnostics). */
struct scene_load_stats {
	size_t unknown_statements; /* OBJ: lines with a statement it does not know */
};

/* bvhlab_scene_load_obj, also reporting what was skipped; stats may be NULL. */
int scene_load_obj_stats(const char *path, bvhlab_scene **out,
                         struct scene_load_stats *stats, bvhlab_error *err);

/* The "needles" generator (scene_needles.c); `source` gets its description. */
int scene_gen_needles(const bvhlab_gen_params *params, bvhlab_scene **out, char *source,
                      size_t source_size, bvhlab_error *err);

/* The "room" generator (scene_room.c): 12 huge triangles, no parameters. */
int scene_gen_room(const bvhlab_gen_params *params, bvhlab_scene **out, char *source,
                   size_t source_size, bvhlab_error *err);

#endif /* BVHLAB_CORE_SCENE_PRIVATE_H */
