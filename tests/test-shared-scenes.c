/*
 * The real meshes in BVHLAB_SHARED_SCENES: triangle counts as published,
 * and load times on stdout (informative only; nothing asserts on time).
 */
#include <stdio.h>
#include <string.h>
#include <sys/stat.h>

#include <bvhlab/scene.h>

#include "testutil.h"
#include "util/util.h"

static bvhlab_scene *load(const char *file, uint32_t triangles)
{
	char path[1024];
	bvhlab_scene *s = NULL;
	bvhlab_error err = { "" };
	double t0 = util_now_ms(), ms;
	int ret;

	snprintf(path, sizeof(path), "%s/%s", BVHLAB_SHARED_SCENES, file);
	ret = bvhlab_scene_load(path, &s, &err);
	ms = util_now_ms() - t0;
	CHECK_INT(ret, 0);
	if (ret) {
		fprintf(stderr, "  %s\n", err.message);
		return NULL;
	}
	printf("%-20s %9u triangles %8u vertices %4u degenerate  %7.1f ms\n", file,
	       s->triangle_count, s->vertex_count, s->degenerate_count, ms);
	CHECK_INT(s->triangle_count, triangles);
	CHECK(s->bounds.lo[0] < s->bounds.hi[0]);
	return s;
}

int main(void)
{
	static const struct {
		const char *file;
		uint32_t triangles;
	} meshes[] = {
		{ "stanford-bunny.obj", 69451 }, { "ogre.obj", 124008 }, { "nefertiti.obj", 99938 },
		{ "horse.ply", 96966 },          { "igea.ply", 268686 },
	};
	struct stat st;
	bvhlab_scene *igea = NULL;
	bvhlab_error err = { "" };
	double t0;

	if (stat(BVHLAB_SHARED_SCENES, &st) != 0 || !S_ISDIR(st.st_mode)) {
		printf("no shared scenes at %s: skipped\n", BVHLAB_SHARED_SCENES);
		return TEST_SKIP;
	}
	for (size_t i = 0; i < sizeof(meshes) / sizeof(meshes[0]); i++) {
		bvhlab_scene *s = load(meshes[i].file, meshes[i].triangles);

		if (s && strcmp(meshes[i].file, "igea.ply") == 0)
			igea = s;
		else
			bvhlab_scene_destroy(s);
	}
	if (igea) {
		t0 = util_now_ms();
		CHECK_INT(bvhlab_scene_subdivide(igea, 1, &err), 0);
		printf("%-20s %9u triangles %8u vertices %4u degenerate  %7.1f ms\n",
		       "igea.ply subdivide 1", igea->triangle_count, igea->vertex_count,
		       igea->degenerate_count, util_now_ms() - t0);
		CHECK_INT(igea->triangle_count, 1074744);
	}
	bvhlab_scene_destroy(igea);
	return test_finish();
}
