/*
 * Mesh files the loader tests write into a temporary folder, and the
 * checks they make on what loads. Call tmp_begin(tag) first and
 * tmp_end() last; files written in between are removed by tmp_end.
 */
#ifndef BVHLAB_SCENE_FILES_H
#define BVHLAB_SCENE_FILES_H

#include <stdbool.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <unistd.h>

#include <bvhlab/scene.h>

#include "testutil.h"

#define TMP_FILES 64

static char tmpdir[64];
static char tmp_files[TMP_FILES][128];
static int tmp_file_count;

/* Makes the folder /tmp/bvhlab-test-TAG-XXXXXX, or exits. */
static inline void tmp_begin(const char *tag)
{
	snprintf(tmpdir, sizeof(tmpdir), "/tmp/bvhlab-test-%s-XXXXXX", tag);
	if (!mkdtemp(tmpdir)) {
		perror("mkdtemp");
		exit(1);
	}
}

/* tmpdir/name, for a file the caller writes; tmp_end removes it. */
static inline const char *tmp_file(const char *name)
{
	if (tmp_file_count == TMP_FILES) {
		fprintf(stderr, "scene_files.h: more than %d files\n", TMP_FILES);
		exit(1);
	}
	char *path = tmp_files[tmp_file_count++];
	snprintf(path, sizeof(tmp_files[0]), "%s/%s", tmpdir, name);
	return path;
}

/* tmpdir/name for a path the caller only compares or makes itself (a
 * folder, a file that must not exist); tmp_end leaves it. Eight rotate, so
 * one expression may hold several. */
static inline const char *tmp_path(const char *name)
{
	static char buf[8][256];
	static int next;
	char *out = buf[next++ % 8];
	snprintf(out, sizeof(buf[0]), "%s/%s", tmpdir, name);
	return out;
}

/* Writes data to tmpdir/name and returns the path (valid until tmp_end). */
static inline const char *write_file(const char *name, const void *data, size_t len)
{
	const char *path = tmp_file(name);
	FILE *f = fopen(path, "wb");
	if (!f) {
		perror(path);
		exit(1);
	}
	fwrite(data, 1, len, f);
	fclose(f);
	return path;
}

static inline const char *write_text(const char *name, const char *text)
{
	return write_file(name, text, strlen(text));
}

/* Removes the files written, then the folder if nothing else is in it. */
static inline void tmp_end(void)
{
	for (int i = 0; i < tmp_file_count; i++)
		unlink(tmp_files[i]);
	rmdir(tmpdir);
}

static inline bool vertex_is(const bvhlab_scene *s, uint32_t i, float x, float y, float z)
{
	const float *v = s->vertices + 3 * i;

	return v[0] == x && v[1] == y && v[2] == z;
}

static inline bool triangle_is(const bvhlab_scene *s, uint32_t t, uint32_t a, uint32_t b,
                               uint32_t c)
{
	const uint32_t *i = s->indices + 3 * t;

	return i[0] == a && i[1] == b && i[2] == c;
}

/* What a loaded mesh must hold: its vertex count (0: not checked), its
 * triangle count, and up to 4 vertices and 4 triangles by index. */
struct mesh_expect {
	uint32_t vertices, triangles;
	struct {
		uint32_t at;
		float x, y, z;
	} v[4];
	uint32_t nv;
	struct {
		uint32_t at, a, b, c;
	} t[4];
	uint32_t nt;
};

/* s against e; false when s is NULL (its load already failed a check). */
static inline bool expect_mesh(const bvhlab_scene *s, const struct mesh_expect *e)
{
	if (!s)
		return false;
	if (e->vertices)
		CHECK_INT(s->vertex_count, e->vertices);
	CHECK_INT(s->triangle_count, e->triangles);
	for (uint32_t k = 0; k < e->nv; k++)
		CHECK(e->v[k].at < s->vertex_count &&
		      vertex_is(s, e->v[k].at, e->v[k].x, e->v[k].y, e->v[k].z));
	for (uint32_t k = 0; k < e->nt; k++)
		CHECK(e->t[k].at < s->triangle_count &&
		      triangle_is(s, e->t[k].at, e->t[k].a, e->t[k].b, e->t[k].c));
	return true;
}

/* The scene at path, which must load (NULL, a failed check, if not). */
static inline bvhlab_scene *load_ok(const char *path)
{
	bvhlab_scene *s = NULL;
	bvhlab_error err = { "" };
	int ret = bvhlab_scene_load(path, &s, &err);

	CHECK_INT(ret, 0);
	if (ret)
		fprintf(stderr, "  %s\n", err.message);
	return s;
}

/* The degenerate mesh every loader test writes: 3 triangles, 2 of zero
 * area, all kept (a builder must cope) and counted. */
static inline void expect_degenerate(const char *path)
{
	bvhlab_scene *s = load_ok(path);

	if (!s)
		return;
	CHECK_INT(s->triangle_count, 3);
	CHECK_INT(s->degenerate_count, 2);
	bvhlab_scene_destroy(s);
}

/* Loading fails with `code` and a message holding the path, then `needle`. */
static inline void expect_scene_error(const char *path, int code, const char *needle)
{
	bvhlab_scene *s = NULL;
	bvhlab_error err = { "" };
	char where[512];

	CHECK_INT(bvhlab_scene_load(path, &s, &err), code);
	CHECK(s == NULL);
	snprintf(where, sizeof(where), "%s%s", path, needle);
	CHECK_CONTAINS(err.message, where);
	bvhlab_scene_destroy(s);
}

#endif /* BVHLAB_SCENE_FILES_H */
