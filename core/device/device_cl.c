/*
 * The device layer's OpenCL backend (device.h): the devices by spec and
 * the programs built on them, made once per process under one lock.
 */
#include <errno.h>
#include <pthread.h>
#include <stdint.h>
#include <stdlib.h>
#include <string.h>
#include <unistd.h>

#include <bvhlab/opencl.h>

#include "device/device.h"

/* Correctly rounded division and square root: OpenCL's default float
 * division may be 2.5 ulp off the CPU's IEEE result. A device that cannot
 * round them correctly is not asked to (the build would fail). */
#define EXACT_DIVIDE "-cl-fp32-correctly-rounded-divide-sqrt"
#define MAX_DEVICES 4
#define MAX_PROGRAMS 32

struct device {
	char spec[64];
	bvhlab_cl cl;
	char exact[sizeof(EXACT_DIVIDE)]; /* EXACT_DIVIDE, or "" without it */
};

struct program {
	const struct device *dev;
	uint64_t hash; /* of the source and the options */
	size_t len;
	cl_program prog;
};

static struct device devices[MAX_DEVICES];
static struct program programs[MAX_PROGRAMS];
static unsigned device_count, program_count;
static pid_t owner; /* the process the entries were made in */
static pthread_mutex_t lock = PTHREAD_MUTEX_INITIALIZER;

/* After a fork the parent's entries are handles of the parent's driver
 * state: forgotten, never released (that would reach into it). */
static void forget_if_forked(void)
{
	if (owner == getpid())
		return;
	memset(devices, 0, sizeof(devices));
	memset(programs, 0, sizeof(programs));
	device_count = program_count = 0;
	owner = getpid();
}

/*
 * At exit() (registered with the first device, so before the handlers
 * registered earlier, LeakSanitizer's among them) the layer releases what it made, so the driver can
 * stop its threads (PoCL's pthread device keeps workers while a context
 * lives; LeakSanitizer's scan at exit crashed on them, test-rays under
 * ASan). A forked child's entries are its parent's: left alone.
 */
static void release_all(void)
{
	pthread_mutex_lock(&lock);
	if (owner == getpid()) {
		for (unsigned i = 0; i < program_count; i++)
			bvhlab_cl_release_program(&programs[i].prog);
		for (unsigned i = 0; i < device_count; i++)
			bvhlab_cl_finish(&devices[i].cl);
		device_count = program_count = 0;
	}
	pthread_mutex_unlock(&lock);
}

static uint64_t fnv1a(uint64_t h, const char *s, size_t n)
{
	for (size_t i = 0; i < n; i++)
		h = (h ^ (unsigned char)s[i]) * 0x100000001b3ull;
	return h;
}

static int get_device(const char *spec, struct device **out, char *err, size_t err_size)
{
	for (unsigned i = 0; i < device_count; i++)
		if (strcmp(devices[i].spec, spec) == 0) {
			*out = &devices[i];
			return 0;
		}
	if (device_count == MAX_DEVICES || strlen(spec) >= sizeof(devices[0].spec))
		return bvhlab_cl_fail(-EINVAL, err, err_size, "cl: too many device specs in one "
		                      "process (or '%.40s' too long)", spec);
	struct device *d = &devices[device_count];
	static bool registered;
	if (!registered)
		registered = atexit(release_all) == 0;
	int r = bvhlab_cl_init(&d->cl, spec, err, err_size);
	if (r < 0)
		return r;
	cl_device_fp_config fp = 0;
	clGetDeviceInfo(d->cl.device, CL_DEVICE_SINGLE_FP_CONFIG, sizeof(fp), &fp, NULL);
	snprintf(d->exact, sizeof(d->exact), "%s",
	         fp & CL_FP_CORRECTLY_ROUNDED_DIVIDE_SQRT ? EXACT_DIVIDE : "");
	snprintf(d->spec, sizeof(d->spec), "%s", spec);
	device_count++;
	*out = d;
	return 0;
}

static int get_program(struct device *d, const char *src, size_t len,
                       const char *options, cl_program *out, char *err, size_t err_size)
{
	char opts[512];
	int n = snprintf(opts, sizeof(opts), "%s %s", d->exact, options ? options : "");
	if (n < 0 || (size_t)n >= sizeof(opts))
		return bvhlab_cl_fail(-EINVAL, err, err_size, "cl: build options too long");
	uint64_t h = fnv1a(fnv1a(0xcbf29ce484222325ull, src, len), opts, (size_t)n);
	for (unsigned i = 0; i < program_count; i++)
		if (programs[i].dev == d && programs[i].hash == h && programs[i].len == len) {
			*out = programs[i].prog;
			return 0;
		}
	if (program_count == MAX_PROGRAMS)
		return bvhlab_cl_fail(-ENOMEM, err, err_size, "cl: more than %d programs in one "
		                      "process", MAX_PROGRAMS);
	int r = bvhlab_cl_program(&d->cl, src, len, opts, out, err, err_size);
	if (r == 0)
		programs[program_count++] = (struct program){d, h, len, *out};
	return r;
}

int device_program(const char *spec, const char *src, size_t len, const char *options,
                   const void **device, void **program, char *err, size_t err_size)
{
	struct device *d = NULL;
	cl_program prog = NULL;
	len = len ? len : strlen(src);
	pthread_mutex_lock(&lock);
	forget_if_forked();
	int r = get_device(spec ? spec : "auto", &d, err, err_size);
	if (r == 0)
		r = get_program(d, src, len, options, &prog, err, err_size);
	pthread_mutex_unlock(&lock);
	*device = r == 0 ? &d->cl : NULL;
	*program = r == 0 ? (void *)prog : NULL;
	return r;
}
