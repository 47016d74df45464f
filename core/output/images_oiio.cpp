// The images module, bvhlab-images.so: OpenImageIO behind a C interface,
// loaded by core/output/image_module.c only when images are drawn, so that
// bvhlab itself links neither OIIO nor its ~250 libraries (a relocatable
// bundle leaves the module out) and OIIO's exceptions never cross into C.
#include <cerrno>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <memory>
#include <string>

#include <OpenImageIO/imageio.h>

#include <bvhlab/types.h>

namespace {

void set_error(bvhlab_error *err, const char *what, const char *path, const std::string &why)
{
	if (err)
		std::snprintf(err->message, sizeof(err->message), "cannot %s %s: %s", what, path,
		              why.empty() ? "unknown error" : why.c_str());
}

// OIIO's own thread pool would outlive our calls; forked children of the
// harness must not inherit running threads, so keep it to the caller's.
void single_threaded()
{
	static bool done = false;
	if (!done) {
		OIIO::attribute("threads", 1);
		done = true;
	}
}

} // namespace

// What image_module.c looks up (its typedefs give the same signatures).
#define EXPORT extern "C" __attribute__((visibility("default")))

EXPORT int bvhlab_image_write_rgb8(const char *path, int width, int height,
                                   const uint8_t *rgb, bvhlab_error *err)
{
	try {
		single_threaded();
		auto out = OIIO::ImageOutput::create(path);
		if (!out) {
			set_error(err, "write", path, OIIO::geterror());
			return -EIO;
		}
		OIIO::ImageSpec spec(width, height, 3, OIIO::TypeDesc::UINT8);
		if (!out->open(path, spec) || !out->write_image(OIIO::TypeDesc::UINT8, rgb) ||
		    !out->close()) {
			set_error(err, "write", path, out->geterror());
			return -EIO;
		}
		return 0;
	} catch (const std::exception &e) {
		set_error(err, "write", path, e.what());
		return -EIO;
	}
}

EXPORT int bvhlab_image_read_rgb8(const char *path, int *width, int *height, uint8_t **rgb,
                                  bvhlab_error *err)
{
	*rgb = nullptr;
	try {
		single_threaded();
		auto in = OIIO::ImageInput::open(path);
		if (!in) {
			set_error(err, "read", path, OIIO::geterror());
			return -EIO;
		}
		const OIIO::ImageSpec &spec = in->spec();
		size_t n = (size_t)spec.width * (size_t)spec.height * 3;
		uint8_t *pixels = static_cast<uint8_t *>(std::malloc(n ? n : 1));
		if (!pixels) {
			set_error(err, "read", path, "out of memory");
			return -ENOMEM;
		}
		if (!in->read_image(0, 0, 0, 3, OIIO::TypeDesc::UINT8, pixels)) {
			set_error(err, "read", path, in->geterror());
			std::free(pixels);
			return -EIO;
		}
		*width = spec.width;
		*height = spec.height;
		*rgb = pixels;
		return 0;
	} catch (const std::exception &e) {
		set_error(err, "read", path, e.what());
		return -EIO;
	}
}
