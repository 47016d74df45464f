/*
 * The bad-input catalogue, where the loaders' own tests (test-scene-obj,
 * test-scene-ply, test-config) leave gaps: empty files, wrong PLY element
 * counts, degenerate triangles in PLY, folders, unreadable files and
 * missing files as scenes and configs, unknown plugin names. Each failure
 * is checked for its message, not only its code. Then every input of
 * tests/fuzz-regress/ and the fuzz seed corpora goes through its loader.
 */
#include <dirent.h>
#include <errno.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>
#include <unistd.h>

#include <bvhlab/bvhlab.h>

#include "config/config.h"
#include "scene_files.h"
#include "testutil.h"

#define PLY_XYZ "property float x\nproperty float y\nproperty float z\n"
#define PLY_FACE "element face 1\nproperty list uchar int vertex_indices\n"

static void test_empty(void)
{
	expect_scene_error(write_text("empty.obj", ""), -EINVAL, ": no faces");
	expect_scene_error(write_text("comments.obj", "# nothing\n\n"), -EINVAL, ": no faces");
	expect_scene_error(write_text("empty.ply", ""), -EINVAL,
	                   ":1: bad PLY header: missing 'end_header'");
	expect_scene_error(write_text("noelements.ply", "ply\nformat ascii 1.0\nend_header\n"),
	                   -EINVAL, ":3: no 'vertex' element");
	/* Vertices but not one face. */
	expect_scene_error(write_text("novface.ply", "ply\nformat ascii 1.0\nelement vertex 1\n"
	                              PLY_XYZ "element face 0\nproperty list uchar int "
	                              "vertex_indices\nend_header\n0 0 0\n"),
	                   -EINVAL, ":9: no faces");
}

/* Counts in the header that do not match the data, both ways. */
static void test_element_counts(void)
{
	const char *head = "ply\nformat ascii 1.0\nelement vertex 3\n" PLY_XYZ PLY_FACE
	                   "end_header\n";
	char text[512];
	unsigned char bin[256];
	size_t n;

	snprintf(text, sizeof(text), "%s0 0 0\n1 0 0\n0 1 0\n3 0 1 2\n3 2 1 0\n\n", head);
	expect_scene_error(write_text("toomany.ply", text), -EINVAL,
	                   ":14: 9 bytes of data after the last element 'face' (wrong element "
	                   "counts in the header?)");
	snprintf(text, sizeof(text), "%s0 0 0\n1 0 0\n3 0 1 2\n", head);
	expect_scene_error(write_text("toofew.ply", text), -EINVAL, ":12: truncated file");
	snprintf(text, sizeof(text), "%s0 0 0\n1 0 0\n0 1 0\n3 0 1 2\n \r\n\t\n", head);
	bvhlab_scene *s = NULL;
	bvhlab_error err = { "" };
	CHECK_INT(bvhlab_scene_load(write_text("blanks.ply", text), &s, &err), 0);
	bvhlab_scene_destroy(s);

	/* Binary: one whole face more than the header declares. */
	n = (size_t)snprintf((char *)bin, sizeof(bin),
	                     "ply\nformat binary_little_endian 1.0\nelement vertex 3\n"
	                     PLY_XYZ PLY_FACE "end_header\n");
	size_t header = n;
	float xyz[9] = { 0, 0, 0, 1, 0, 0, 0, 1, 0 };
	const unsigned char face[13] = { 3, 0, 0, 0, 0, 1, 0, 0, 0, 2, 0, 0, 0 };
	memcpy(bin + n, xyz, sizeof(xyz)); /* little-endian hosts only, as the suite runs */
	n += sizeof(xyz);
	memcpy(bin + n, face, sizeof(face));
	memcpy(bin + n + sizeof(face), face, sizeof(face));
	n += 2 * sizeof(face);
	char needle[128];
	snprintf(needle, sizeof(needle), ": byte offset %zu: 13 bytes of data after the last "
	         "element 'face'", header + sizeof(xyz) + sizeof(face));
	expect_scene_error(write_file("toomany-le.ply", bin, n), -EINVAL, needle);
}

/* Zero-area triangles are kept (a builder must cope) and counted. */
static void test_degenerate_ply(void)
{
	expect_degenerate(write_text("degen.ply",
		"ply\nformat ascii 1.0\nelement vertex 4\n" PLY_XYZ
		"element face 3\nproperty list uchar int vertex_indices\nend_header\n"
		"0 0 0\n1 0 0\n2 0 0\n0 1 0\n3 0 1 2\n3 0 0 3\n3 0 1 3\n"));
}

static void test_paths(void)
{
	const char *dir = tmp_path("folder.obj");
	CHECK_INT(mkdir(dir, 0755), 0);
	expect_scene_error(dir, -EISDIR, ": not a regular file");
	expect_scene_error(tmp_path("missing.ply"), -ENOENT, ": cannot open: No such file");

	struct config cfg;
	bvhlab_error err = { "" };
	CHECK(config_load(&cfg, dir, &err) < 0);
	CHECK_CONTAINS(err.message, "folder.obj: cannot read: Is a directory");
	config_finish(&cfg);

	const char *locked = write_text("locked.obj", "v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 3\n");
	chmod(locked, 0);
	if (geteuid() == 0) {
		/* Permission bits do not stop root: nothing to check. */
		printf("unreadable file check skipped: running as root\n");
	} else {
		expect_scene_error(locked, -EACCES, ": cannot open: Permission denied");
		CHECK(config_load(&cfg, locked, &err) == -EACCES);
		CHECK_CONTAINS(err.message, "locked.obj: cannot open: Permission denied");
		config_finish(&cfg);
	}
}

/* An unknown plugin name lists the plugins there are. */
static void test_unknown_plugin(void)
{
	bvhlab_plugin *p = NULL;
	bvhlab_error err = { "" };
	CHECK_INT(bvhlab_plugin_open("fake_godo", &p, &err), -ENOENT);
	CHECK_CONTAINS(err.message, "plugin 'fake_godo' not found on the search path");
	CHECK_CONTAINS(err.message, "(available: ");
	CHECK_CONTAINS(err.message, "fake_abi2, fake_badopt, fake_good, fake_nobuild,");
	CHECK(p == NULL);
}

/* What a successful load promises the rest of the core. */
static void check_scene(const char *path, int ret, const bvhlab_scene *s,
                        const bvhlab_error *err)
{
	bool ok = true;
	if (ret != 0) {
		CHECK(s == NULL && err->message[0] != '\0');
		return;
	}
	for (size_t i = 0; s && i < 3 * (size_t)s->vertex_count; i++)
		ok = ok && isfinite(s->vertices[i]);
	for (size_t i = 0; s && i < 3 * (size_t)s->triangle_count; i++)
		ok = ok && s->indices[i] < s->vertex_count;
	ok = ok && s && s->triangle_count > 0;
	if (!ok)
		fprintf(stderr, "%s: loaded, but inconsistent\n", path);
	CHECK(ok);
}

static void load_any(const char *kind, const char *path)
{
	bvhlab_error err = { "" };
	if (strcmp(kind, "config") == 0) {
		struct config cfg;
		int ret = config_load(&cfg, path, &err);
		CHECK(ret == 0 || err.message[0] != '\0');
		config_finish(&cfg);
		return;
	}
	bvhlab_scene *s = NULL;
	int ret = strcmp(kind, "obj") == 0 ? bvhlab_scene_load_obj(path, &s, &err)
	                                   : bvhlab_scene_load_ply(path, &s, &err);
	check_scene(path, ret, s, &err);
	bvhlab_scene_destroy(s);
}

/* Every file of dir/KIND goes through the loader of its kind; returns how many. */
static int load_folder(const char *dir, const char *kind)
{
	char path[1024];
	int count = 0;
	snprintf(path, sizeof(path), "%s/%s", dir, kind);
	DIR *d = opendir(path);
	struct dirent *e;
	while (d && (e = readdir(d))) {
		if (e->d_name[0] == '.')
			continue;
		snprintf(path, sizeof(path), "%s/%s/%s", dir, kind, e->d_name);
		load_any(kind, path);
		count++;
	}
	if (d)
		closedir(d);
	return count;
}

/* Inputs the fuzzers once crashed on, and the seeds they start from. */
static void test_fuzz_inputs(void)
{
	static const char *const kinds[] = { "obj", "ply", "config" };
	for (int k = 0; k < 3; k++) {
		int regress = load_folder(BVHLAB_TEST_SRCDIR "/fuzz-regress", kinds[k]);
		int seeds = load_folder(BVHLAB_TEST_BUILDDIR "/fuzz-seeds", kinds[k]);
		printf("%s: %d regression inputs, %d seeds\n", kinds[k], regress, seeds);
		CHECK(seeds > 0);
	}
}

int main(void)
{
	tmp_begin("bad-input");
	test_empty();
	test_element_counts();
	test_degenerate_ply();
	test_paths();
	test_unknown_plugin();
	test_fuzz_inputs();
	char cmd[128];
	snprintf(cmd, sizeof(cmd), "rm -rf '%s'", tmpdir);
	CHECK_INT(system(cmd), 0);
	return test_finish();
}
