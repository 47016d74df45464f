/*
 * Subdivision: every triangle into 4 through its edge midpoints, shared
 * edges sharing their midpoint vertex, so a closed mesh stays closed.
 */
#include <errno.h>
#include <stdint.h>
#include <stdlib.h>
#include <string.h>

#include "scene/scene_private.h"

/* Edge -> midpoint vertex, open addressing; a key packs both endpoints. */
struct edge_table {
	uint64_t *keys;
	uint32_t *values;
	size_t mask;
	unsigned shift;
};

#define EDGE_EMPTY UINT64_MAX /* (UINT32_MAX, UINT32_MAX) is never a valid edge */

static int edge_table_init(struct edge_table *table, size_t max_edges)
{
	size_t cap = 16;
	unsigned bits = 4;

	/* Closed meshes fill about a third of this, triangle soups up to 3/4. */
	for (; cap < max_edges + max_edges / 3; bits++)
		cap *= 2;
	table->keys = malloc(cap * sizeof(uint64_t));
	table->values = malloc(cap * sizeof(uint32_t));
	if (!table->keys || !table->values)
		return -ENOMEM;
	memset(table->keys, 0xff, cap * sizeof(uint64_t));
	table->mask = cap - 1;
	table->shift = 64 - bits;
	return 0;
}

static void edge_table_free(struct edge_table *table)
{
	free(table->keys);
	free(table->values);
}

static size_t edge_slot(const struct edge_table *table, uint64_t key)
{
	size_t i = (size_t)((key * 0x9e3779b97f4a7c15ull) >> table->shift);

	while (table->keys[i] != key && table->keys[i] != EDGE_EMPTY)
		i = (i + 1) & table->mask;
	return i;
}

/*
 * Gives every distinct edge a new vertex index after the existing ones and
 * records, per triangle corner j, the midpoint of edge (j, j+1). Returns the
 * new vertex count, which the caller checks against UINT32_MAX.
 */
static uint64_t number_edges(const bvhlab_scene *scene, struct edge_table *table,
                             uint32_t *mids)
{
	uint64_t next = scene->vertex_count;

	for (size_t i = 0; i < 3 * (size_t)scene->triangle_count; i++) {
		uint32_t a = scene->indices[i];
		uint32_t b = scene->indices[i % 3 == 2 ? i - 2 : i + 1];
		uint64_t key = a < b ? (uint64_t)a << 32 | b : (uint64_t)b << 32 | a;
		size_t slot;

		if (a == b) { /* a collapsed edge's midpoint is its end */
			mids[i] = a;
			continue;
		}
		slot = edge_slot(table, key);
		if (table->keys[slot] == EDGE_EMPTY) {
			table->keys[slot] = key;
			table->values[slot] = (uint32_t)next++;
		}
		mids[i] = table->values[slot];
	}
	return next;
}

static void put_midpoints(float *vertices, const struct edge_table *table)
{
	for (size_t i = 0; i <= table->mask; i++) {
		const float *a, *b;
		float *m;

		if (table->keys[i] == EDGE_EMPTY)
			continue;
		a = vertices + 3 * (size_t)(table->keys[i] >> 32);
		b = vertices + 3 * (size_t)(table->keys[i] & UINT32_MAX);
		m = vertices + 3 * (size_t)table->values[i];
		for (int k = 0; k < 3; k++)
			m[k] = (a[k] + b[k]) * 0.5f;
	}
}

/* Corner triangles keep the parent's winding, the middle one too. */
static void split_triangles(const uint32_t *in, const uint32_t *mids, size_t count,
                            uint32_t *out)
{
	for (size_t t = 0; t < count; t++, in += 3, mids += 3, out += 12) {
		uint32_t a = in[0], b = in[1], c = in[2];
		uint32_t ab = mids[0], bc = mids[1], ca = mids[2];
		const uint32_t quad[12] = { a, ab, ca, ab, b, bc, ca, bc, c, ab, bc, ca };

		memcpy(out, quad, sizeof(quad));
	}
}

static int subdivide_once(bvhlab_scene *scene, bvhlab_error *err)
{
	size_t count = scene->triangle_count;
	struct edge_table table = { 0 };
	uint32_t *mids = malloc(3 * count * sizeof(uint32_t) + 1), *indices;
	uint64_t vertex_count;
	float *vertices;
	int ret = -ENOMEM;

	if (!mids || edge_table_init(&table, 3 * count))
		goto nomem;
	vertex_count = number_edges(scene, &table, mids);
	if (vertex_count > UINT32_MAX) {
		scene_error(err, "subdivide: %llu vertices, more than the %u a scene can hold",
		            (unsigned long long)vertex_count, UINT32_MAX);
		ret = -EOVERFLOW;
		goto out;
	}
	vertices = realloc(scene->vertices, (size_t)vertex_count * 3 * sizeof(float));
	if (!vertices)
		goto nomem;
	scene->vertices = vertices;
	put_midpoints(vertices, &table);
	indices = malloc(12 * count * sizeof(uint32_t) + 1);
	if (!indices)
		goto nomem;
	split_triangles(scene->indices, mids, count, indices);
	free(scene->indices);
	scene->indices = indices;
	scene->vertex_count = (uint32_t)vertex_count;
	scene->triangle_count = (uint32_t)(4 * count);
	ret = 0;
	goto out;
nomem:
	scene_error(err, "subdivide: out of memory splitting %zu triangles", count);
out:
	free(mids);
	edge_table_free(&table);
	return ret;
}

int bvhlab_scene_subdivide(bvhlab_scene *scene, unsigned levels, bvhlab_error *err)
{
	uint64_t count = scene->triangle_count;
	int ret = 0;

	for (unsigned i = 0; i < levels && count <= UINT32_MAX; i++)
		count *= 4;
	if (count > UINT32_MAX) {
		scene_error(err, "subdivide %u: %u triangles times 4^%u exceeds the limit of "
		            "%u triangles", levels, scene->triangle_count, levels, UINT32_MAX);
		return -EOVERFLOW;
	}
	for (unsigned i = 0; i < levels; i++) {
		ret = subdivide_once(scene, err);
		if (ret)
			break;
	}
	/* Also after a failed later level: the scene stays consistent. */
	if (levels)
		bvhlab_scene_update(scene);
	return ret;
}
