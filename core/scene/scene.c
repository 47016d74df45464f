/*
 * The scene model: allocation, names, bounds and degenerate count, and the
 * file reading and growable mesh the loaders build a scene with. Loading
 * by extension is scene_load.c, subdivision scene_subdivide.c.
 */
#include <errno.h>
#include <math.h>
#include <stdarg.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>
#include <fcntl.h>
#include <unistd.h>

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
	scene->part_count = 1;
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
static int regular_file_size(int fd, const char *path, size_t *size, bvhlab_error *err)
{
	struct stat st;

	if (fstat(fd, &st) != 0) {
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

/* Exactly `size` bytes from fd; a file that shrank meanwhile is a read error. */
static int read_exact(int fd, char *buf, size_t size)
{
	size_t got = 0;
	while (got < size) {
		ssize_t n = read(fd, buf + got, size - got);
		if (n < 0 && errno == EINTR)
			continue;
		if (n <= 0)
			return -EIO;
		got += (size_t)n;
	}
	return 0;
}

int scene_read_head(const char *path, size_t max, char **data, size_t *size,
                    bvhlab_error *err)
{
	/* O_NONBLOCK: opening a FIFO for reading would wait for a writer forever;
	 * this way it opens at once and fstat refuses it. */
	int fd = open(path, O_RDONLY | O_NONBLOCK | O_CLOEXEC);
	char *buf = NULL;
	int ret;

	if (fd < 0) {
		ret = -errno;
		scene_error(err, "%s: cannot open: %s", path, strerror(errno));
		return ret;
	}
	ret = regular_file_size(fd, path, size, err);
	if (ret)
		goto out;
	*size = *size < max ? *size : max;
	buf = malloc(*size + 1);
	if (!buf) {
		ret = -ENOMEM;
		scene_error(err, "%s: out of memory reading %zu bytes", path, *size);
	} else if (read_exact(fd, buf, *size) < 0) {
		ret = -EIO;
		scene_error(err, "%s: read error", path);
	} else {
		buf[*size] = '\0'; /* parsers may run strtod up to it */
		*data = buf;
		buf = NULL;
	}
out:
	free(buf);
	close(fd);
	return ret;
}

int scene_read_file(const char *path, char **data, size_t *size, bvhlab_error *err)
{
	return scene_read_head(path, SIZE_MAX, data, size, err);
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
	scene->part_count = 1;
	memset(mesh, 0, sizeof(*mesh));
	bvhlab_scene_update(scene);
	*out = scene;
	return 0;
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
	params->width = 0.001;
}
