/*
 * The OpenCL platforms and devices of this machine, for `bvhlab info
 * --machine` (machine.h): what the cl_ builders' and traversals' device
 * specs can name, "P:D" being the indices listed here; and the device a
 * device builder's run builds on, opened before its builds.
 */
#include <errno.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "machine/machine.h"

#ifdef BVHLAB_HAVE_OPENCL

#include <bvhlab/opencl.h>

static const char *kind_name(cl_device_type t)
{
	return t & CL_DEVICE_TYPE_GPU ? "gpu"
	       : t & CL_DEVICE_TYPE_CPU ? "cpu"
	       : t & CL_DEVICE_TYPE_ACCELERATOR ? "accelerator" : "other";
}

static void describe(cl_platform_id p, cl_device_id d, struct machine_cl_device *out)
{
	cl_device_type type = 0;
	cl_uint units = 0;
	cl_ulong mem = 0;
	clGetPlatformInfo(p, CL_PLATFORM_NAME, sizeof(out->platform) - 1, out->platform, NULL);
	clGetDeviceInfo(d, CL_DEVICE_NAME, sizeof(out->name) - 1, out->name, NULL);
	clGetDeviceInfo(d, CL_DEVICE_VERSION, sizeof(out->version) - 1, out->version, NULL);
	clGetDeviceInfo(d, CL_DEVICE_TYPE, sizeof(type), &type, NULL);
	clGetDeviceInfo(d, CL_DEVICE_MAX_COMPUTE_UNITS, sizeof(units), &units, NULL);
	clGetDeviceInfo(d, CL_DEVICE_GLOBAL_MEM_SIZE, sizeof(mem), &mem, NULL);
	snprintf(out->kind, sizeof(out->kind), "%s", kind_name(type));
	out->compute_units = units;
	out->global_mem = mem;
}

/* Appends platform p's devices to *list. 0 or a negative errno. */
static int add_platform(cl_platform_id p, unsigned pi, struct machine_cl_device **list,
                        size_t *n, char *why, size_t why_size)
{
	cl_device_id *devs = NULL;
	cl_uint nd = 0;
	int r = bvhlab_cl_devices(p, &devs, &nd, why, why_size);
	struct machine_cl_device *grown = r == 0 && nd ? realloc(*list, (*n + nd) * sizeof(**list))
	                                               : *list;
	if (r == 0 && nd && !grown)
		r = -ENOMEM;
	for (cl_uint d = 0; r == 0 && d < nd; d++) {
		struct machine_cl_device *m = &grown[(*n)++];
		memset(m, 0, sizeof(*m));
		m->platform_index = pi;
		m->device_index = d;
		describe(p, devs[d], m);
	}
	if (grown)
		*list = grown;
	free(devs);
	return r;
}

int machine_cl_devices(struct machine_cl_device **out, size_t *count, char *why, size_t why_size)
{
	cl_platform_id *plats = NULL;
	cl_uint np = 0;
	*out = NULL;
	*count = 0;
	int r = bvhlab_cl_platforms(&plats, &np, why, why_size);
	for (cl_uint p = 0; r == 0 && p < np; p++)
		r = add_platform(plats[p], p, out, count, why, why_size);
	free(plats);
	if (r < 0) {
		free(*out);
		*out = NULL;
		*count = 0;
	}
	return r;
}

/* The devices opened by spec, each with its context, for the process's life. */
static struct opened {
	char spec[64];
	bvhlab_cl cl;
	struct machine_cl_device dev;
} opened[4];
static unsigned opened_count;

int machine_cl_open(const char *spec, struct machine_cl_device *out, char *why, size_t why_size)
{
	spec = spec ? spec : "auto";
	for (unsigned k = 0; k < opened_count; k++)
		if (strcmp(opened[k].spec, spec) == 0)
			return *out = opened[k].dev, 0;
	if (opened_count == sizeof(opened) / sizeof(opened[0]) ||
	    strlen(spec) >= sizeof(opened[0].spec))
		return snprintf(why, why_size, "cl: too many device specs in one process (or '%.40s' "
		                "too long)", spec), -ENOMEM;
	struct opened *o = &opened[opened_count];
	int r = bvhlab_cl_init(&o->cl, spec, why, why_size);
	if (r < 0)
		return r;
	memset(&o->dev, 0, sizeof(o->dev));
	o->dev.platform_index = o->cl.platform_index;
	o->dev.device_index = o->cl.device_index;
	describe(o->cl.platform, o->cl.device, &o->dev);
	snprintf(o->spec, sizeof(o->spec), "%s", spec);
	opened_count++;
	*out = o->dev;
	return 0;
}

#else

int machine_cl_open(const char *spec, struct machine_cl_device *out, char *why, size_t why_size)
{
	(void)spec;
	memset(out, 0, sizeof(*out));
	snprintf(why, why_size, "not built (this bvhlab was built without OpenCL)");
	return -ENOTSUP;
}

int machine_cl_devices(struct machine_cl_device **out, size_t *count, char *why, size_t why_size)
{
	*out = NULL;
	*count = 0;
	snprintf(why, why_size, "not built (this bvhlab was built without OpenCL: install "
	                        "ocl-icd-opencl-dev and opencl-c-headers, then meson setup again)");
	return -ENOTSUP;
}

#endif
