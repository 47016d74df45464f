/* libFuzzer target: the OBJ loader (scene_obj.c). */
#include <stdint.h>

#include "fuzz_input.h"
#include "scene/scene_private.h"

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size);

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size)
{
	const char *path = fuzz_write_file(data, size, ".obj");
	bvhlab_scene *s = NULL;
	bvhlab_error err = { "" };
	struct scene_load_stats stats;
	int ret = scene_load_obj_stats(path, &s, &stats, &err);

	fuzz_check_scene(ret, s, &err);
	bvhlab_scene_destroy(s);
	return 0;
}
