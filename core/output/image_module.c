/*
 * Image files through the optional module bvhlab-images.so (OpenImageIO,
 * images_oiio.cpp), opened on first use from beside the plugin folder: the
 * build tree's root or the install's <libdir>/bvhlab. bvhlab itself links
 * no image library, so a relocatable bundle (scripts/bundle.sh) carries
 * about 20 libraries instead of OIIO's 260; without the module a run
 * skips its images and goes on.
 */
#include <dlfcn.h>
#include <errno.h>
#include <limits.h>
#include <pthread.h>
#include <stdio.h>

#include "host/plugin_search.h"
#include "output/image.h"
#include "util/util.h"

#define MODULE_FILE "bvhlab-images.so"

typedef int (*write_fn)(const char *, int, int, const uint8_t *, bvhlab_error *);
typedef int (*read_fn)(const char *, int *, int *, uint8_t **, bvhlab_error *);

static struct {
	pthread_once_t once;
	write_fn write;
	read_fn read;
	char why[PATH_MAX + 256]; /* why there is none */
} module = {.once = PTHREAD_ONCE_INIT};

/* Kept open for the process's life, like OIIO's own state was. */
static void open_module(void)
{
	char path[PATH_MAX];
	if (plugin_home_file(MODULE_FILE, path, sizeof(path)) < 0) {
		snprintf(module.why, sizeof(module.why), "%s: no folder to look in", MODULE_FILE);
		return;
	}
	void *h = dlopen(path, RTLD_NOW | RTLD_LOCAL);
	if (!h) {
		snprintf(module.why, sizeof(module.why), "%s", dlerror());
		return;
	}
	module.write = (write_fn)dlsym(h, "bvhlab_image_write_rgb8");
	module.read = (read_fn)dlsym(h, "bvhlab_image_read_rgb8");
	if (!module.write || !module.read) {
		snprintf(module.why, sizeof(module.why), "%s: not bvhlab's images module", path);
		module.write = NULL;
		module.read = NULL;
	}
}

bool image_module_ready(const char **why)
{
	pthread_once(&module.once, open_module);
	if (why)
		*why = module.why;
	return module.write != NULL;
}

int image_write_rgb8(const char *path, int width, int height, const uint8_t *rgb,
                     bvhlab_error *err)
{
	const char *why;
	if (!image_module_ready(&why)) {
		error_set(err, "cannot write %s: no images module (%s)", path, why);
		return -ENOTSUP;
	}
	return module.write(path, width, height, rgb, err);
}

int image_read_rgb8(const char *path, int *width, int *height, uint8_t **rgb,
                    bvhlab_error *err)
{
	const char *why;
	*rgb = NULL;
	if (!image_module_ready(&why)) {
		error_set(err, "cannot read %s: no images module (%s)", path, why);
		return -ENOTSUP;
	}
	return module.read(path, width, height, rgb, err);
}
