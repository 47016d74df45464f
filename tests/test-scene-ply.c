/*
 * PLY loader: ASCII and binary of both byte orders, property types and
 * orders, skipped elements, tristrips, and errors with line or byte offset.
 */
#include <errno.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <unistd.h>

#include <bvhlab/scene.h>

#include "scene_files.h"
#include "testutil.h"

/* A file being assembled: header text, then binary or text body. */
struct buf {
	unsigned char data[4096];
	size_t len;
	bool big; /* byte order of put_* */
};

static void put_bytes(struct buf *b, const void *p, size_t n)
{
	unsigned char tmp[8];

	memcpy(tmp, p, n);
	for (size_t i = 0; i < n; i++)
		b->data[b->len++] = b->big ? tmp[n - 1 - i] : tmp[i];
}

static void put_text(struct buf *b, const char *s)
{
	memcpy(b->data + b->len, s, strlen(s));
	b->len += strlen(s);
}

static void put_u8(struct buf *b, uint8_t v) { put_bytes(b, &v, 1); }
static void put_u16(struct buf *b, uint16_t v) { put_bytes(b, &v, 2); }
static void put_i16(struct buf *b, int16_t v) { put_bytes(b, &v, 2); }
static void put_i32(struct buf *b, int32_t v) { put_bytes(b, &v, 4); }
static void put_u32(struct buf *b, uint32_t v) { put_bytes(b, &v, 4); }
static void put_f32(struct buf *b, float v) { put_bytes(b, &v, 4); }
static void put_f64(struct buf *b, double v) { put_bytes(b, &v, 8); }

static const char *write_buf(const char *name, const struct buf *b)
{
	return write_file(name, b->data, b->len);
}

static const char ascii_ply[] =
	"ply\n"
	"format ascii 1.0\n"
	"comment made by hand\n"
	"obj_info nothing\n"
	"element material 1\n"
	"property list uchar float weights\n"
	"property uchar id\n"
	"element vertex 5\n"
	"property float x\n"
	"property float y\n"
	"property float z\n"
	"property list int int tags\n"
	"element face 2\n"
	"property uchar flags\n"
	"property list uchar int vertex_indices\n"
	"end_header\n"
	"3 0.5 0.25 1 7\n"
	"0.5 -1.25 3 0\n"
	"1 0 0 2 10 11\n"
	"0 1 0 0\n"
	"1 1 0 1 -5\n"
	"2e-3 4 -8 0\n"
	"0 4 0 1 2 3\n"
	"9 3 2 3 4\n";

static void test_ascii(void)
{
	const char *path = write_text("ascii.ply", ascii_ply);
	static const struct mesh_expect e = {
		.vertices = 5, .triangles = 3,
		.v = { { 0, 0.5f, -1.25f, 3.0f }, { 4, 2e-3f, 4.0f, -8.0f } }, .nv = 2,
		.t = { { 0, 0, 1, 2 }, { 1, 0, 2, 3 }, { 2, 2, 3, 4 } }, .nt = 3,
	};
	bvhlab_scene *s = load_ok(path);

	if (expect_mesh(s, &e)) {
		CHECK(strcmp(s->name, "ascii") == 0);
		CHECK(strcmp(s->source, path) == 0);
	}
	bvhlab_scene_destroy(s);
}

/* Binary LE: float xyz plus normals, faces "list uchar int", CRLF header. */
static void build_le(struct buf *b)
{
	static const float v[4][3] = {
		{ 0, 0, 0 }, { 1.5f, 0, 0 }, { 0, -2.75f, 0 }, { 0, 0, 1e-7f },
	};

	b->len = 0;
	b->big = false;
	put_text(b, "ply\r\nformat binary_little_endian 1.0\r\nelement vertex 4\r\n"
	            "property float x\r\nproperty float y\r\nproperty float z\r\n"
	            "property float nx\r\nproperty float ny\r\nproperty float nz\r\n"
	            "element face 2\r\nproperty list uchar int vertex_indices\r\nend_header\r\n");
	for (int i = 0; i < 4; i++) {
		for (int k = 0; k < 3; k++)
			put_f32(b, v[i][k]);
		for (int k = 0; k < 3; k++)
			put_f32(b, 0.5f);
	}
	put_u8(b, 3), put_i32(b, 0), put_i32(b, 1), put_i32(b, 2);
	put_u8(b, 4), put_i32(b, 0), put_i32(b, 1), put_i32(b, 2), put_i32(b, 3);
}

static void test_binary_le(void)
{
	static const struct mesh_expect e = {
		.vertices = 4, .triangles = 3,
		.v = { { 1, 1.5f, 0, 0 }, { 2, 0, -2.75f, 0 }, { 3, 0, 0, 1e-7f } }, .nv = 3,
		.t = { { 2, 0, 2, 3 } }, .nt = 1,
	};
	struct buf b;
	bvhlab_scene *s;

	build_le(&b);
	s = load_ok(write_buf("le.ply", &b));
	expect_mesh(s, &e);
	bvhlab_scene_destroy(s);
}

/* Binary BE: an element before the vertices, double coordinates in z y x
 * order, faces "list int ushort vertex_index", an element with lists after. */
static void test_binary_be(void)
{
	static const struct mesh_expect e = {
		.vertices = 3, .triangles = 1,
		.v = { { 0, 1.0f, 2.0f, 3.0f }, { 1, 1e10f, -0.5f, (float)0.1 } }, .nv = 2,
		.t = { { 0, 2, 1, 0 } }, .nt = 1,
	};
	struct buf b = { .big = true };
	bvhlab_scene *s;

	put_text(&b, "ply\nformat binary_big_endian 1.0\nelement camera 2\n"
	             "property short view\nproperty double fov\n"
	             "element vertex 3\nproperty double z\nproperty double y\nproperty double x\n"
	             "element face 1\nproperty list int ushort vertex_index\n"
	             "element edge 2\nproperty list uint16 uint vertex\nproperty uchar c\n"
	             "end_header\n");
	put_i16(&b, -3), put_f64(&b, 1.0), put_i16(&b, 4), put_f64(&b, 2.0);
	put_f64(&b, 3.0), put_f64(&b, 2.0), put_f64(&b, 1.0);
	put_f64(&b, 0.1), put_f64(&b, -0.5), put_f64(&b, 1e10);
	put_f64(&b, 0.0), put_f64(&b, 0.0), put_f64(&b, 0.0);
	put_i32(&b, 3), put_u16(&b, 2), put_u16(&b, 1), put_u16(&b, 0);
	put_u16(&b, 2), put_u32(&b, 0), put_u32(&b, 1), put_u8(&b, 9);
	put_u16(&b, 1), put_u32(&b, 2), put_u8(&b, 9);
	s = load_ok(write_buf("be.ply", &b));
	expect_mesh(s, &e);
	bvhlab_scene_destroy(s);
}

/* Integer coordinate types, faces "list uint16 int". */
static void test_integer_coords(void)
{
	static const struct mesh_expect e = {
		.triangles = 1, .v = { { 0, -300.0f, 200.0f, -70000.0f } }, .nv = 1,
	};
	struct buf b = { .big = false };
	bvhlab_scene *s;

	put_text(&b, "ply\nformat binary_little_endian 1.0\nelement vertex 3\n"
	             "property short x\nproperty uchar y\nproperty int z\n"
	             "element face 1\nproperty list uint16 int vertex_indices\nend_header\n");
	put_i16(&b, -300), put_u8(&b, 200), put_i32(&b, -70000);
	put_i16(&b, 1), put_u8(&b, 0), put_i32(&b, 0);
	put_i16(&b, 0), put_u8(&b, 1), put_i32(&b, 0);
	put_u16(&b, 3), put_i32(&b, 0), put_i32(&b, 1), put_i32(&b, 2);
	s = load_ok(write_buf("ints.ply", &b));
	expect_mesh(s, &e);
	bvhlab_scene_destroy(s);
}

/* Strips with -1 restarts and triangles that repeat an index, which are
 * dropped while the winding keeps alternating. */
static const int32_t strip[] = { 0, 1, 2, 3, -1, 4, 5, 6, 6, 7, 5 };
#define STRIP_LEN ((int)(sizeof(strip) / sizeof(strip[0])))

static void check_strips(bvhlab_scene *s)
{
	static const struct mesh_expect e = {
		.triangles = 4,
		.t = { { 0, 0, 1, 2 }, { 1, 2, 1, 3 }, { 2, 4, 5, 6 }, { 3, 7, 6, 5 } }, .nt = 4,
	};

	expect_mesh(s, &e);
	bvhlab_scene_destroy(s);
}

static void put_strip_vertices(struct buf *b)
{
	for (int i = 0; i < 8; i++)
		put_f32(b, (float)(i % 3)), put_f32(b, (float)(i / 3)), put_f32(b, (float)(i % 2));
}

static void test_tristrips(void)
{
	struct buf b = { .big = false };
	char text[1024];
	size_t n;

	put_text(&b, "ply\nformat binary_little_endian 1.0\nelement vertex 8\n"
	             "property float x\nproperty float y\nproperty float z\n"
	             "element tristrips 1\nproperty list int int vertex_indices\nend_header\n");
	put_strip_vertices(&b);
	put_i32(&b, STRIP_LEN);
	for (int i = 0; i < STRIP_LEN; i++)
		put_i32(&b, strip[i]);
	check_strips(load_ok(write_buf("strips.ply", &b)));

	n = (size_t)snprintf(text, sizeof(text), "ply\nformat ascii 1.0\nelement vertex 8\n"
	                     "property float x\nproperty float y\nproperty float z\n"
	                     "element tristrips 1\nproperty list uchar short vertex_indices\n"
	                     "end_header\n");
	for (int i = 0; i < 8; i++)
		n += (size_t)snprintf(text + n, sizeof(text) - n, "%d %d %d\n", i % 3, i / 3,
		                      i % 2);
	n += (size_t)snprintf(text + n, sizeof(text) - n, "%d", STRIP_LEN);
	for (int i = 0; i < STRIP_LEN; i++)
		n += (size_t)snprintf(text + n, sizeof(text) - n, " %d", strip[i]);
	check_strips(load_ok(write_text("strips-ascii.ply", text)));
}

static void test_binary_errors(void)
{
	struct buf b;
	const char *path;
	char needle[96];
	size_t header, faces;

	build_le(&b);
	header = b.len - 4 * 24 - (1 + 12) - (1 + 16);
	faces = header + 4 * 24;
	/* The last index (4 bytes) is cut to 1 byte. */
	b.len -= 3;
	path = write_buf("cut.ply", &b);
	snprintf(needle, sizeof(needle), ": byte offset %zu: truncated file", b.len - 1);
	expect_scene_error(path, -EINVAL, needle);

	build_le(&b);
	b.data[faces + 1 + 4] = 4; /* second index of the first face: 4 of 4 vertices */
	path = write_buf("badindex.ply", &b);
	snprintf(needle, sizeof(needle), ": byte offset %zu: vertex index 4 out of range",
	         faces + 1 + 4);
	expect_scene_error(path, -EINVAL, needle);

	build_le(&b);
	memset(b.data + faces + 1 + 8, 0xff, 4); /* -1 in a face */
	path = write_buf("negindex.ply", &b);
	snprintf(needle, sizeof(needle), ": byte offset %zu: negative vertex index", faces + 9);
	expect_scene_error(path, -EINVAL, needle);

	build_le(&b);
	memcpy(b.data + header + 24 + 4, (const unsigned char[]){ 0, 0, 0xc0, 0x7f }, 4); /* NaN */
	path = write_buf("nan.ply", &b);
	snprintf(needle, sizeof(needle), ": byte offset %zu: vertex 1: coordinate y is NaN",
	         header + 28);
	expect_scene_error(path, -EINVAL, needle);

	build_le(&b);
	b.len = header + 10; /* inside the vertices */
	path = write_buf("cutvertex.ply", &b);
	expect_scene_error(path, -EINVAL, ": byte offset");
}

static void test_header_errors(void)
{
	const char *ok_tail = "element face 1\nproperty list uchar int vertex_indices\nend_header\n"
	                      "0 0 0\n1 0 0\n0 1 0\n3 0 1 2\n";
	const char *xyz = "property float x\nproperty float y\nproperty float z\n";
	char text[1024];
	char missing[160];

	expect_scene_error(write_text("magic.ply", "plx\nformat ascii 1.0\n"), -EINVAL,
	            ":1: bad PLY header");
	expect_scene_error(write_text("fmt.ply", "ply\nformat utf8 1.0\n"), -EINVAL, ":2: bad PLY header");
	snprintf(text, sizeof(text), "ply\nformat ascii 1.0\nelement vertex 3\nproperty flt x\n%s",
	         ok_tail);
	expect_scene_error(write_text("type.ply", text), -EINVAL,
	            ":4: bad PLY header: unknown property type");
	expect_scene_error(write_text("noend.ply", "ply\nformat ascii 1.0\nelement vertex 3\n"), -EINVAL,
	            ":4: bad PLY header: missing 'end_header'");
	snprintf(text, sizeof(text), "ply\nformat ascii 1.0\nproperty float x\n");
	expect_scene_error(write_text("noelem.ply", text), -EINVAL, ":3: bad PLY header: property before");
	snprintf(text, sizeof(text), "ply\nformat ascii 1.0\nelement vertex 3\nproperty float x\n"
	         "property float y\n%s", ok_tail);
	expect_scene_error(write_text("noz.ply", text), -EINVAL,
	            ":3: element 'vertex' has no property 'z'");
	snprintf(text, sizeof(text), "ply\nformat ascii 1.0\nelement vertex 3\n%send_header\n"
	         "0 0 0\n1 0 0\n0 1 0\n", xyz);
	expect_scene_error(write_text("nofaces.ply", text), -EINVAL, ":7: no faces");
	snprintf(text, sizeof(text), "ply\nformat ascii 1.0\nelement vertex 3\n%s"
	         "element face 0\nproperty list uchar int vertex_indices\nend_header\n"
	         "0 0 0\n1 0 0\n0 1 0\n", xyz);
	expect_scene_error(write_text("zerofaces.ply", text), -EINVAL, ":9: no faces");

	snprintf(missing, sizeof(missing), "%s/missing.ply", tmpdir);
	expect_scene_error(missing, -ENOENT, ": cannot open");
}

static void test_ascii_errors(void)
{
	const char *head = "ply\nformat ascii 1.0\nelement vertex 3\nproperty float x\n"
	                   "property float y\nproperty float z\nelement face 1\n"
	                   "property list uchar int vertex_indices\nend_header\n";
	static const struct {
		const char *file, *body, *error;
	} cases[] = {
		{ "a-range.ply", "0 0 0\n1 0 0\n0 1 0\n3 0 1 3\n", ":13: vertex index 3 out of range" },
		{ "a-neg.ply", "0 0 0\n1 0 0\n0 1 0\n3 0 -2 1\n", ":13: negative vertex index" },
		{ "a-num.ply", "0 0 0\n1 zero 0\n0 1 0\n3 0 1 2\n", ":11: malformed number" },
		{ "a-inf.ply", "0 0 0\n1 inf 0\n0 1 0\n3 0 1 2\n", ":11: vertex 1: coordinate y is NaN" },
		{ "a-cut.ply", "0 0 0\n1 0 0\n0 1 0\n3 0 1\n", ":13: truncated file" },
		{ "a-short.ply", "0 0 0\n1 0 0\n0 1 0\n2 0 1\n", ":13: face 0 has 2 vertices" },
		{ "a-count.ply", "0 0 0\n1 0 0\n0 1 0\n300 0 1 2\n", ":13: value out of range" },
	};
	char text[512];

	for (size_t k = 0; k < sizeof(cases) / sizeof(cases[0]); k++) {
		snprintf(text, sizeof(text), "%s%s", head, cases[k].body);
		expect_scene_error(write_text(cases[k].file, text), -EINVAL, cases[k].error);
	}
}

/* Faces may come before the vertices they index. */
static void test_faces_first(void)
{
	static const struct mesh_expect e = {
		.triangles = 1, .v = { { 2, 0, 1.0f, 0 } }, .nv = 1, .t = { { 0, 2, 0, 1 } }, .nt = 1,
	};
	bvhlab_scene *s = load_ok(write_text("facesfirst.ply",
		"ply\nformat ascii 1.0\nelement face 1\nproperty list uchar uint vertex_indices\n"
		"element vertex 3\nproperty float x\nproperty float y\nproperty float z\n"
		"end_header\n3 2 0 1\n0 0 0\n1 0 0\n0 1 0\n"));

	expect_mesh(s, &e);
	bvhlab_scene_destroy(s);
}

static void test_extension_case(void)
{
	bvhlab_scene *s = load_ok(write_text("UPPER.PLY", ascii_ply));

	CHECK(s && s->triangle_count == 3);
	bvhlab_scene_destroy(s);
}

int main(void)
{
	tmp_begin("ply");
	test_ascii();
	test_binary_le();
	test_binary_be();
	test_integer_coords();
	test_tristrips();
	test_binary_errors();
	test_header_errors();
	test_ascii_errors();
	test_faces_first();
	test_extension_case();
	tmp_end();
	return test_finish();
}
