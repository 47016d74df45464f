/* libFuzzer target: the PLY loader (scene_ply.c, scene_ply_header.c). */
#include <stdint.h>

#include "fuzz_input.h"

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size);

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size)
{
	const char *path = fuzz_write_file(data, size, ".ply");
	bvhlab_scene *s = NULL;
	bvhlab_error err = { "" };
	int ret = bvhlab_scene_load_ply(path, &s, &err);

	fuzz_check_scene(ret, s, &err);
	bvhlab_scene_destroy(s);
	return 0;
}
