/*
 * Composite scenes: placing a part (scale, rotation, translation) and
 * merging parts into one scene. Real scenes are many objects at many
 * scales, some turned so their triangles lie diagonal to the axes; that is
 * where spatial splits matter, and a single scanned mesh does not show it.
 */
#include <errno.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "scene/instances.h"
#include "scene/scene_private.h"

void bvhlab_transform_init(bvhlab_transform *xf)
{
	memset(xf, 0, sizeof(*xf));
	xf->scale = 1.0;
}

/* Row-major 3x4: scale, then rotations about x, y, z in that order, then
 * the translation. */
void scene_transform_matrix(const bvhlab_transform *xf, double m[12])
{
	const double deg = 3.14159265358979323846 / 180.0;
	double cx = cos(xf->rotate[0] * deg), sx = sin(xf->rotate[0] * deg);
	double cy = cos(xf->rotate[1] * deg), sy = sin(xf->rotate[1] * deg);
	double cz = cos(xf->rotate[2] * deg), sz = sin(xf->rotate[2] * deg);
	/* Rz * Ry * Rx, so x's rotation applies first. */
	double r[3][3] = {
		{ cz * cy, cz * sy * sx - sz * cx, cz * sy * cx + sz * sx },
		{ sz * cy, sz * sy * sx + cz * cx, sz * sy * cx - cz * sx },
		{ -sy, cy * sx, cy * cx },
	};

	for (int i = 0; i < 3; i++) {
		for (int j = 0; j < 3; j++)
			m[4 * i + j] = r[i][j] * xf->scale;
		m[4 * i + 3] = xf->translate[i];
	}
}

void scene_matrix_apply(const double m[12], const double p[3], double w, double out[3])
{
	for (int i = 0; i < 3; i++)
		out[i] = m[4 * i] * p[0] + m[4 * i + 1] * p[1] + m[4 * i + 2] * p[2] + m[4 * i + 3] * w;
}

void bvhlab_scene_transform(bvhlab_scene *scene, const bvhlab_transform *xf)
{
	double m[12];

	scene_transform_matrix(xf, m);
	for (size_t v = 0; v < scene->vertex_count; v++) {
		float *p = scene->vertices + 3 * v;
		double q[3] = { p[0], p[1], p[2] }, r[3];

		scene_matrix_apply(m, q, 1.0, r);
		for (int i = 0; i < 3; i++)
			p[i] = (float)r[i];
	}
	bvhlab_scene_update(scene);
}

static int merge_counts(bvhlab_scene *const *parts, uint32_t count, uint32_t *vertices,
                        uint32_t *triangles, uint32_t *part_count, bvhlab_error *err)
{
	uint64_t v = 0, t = 0, p = 0;

	for (uint32_t i = 0; i < count; i++) {
		v += parts[i]->vertex_count;
		t += parts[i]->triangle_count;
		p += parts[i]->part_count ? parts[i]->part_count : 1;
	}
	if (v > UINT32_MAX || t > UINT32_MAX || p > UINT32_MAX) {
		scene_error(err, "composite scene too large: %llu vertices, %llu triangles "
		            "(limit %u each)", (unsigned long long)v, (unsigned long long)t,
		            UINT32_MAX);
		return -EOVERFLOW;
	}
	*vertices = (uint32_t)v;
	*triangles = (uint32_t)t;
	*part_count = (uint32_t)p;
	return 0;
}

int bvhlab_scene_merge(bvhlab_scene *const *parts, uint32_t count, const char *name,
                       bvhlab_scene **out, bvhlab_error *err)
{
	uint32_t vertices, triangles, part_count, vbase = 0;
	size_t tbase = 0;
	bvhlab_scene *scene = NULL;
	int rc = merge_counts(parts, count, &vertices, &triangles, &part_count, err);

	if (rc == 0)
		rc = scene_alloc(vertices, triangles, &scene, err);
	if (rc)
		return rc;
	for (uint32_t i = 0; i < count; i++) {
		const bvhlab_scene *p = parts[i];

		memcpy(scene->vertices + 3 * (size_t)vbase, p->vertices,
		       3 * (size_t)p->vertex_count * sizeof(float));
		for (size_t k = 0; k < 3 * (size_t)p->triangle_count; k++)
			scene->indices[3 * tbase + k] = p->indices[k] + vbase;
		vbase += p->vertex_count;
		tbase += p->triangle_count;
	}
	scene->part_count = part_count;
	if (bvhlab_scene_set_name(scene, name) ||
	    scene_set_source(scene, "composite of %u parts", part_count)) {
		bvhlab_scene_destroy(scene);
		scene_error(err, "%s: out of memory", name);
		return -ENOMEM;
	}
	bvhlab_scene_update(scene);
	*out = scene;
	return 0;
}
