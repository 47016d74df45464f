/*
 * Scenes: allocation, loading by extension, bounds, subdivision.
 */
#include <errno.h>
#include <math.h>
#include <stdarg.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <strings.h>
#include <sys/stat.h>

#include <bvhlab/aabb.h>

#include "scene/scene_private.h"

void scene_error(bvhlab_error *err, const char *fmt, ...)
{
	va_list ap;

	if (!err)
		return;
	va_start(ap, fmt);
	vsnprintf(err->message, sizeof(err->message), fmt, ap);
	va_end(ap);
}

int scene_alloc(uint32_t vertex_count, uint32_t triangle_count, bvhlab_scene **out,
                bvhlab_error *err)
{
	bvhlab_scene *scene = calloc(1, sizeof(*scene));

	if (!scene)
		goto fail;
	/* malloc(0) may return NULL; one spare element keeps "empty" distinct
	 * from "out of memory". */
	scene->vertices = malloc(((size_t)vertex_count * 3 + 1) * sizeof(float));
	scene->indices = malloc(((size_t)triangle_count * 3 + 1) * sizeof(uint32_t));
	if (!scene->vertices || !scene->indices)
		goto fail;
	scene->vertex_count = vertex_count;
	scene->triangle_count = triangle_count;
	bvhlab_aabb_empty(&scene->bounds);
	*out = scene;
	return 0;
fail:
	bvhlab_scene_destroy(scene);
	scene_error(err, "out of memory for a scene of %u vertices and %u triangles",
	            vertex_count, triangle_count);
	return -ENOMEM;
}

int scene_set_source(bvhlab_scene *scene, const char *fmt, ...)
{
	va_list ap;
	char *text;
	int n;

	va_start(ap, fmt);
	n = vasprintf(&text, fmt, ap);
	va_end(ap);
	if (n < 0)
		return -ENOMEM;
	free(scene->source);
	scene->source = text;
	return 0;
}

int scene_set_path_names(bvhlab_scene *scene, const char *path)
{
	const char *base = strrchr(path, '/');
	const char *dot;
	char *stem;

	base = base ? base + 1 : path;
	dot = strrchr(base, '.');
	stem = strndup(base, dot && dot != base ? (size_t)(dot - base) : strlen(base));
	if (!stem)
		return -ENOMEM;
	free(scene->name);
	scene->name = stem;
	return scene_set_source(scene, "%s", path);
}

/* The size of an open regular file; a directory or a pipe is refused. */
static int regular_file_size(FILE *f, const char *path, size_t *size, bvhlab_error *err)
{
	struct stat st;

	if (fstat(fileno(f), &st) != 0) {
		scene_error(err, "%s: cannot stat: %s", path, strerror(errno));
		return -EIO;
	}
	if (!S_ISREG(st.st_mode)) {
		scene_error(err, "%s: not a regular file", path);
		return S_ISDIR(st.st_mode) ? -EISDIR : -EINVAL;
	}
	*size = (size_t)st.st_size;
	return 0;
}

int scene_read_file(const char *path, char **data, size_t *size, bvhlab_error *err)
{
	FILE *f = fopen(path, "rb");
	char *buf = NULL;
	int ret;

	if (!f) {
		ret = -errno;
		scene_error(err, "%s: cannot open: %s", path, strerror(errno));
		return ret;
	}
	ret = regular_file_size(f, path, size, err);
	if (ret)
		goto out;
	buf = malloc(*size + 1);
	if (!buf) {
		ret = -ENOMEM;
		scene_error(err, "%s: out of memory reading %zu bytes", path, *size);
	} else if (fread(buf, 1, *size, f) != *size) {
		ret = -EIO;
		scene_error(err, "%s: read error", path);
	} else {
		buf[*size] = '\0'; /* parsers may run strtod up to it */
		*data = buf;
		buf = NULL;
	}
out:
	free(buf);
	fclose(f);
	return ret;
}

static int grow(void **array, size_t *cap, size_t need, size_t elem_size)
{
	size_t n = *cap ? *cap : 1024;
	void *p;

	while (n < need)
		n *= 2;
	if (n == *cap)
		return 0;
	p = realloc(*array, n * elem_size);
	if (!p)
		return -ENOMEM;
	*array = p;
	*cap = n;
	return 0;
}

int scene_mesh_reserve(struct scene_mesh *mesh, size_t vertices, size_t triangles)
{
	size_t v = mesh->vertex_cap, t = mesh->triangle_cap;
	int ret;

	ret = grow((void **)&mesh->vertices, &v, mesh->vertex_count + vertices, 3 * sizeof(float));
	if (ret)
		return ret;
	mesh->vertex_cap = v;
	ret = grow((void **)&mesh->indices, &t, mesh->triangle_count + triangles,
	           3 * sizeof(uint32_t));
	if (ret)
		return ret;
	mesh->triangle_cap = t;
	return 0;
}

void scene_mesh_free(struct scene_mesh *mesh)
{
	free(mesh->vertices);
	free(mesh->indices);
	memset(mesh, 0, sizeof(*mesh));
}

int scene_mesh_finish(struct scene_mesh *mesh, const char *path, bvhlab_scene **out,
                      bvhlab_error *err)
{
	bvhlab_scene *scene;

	if (mesh->vertex_count > UINT32_MAX || mesh->triangle_count > UINT32_MAX) {
		scene_error(err, "%s: too large: %zu vertices, %zu triangles (limit %u each)",
		            path, mesh->vertex_count, mesh->triangle_count, UINT32_MAX);
		scene_mesh_free(mesh);
		return -EOVERFLOW;
	}
	scene = calloc(1, sizeof(*scene));
	if (!scene || scene_mesh_reserve(mesh, 1, 1) || scene_set_path_names(scene, path)) {
		bvhlab_scene_destroy(scene);
		scene_mesh_free(mesh);
		scene_error(err, "%s: out of memory", path);
		return -ENOMEM;
	}
	scene->vertices = mesh->vertices;
	scene->vertex_count = (uint32_t)mesh->vertex_count;
	scene->indices = mesh->indices;
	scene->triangle_count = (uint32_t)mesh->triangle_count;
	memset(mesh, 0, sizeof(*mesh));
	bvhlab_scene_update(scene);
	*out = scene;
	return 0;
}

int bvhlab_scene_load(const char *path, bvhlab_scene **out, bvhlab_error *err)
{
	const char *base = strrchr(path, '/');
	const char *dot;

	base = base ? base + 1 : path;
	dot = strrchr(base, '.');
	if (dot && strcasecmp(dot, ".obj") == 0)
		return bvhlab_scene_load_obj(path, out, err);
	if (dot && strcasecmp(dot, ".ply") == 0)
		return bvhlab_scene_load_ply(path, out, err);
	scene_error(err, "%s: unknown scene file type (expected a .obj or .ply extension)", path);
	return -EINVAL;
}

static bool triangle_degenerate(const float *a, const float *b, const float *c)
{
	/* Double precision: the cross product of float differences is then exact
	 * enough that only truly collinear triangles give zero. */
	double e1[3], e2[3];

	for (int k = 0; k < 3; k++) {
		e1[k] = (double)b[k] - a[k];
		e2[k] = (double)c[k] - a[k];
	}
	return e1[1] * e2[2] - e1[2] * e2[1] == 0.0 && e1[2] * e2[0] - e1[0] * e2[2] == 0.0 &&
	       e1[0] * e2[1] - e1[1] * e2[0] == 0.0;
}

void bvhlab_scene_update(bvhlab_scene *scene)
{
	const uint32_t *idx = scene->indices;
	const float *v = scene->vertices;
	bvhlab_aabb box;

	bvhlab_aabb_empty(&box);
	scene->degenerate_count = 0;
	for (size_t t = 0; t < scene->triangle_count; t++, idx += 3) {
		for (int j = 0; j < 3; j++)
			bvhlab_aabb_grow_point(&box, v + 3 * (size_t)idx[j]);
		if (triangle_degenerate(v + 3 * (size_t)idx[0], v + 3 * (size_t)idx[1],
		                        v + 3 * (size_t)idx[2]))
			scene->degenerate_count++;
	}
	scene->bounds = box;
}

int bvhlab_scene_set_name(bvhlab_scene *scene, const char *name)
{
	char *copy = strdup(name);

	if (!copy)
		return -ENOMEM;
	free(scene->name);
	scene->name = copy;
	return 0;
}

void bvhlab_scene_destroy(bvhlab_scene *scene)
{
	if (!scene)
		return;
	free(scene->name);
	free(scene->source);
	free(scene->vertices);
	free(scene->indices);
	free(scene);
}

void bvhlab_gen_params_init(bvhlab_gen_params *params)
{
	memset(params, 0, sizeof(*params));
	params->frequency = 16;
	params->count = 10000;
	params->size = 256;
	params->seed = 1;
}

/* ---- subdivision --------------------------------------------------------- */

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
