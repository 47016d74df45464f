/*
 * OBJ loader: statements, face forms, polygons, relative indices, line
 * endings, and every error with its file and line.
 */
#include <errno.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <unistd.h>

#include <bvhlab/scene.h>

#include "scene/scene_private.h"
#include "scene_files.h"
#include "testutil.h"

static void test_statements(void)
{
	const char *path = write_text("mixed.obj",
		"# a comment\r\n"
		"mtllib scene.mtl\r\n"
		"o thing\r\n"
		"\r\n"
		"v 0.5 -1.25 3\r\n"
		"v 1e1 0 0 1.0\r\n"          /* optional w */
		"  v\t0 2 0\r\n"             /* leading blanks, tab */
		"v 1 1 1 0.5 0.5 0.5\r\n"    /* vertex colours */
		"vt 0 0\r\nvn 0 0 1\r\ng grp\r\ns off\r\nusemtl red\r\n"
		"f 1 2 3\r\n"
		"f 1/1 2/1 3/1 4/1 # quad with a comment\r\n"
		"f 1//1 2//1 3//1\r\n"
		"f 1/1/1 2/1/1 3/1/1\r\n"
		"curv 0 1 2\r\n"             /* unknown: counted */
		"bevel on\r\n"
		"v 9 9 9\r\n"
		"f 1 2 3 4 5");              /* pentagon, no final newline */
	struct scene_load_stats stats;
	bvhlab_scene *s = NULL;
	bvhlab_error err = { "" };

	CHECK_INT(scene_load_obj_stats(path, &s, &stats, &err), 0);
	if (!s)
		return;
	CHECK_INT(s->vertex_count, 5);
	CHECK_INT(s->triangle_count, 1 + 2 + 1 + 1 + 3);
	CHECK_INT(stats.unknown_statements, 2);
	CHECK(vertex_is(s, 0, 0.5f, -1.25f, 3.0f));
	CHECK(vertex_is(s, 1, 10.0f, 0, 0));
	CHECK(vertex_is(s, 2, 0, 2.0f, 0));
	CHECK(vertex_is(s, 4, 9.0f, 9.0f, 9.0f));
	CHECK(triangle_is(s, 0, 0, 1, 2));
	CHECK(triangle_is(s, 1, 0, 1, 2)); /* quad fan: (0,1,2), (0,2,3) */
	CHECK(triangle_is(s, 2, 0, 2, 3));
	CHECK(triangle_is(s, 7, 0, 3, 4));
	CHECK(strcmp(s->name, "mixed") == 0);
	CHECK(strcmp(s->source, path) == 0);
	CHECK(s->bounds.lo[0] == 0 && s->bounds.lo[1] == -1.25f && s->bounds.lo[2] == 0);
	CHECK(s->bounds.hi[0] == 10 && s->bounds.hi[1] == 9 && s->bounds.hi[2] == 9);
	CHECK_INT(s->degenerate_count, 0);
	bvhlab_scene_destroy(s);
}

static void test_relative_and_forward(void)
{
	const char *path = write_text("rel.obj",
		"v 0 0 0\nv 1 0 0\nv 0 1 0\n"
		"f -3 -2 -1\n"
		"f 4 1 2\n" /* refers forward to a later vertex */
		"v 0 0 1\n"
		"f -1 -4 -3\n");
	static const struct mesh_expect e = {
		.triangles = 3, .t = { { 0, 0, 1, 2 }, { 1, 3, 0, 1 }, { 2, 3, 0, 1 } }, .nt = 3,
	};
	bvhlab_scene *s = NULL;
	bvhlab_error err = { "" };

	CHECK_INT(bvhlab_scene_load_obj(path, &s, &err), 0);
	expect_mesh(s, &e);
	bvhlab_scene_destroy(s);
}

static void test_degenerate(void)
{
	const char *path = write_text("degen.obj",
		"v 0 0 0\nv 1 0 0\nv 2 0 0\nv 0 1 0\n"
		"f 1 2 3\n"  /* collinear */
		"f 1 1 4\n"  /* repeated vertex */
		"f 1 2 4\n");

	expect_degenerate(path);
}

/* Loading `text` fails with -EINVAL and a message containing PATH:`needle`. */
static void check_error(const char *name, const char *text, const char *needle)
{
	char at_line[256];

	snprintf(at_line, sizeof(at_line), ":%s", needle);
	expect_scene_error(write_text(name, text), -EINVAL, at_line);
}

static void test_errors(void)
{
	const char *tri = "v 0 0 0\nv 1 0 0\nv 0 1 0\n";
	char text[256];

	snprintf(text, sizeof(text), "%sf 1 2 0\n", tri);
	check_error("zero.obj", text, "4: vertex index 0");
	snprintf(text, sizeof(text), "%sf 1 2 3\nf 1 2 7\nf 1 2 3\n", tri);
	check_error("range.obj", text, "5: vertex index 7 out of range");
	snprintf(text, sizeof(text), "%sf 1 2 -4\n", tri);
	check_error("negrange.obj", text, "4: vertex index out of range: '-4'");
	snprintf(text, sizeof(text), "%sf 1 2\n", tri);
	check_error("short.obj", text, "4: face with 2 vertices");
	check_error("badnum.obj", "v 0 0 0\nv 1 abc 0\n", "2: malformed number 'abc'");
	check_error("badnum2.obj", "v 0 0 0\nv 1 2.5x 0\n", "2: malformed number '2.5x'");
	check_error("nan.obj", "v 0 0 0\nv nan 0 0\n", "2: coordinate is NaN or infinite");
	check_error("inf.obj", "\n\nv 0 -inf 0\n", "3: coordinate is NaN or infinite");
	check_error("huge.obj", "v 0 1e39 0\n", "1: coordinate is NaN or infinite");
	check_error("fewcoords.obj", "v 0 0\n", "1: vertex needs 3 coordinates");
	snprintf(text, sizeof(text), "%sf 1 2 x\n", tri);
	check_error("badface.obj", text, "4: malformed face vertex 'x'");
	snprintf(text, sizeof(text), "%sf 1 2/a 3\n", tri);
	check_error("badface2.obj", text, "4: malformed face vertex '2/a'");
	check_error("crlf.obj", "v 0 0 0\r\nv 1 0 0\r\nf 1 2 9\r\n", "3: vertex index 9");
}

static void test_no_faces_and_files(void)
{
	const char *path = write_text("nofaces.obj", "v 0 0 0\n");
	bvhlab_scene *s = NULL;
	bvhlab_error err = { "" };
	char missing[160];

	CHECK_INT(bvhlab_scene_load(path, &s, &err), -EINVAL);
	CHECK_CONTAINS(err.message, "nofaces.obj: no faces");

	snprintf(missing, sizeof(missing), "%s/missing.obj", tmpdir);
	CHECK_INT(bvhlab_scene_load(missing, &s, &err), -ENOENT);
	CHECK_CONTAINS(err.message, missing);
	CHECK(s == NULL);

	path = write_text("model.stl", "solid\n");
	CHECK_INT(bvhlab_scene_load(path, &s, &err), -EINVAL);
	CHECK_CONTAINS(err.message, "model.stl");
	CHECK_CONTAINS(err.message, ".obj or .ply");

	path = write_text("UPPER.OBJ", "v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 3\n");
	CHECK_INT(bvhlab_scene_load(path, &s, &err), 0);
	CHECK(s && s->triangle_count == 1 && strcmp(s->name, "UPPER") == 0);
	bvhlab_scene_destroy(s);
}

/* A generated 200K-triangle grid: checks every index and that the loader
 * scales (the time is printed, not asserted). */
static void test_large(void)
{
	const int n = 317; /* (n-1)^2 * 2 = 199712 triangles */
	const char *path = tmp_file("grid.obj");
	bvhlab_scene *s = NULL;
	bvhlab_error err = { "" };
	FILE *f;
	bool ok = true;

	f = fopen(path, "w");
	for (int i = 0; i < n * n; i++)
		fprintf(f, "v %d.25 %d.5 -0.125\n", i % n, i / n);
	for (int y = 0; y + 1 < n; y++)
		for (int x = 0; x + 1 < n; x++)
			fprintf(f, "f %d %d %d\nf -%d -%d -%d\n", y * n + x + 1, y * n + x + 2,
			        (y + 1) * n + x + 1, n * n - y * n - x - 1,
			        n * n - (y + 1) * n - x - 1, n * n - (y + 1) * n - x);
	fclose(f);
	CHECK_INT(bvhlab_scene_load(path, &s, &err), 0);
	if (!s)
		return;
	CHECK_INT(s->triangle_count, 2 * (n - 1) * (n - 1));
	for (uint32_t i = 0; i < 3 * s->triangle_count; i++)
		ok = ok && s->indices[i] < s->vertex_count;
	CHECK(ok);
	CHECK(vertex_is(s, (uint32_t)(n * n - 1), (float)(n - 1) + 0.25f, (float)(n - 1) + 0.5f,
	                -0.125f));
	CHECK_INT(s->degenerate_count, 0);
	bvhlab_scene_destroy(s);
}

int main(void)
{
	tmp_begin("obj");
	test_statements();
	test_relative_and_forward();
	test_degenerate();
	test_errors();
	test_no_faces_and_files();
	test_large();
	tmp_end();
	return test_finish();
}
