/* bvhlab/opencl.h - the OpenCL device layer shared by device builders, the
 * core's device tracer and out-of-tree device plugins.
 *
 * A device builder gets its device and program from the process's one
 * device layer, through the host (ABI 1.6), so every builder and the
 * tracer in a process share one device and compile each program once:
 *
 *   const bvhlab_cl *cl;
 *   cl_program prog;
 *   if (bvhlab_cl_host_program(host, ctx, spec, src, len, NULL, &cl, &prog) < 0)
 *       return ...;   (the host has set the build's error)
 *   ... bvhlab_cl_kernel(prog, "name", &k, err, sizeof err) ...
 *
 * The rest (device choice, programs, kernels, events, release helpers)
 * is what the layer itself is made of, for tools and tests that open a
 * device of their own:
 *
 * Header-only (static inline) so a plugin uses it without linking libbvhlab:
 * it needs only the OpenCL headers and the ICD loader (-lOpenCL; Debian
 * ocl-icd-opencl-dev and opencl-c-headers, plus a driver such as
 * pocl-opencl-icd, which runs OpenCL on the CPU). Installed only when the
 * project was built with OpenCL.
 *
 *   bvhlab_cl cl = {0};
 *   char err[BVHLAB_CL_ERROR_SIZE];
 *   if (bvhlab_cl_init(&cl, "auto", err, sizeof err) < 0) goto fail;
 *   ... bvhlab_cl_program(&cl, src, len, "-cl-std=CL1.2", &prog, err, sizeof err) ...
 *   fail: bvhlab_cl_finish(&cl);   (safe on a zeroed or half-made struct)
 *
 * Every function returns 0 or a negative errno and, on error, writes a
 * message (never longer than err_size - 1) into err: -ENODEV no platform or
 * device, -EINVAL a bad device spec or a kernel that does not compile,
 * -ENOMEM out of host or device memory, -EIO any other OpenCL error.
 *
 * The queue is in order with profiling on, so bvhlab_cl_event_ms gives a
 * kernel's own time. OpenCL 1.2 API: include this header before CL/cl.h (or
 * define CL_TARGET_OPENCL_VERSION yourself) so clCreateCommandQueue, which
 * 1.2 devices need, is not flagged deprecated. */
#ifndef BVHLAB_OPENCL_H
#define BVHLAB_OPENCL_H

#ifndef CL_TARGET_OPENCL_VERSION
#define CL_TARGET_OPENCL_VERSION 120
#endif
#ifndef CL_USE_DEPRECATED_OPENCL_1_2_APIS
#define CL_USE_DEPRECATED_OPENCL_1_2_APIS
#endif
#include <CL/cl.h>

#include <errno.h>
#include <stdarg.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/resource.h>
#include <sys/stat.h>

#include "builder.h"

#ifdef __cplusplus
extern "C" {
#endif

/* A size for error buffers that leaves room for a useful part of a
 * compiler log. */
#define BVHLAB_CL_ERROR_SIZE 4096

/* What to install when there is no OpenCL at all; part of the messages. */
#define BVHLAB_CL_INSTALL_HINT \
	"install an OpenCL driver (on Debian: apt-get install pocl-opencl-icd, " \
	"which runs OpenCL on the CPU; or the GPU vendor's OpenCL ICD)"

/* One chosen device with its context and queue. Zero it before init;
 * bvhlab_cl_finish releases what init made, on a zeroed struct too. */
typedef struct bvhlab_cl {
	cl_platform_id platform;
	cl_device_id device;
	cl_context context;
	cl_command_queue queue;   /* in order, CL_QUEUE_PROFILING_ENABLE */
	cl_device_type type;      /* CL_DEVICE_TYPE_GPU, _CPU, ... */
	unsigned platform_index;  /* the P and D of a "P:D" spec for it */
	unsigned device_index;
	char name[128];           /* the device's CL_DEVICE_NAME */
	size_t max_work_group;    /* CL_DEVICE_MAX_WORK_GROUP_SIZE */
	cl_ulong global_mem;      /* CL_DEVICE_GLOBAL_MEM_SIZE, bytes */
	cl_ulong max_alloc;       /* CL_DEVICE_MAX_MEM_ALLOC_SIZE, bytes */
} bvhlab_cl;

#if defined(__GNUC__)
#define BVHLAB_CL_PRINTF(f, a) __attribute__((format(printf, f, a)))
#else
#define BVHLAB_CL_PRINTF(f, a)
#endif

/* Writes a message into err (when there is one) and returns rc. */
static inline BVHLAB_CL_PRINTF(4, 5)
int bvhlab_cl_fail(int rc, char *err, size_t err_size, const char *fmt, ...)
{
	va_list ap;
	if (err && err_size) {
		va_start(ap, fmt);
		vsnprintf(err, err_size, fmt, ap);
		va_end(ap);
	}
	return rc;
}

/* The name of an OpenCL error code, for messages. */
static inline const char *bvhlab_cl_error_name(cl_int code)
{
	switch (code) {
	case CL_SUCCESS: return "CL_SUCCESS";
	case CL_DEVICE_NOT_FOUND: return "CL_DEVICE_NOT_FOUND";
	case CL_DEVICE_NOT_AVAILABLE: return "CL_DEVICE_NOT_AVAILABLE";
	case CL_COMPILER_NOT_AVAILABLE: return "CL_COMPILER_NOT_AVAILABLE";
	case CL_MEM_OBJECT_ALLOCATION_FAILURE: return "CL_MEM_OBJECT_ALLOCATION_FAILURE";
	case CL_OUT_OF_RESOURCES: return "CL_OUT_OF_RESOURCES";
	case CL_OUT_OF_HOST_MEMORY: return "CL_OUT_OF_HOST_MEMORY";
	case CL_BUILD_PROGRAM_FAILURE: return "CL_BUILD_PROGRAM_FAILURE";
	case CL_INVALID_VALUE: return "CL_INVALID_VALUE";
	case CL_INVALID_DEVICE: return "CL_INVALID_DEVICE";
	case CL_INVALID_BINARY: return "CL_INVALID_BINARY";
	case CL_INVALID_BUILD_OPTIONS: return "CL_INVALID_BUILD_OPTIONS";
	case CL_INVALID_PROGRAM_EXECUTABLE: return "CL_INVALID_PROGRAM_EXECUTABLE";
	case CL_INVALID_KERNEL_NAME: return "CL_INVALID_KERNEL_NAME";
	case CL_INVALID_KERNEL_ARGS: return "CL_INVALID_KERNEL_ARGS";
	case CL_INVALID_ARG_INDEX: return "CL_INVALID_ARG_INDEX";
	case CL_INVALID_ARG_VALUE: return "CL_INVALID_ARG_VALUE";
	case CL_INVALID_ARG_SIZE: return "CL_INVALID_ARG_SIZE";
	case CL_INVALID_WORK_GROUP_SIZE: return "CL_INVALID_WORK_GROUP_SIZE";
	case CL_INVALID_WORK_ITEM_SIZE: return "CL_INVALID_WORK_ITEM_SIZE";
	case CL_INVALID_GLOBAL_WORK_SIZE: return "CL_INVALID_GLOBAL_WORK_SIZE";
	case CL_INVALID_BUFFER_SIZE: return "CL_INVALID_BUFFER_SIZE";
	case CL_INVALID_MEM_OBJECT: return "CL_INVALID_MEM_OBJECT";
	case CL_INVALID_EVENT: return "CL_INVALID_EVENT";
	case CL_INVALID_OPERATION: return "CL_INVALID_OPERATION";
	case CL_PROFILING_INFO_NOT_AVAILABLE: return "CL_PROFILING_INFO_NOT_AVAILABLE";
	case -1001: return "CL_PLATFORM_NOT_FOUND_KHR";
	default: return "an OpenCL error";
	}
}

/* The negative errno for an OpenCL error code. */
static inline int bvhlab_cl_errno(cl_int code)
{
	switch (code) {
	case CL_SUCCESS: return 0;
	case CL_OUT_OF_HOST_MEMORY:
	case CL_OUT_OF_RESOURCES:
	case CL_MEM_OBJECT_ALLOCATION_FAILURE:
	case CL_INVALID_BUFFER_SIZE: return -ENOMEM;
	case CL_DEVICE_NOT_FOUND:
	case CL_DEVICE_NOT_AVAILABLE:
	case -1001: return -ENODEV;
	case CL_BUILD_PROGRAM_FAILURE:
	case CL_INVALID_BUILD_OPTIONS: return -EINVAL;
	default: return -EIO;
	}
}

/* For calls whose failure needs no more words than what failed:
 * returns 0, or the errno with "cl: WHAT: CL_ERROR (code)" in err. */
static inline int bvhlab_cl_check(cl_int code, const char *what, char *err, size_t err_size)
{
	if (code == CL_SUCCESS)
		return 0;
	return bvhlab_cl_fail(bvhlab_cl_errno(code), err, err_size, "cl: %s: %s (%d)",
		what, bvhlab_cl_error_name(code), (int)code);
}

/* Why an installed driver may show no platform or device: an unusable
 * POCL_CACHE_DIR (PoCL then offers no device) or a limited address space
 * (RLIMIT_AS, the harness's memory_limit_mb: the driver cannot load).
 * The cause into buf, "" when neither; returns buf. */
static inline const char *bvhlab_cl_suspect(char *buf, size_t size)
{
	const char *cache = getenv("POCL_CACHE_DIR");
	struct stat st;
	struct rlimit rl;
	buf[0] = '\0';
	if (cache && *cache && (stat(cache, &st) != 0 || !S_ISDIR(st.st_mode)))
		snprintf(buf, size, "POCL_CACHE_DIR=%s is not a folder PoCL can use (fix or unset "
			"it)", cache);
	else if (getrlimit(RLIMIT_AS, &rl) == 0 && rl.rlim_cur != RLIM_INFINITY)
		snprintf(buf, size, "this process's address space is limited to %llu MB "
			"(memory_limit_mb), too little for an OpenCL driver to load: raise "
			"memory_limit_mb or drop it", (unsigned long long)(rl.rlim_cur >> 20));
	return buf;
}

/* The platforms: 0 and *out (malloc'd, count in *n; free it), or an error
 * saying there are none and why, or what to install. */
static inline int bvhlab_cl_platforms(cl_platform_id **out, cl_uint *n, char *err, size_t err_size)
{
	cl_uint count = 0;
	cl_int rc = clGetPlatformIDs(0, NULL, &count);
	*out = NULL;
	*n = 0;
	/* The ICD loader says -1001 (CL_PLATFORM_NOT_FOUND_KHR) for no driver. */
	if (rc != CL_SUCCESS && rc != -1001)
		return bvhlab_cl_check(rc, "clGetPlatformIDs", err, err_size);
	char why[512];
	if ((rc != CL_SUCCESS || count == 0) && bvhlab_cl_suspect(why, sizeof why)[0])
		return bvhlab_cl_fail(-ENODEV, err, err_size,
			"cl: no OpenCL platform could be opened: %s", why);
	if (rc != CL_SUCCESS || count == 0)
		return bvhlab_cl_fail(-ENODEV, err, err_size,
			"cl: no OpenCL platform found: " BVHLAB_CL_INSTALL_HINT);
	*out = (cl_platform_id *)calloc(count, sizeof **out);
	if (!*out)
		return bvhlab_cl_fail(-ENOMEM, err, err_size, "cl: out of memory");
	rc = clGetPlatformIDs(count, *out, NULL);
	if (rc != CL_SUCCESS) {
		free(*out);
		*out = NULL;
		return bvhlab_cl_check(rc, "clGetPlatformIDs", err, err_size);
	}
	*n = count;
	return 0;
}

/* The devices of one platform (malloc'd; free it); none is *n = 0, not an
 * error, since another platform may have some. */
static inline int bvhlab_cl_devices(cl_platform_id p, cl_device_id **out, cl_uint *n,
	char *err, size_t err_size)
{
	cl_uint count = 0;
	cl_int rc = clGetDeviceIDs(p, CL_DEVICE_TYPE_ALL, 0, NULL, &count);
	*out = NULL;
	*n = 0;
	if (rc == CL_DEVICE_NOT_FOUND || (rc == CL_SUCCESS && count == 0))
		return 0;
	if (rc != CL_SUCCESS)
		return bvhlab_cl_check(rc, "clGetDeviceIDs", err, err_size);
	*out = (cl_device_id *)calloc(count, sizeof **out);
	if (!*out)
		return bvhlab_cl_fail(-ENOMEM, err, err_size, "cl: out of memory");
	rc = clGetDeviceIDs(p, CL_DEVICE_TYPE_ALL, count, *out, NULL);
	if (rc != CL_SUCCESS) {
		free(*out);
		*out = NULL;
		return bvhlab_cl_check(rc, "clGetDeviceIDs", err, err_size);
	}
	*n = count;
	return 0;
}

/* What a spec asks for: a kind (want_type, 0 for auto's GPU-else-any) or
 * fixed indices. 0, or -EINVAL naming the spec. */
static inline int bvhlab_cl_parse_spec(const char *spec, cl_device_type *want_type,
	long *pi, long *di, char *err, size_t err_size)
{
	char *end = NULL;
	*want_type = 0;
	*pi = *di = -1;
	if (!spec || !strcmp(spec, "auto"))
		return 0;
	if (!strcmp(spec, "gpu") || !strcmp(spec, "cpu")) {
		*want_type = spec[0] == 'g' ? CL_DEVICE_TYPE_GPU : CL_DEVICE_TYPE_CPU;
		return 0;
	}
	if (spec[0] >= '0' && spec[0] <= '9') {
		*pi = strtol(spec, &end, 10);
		if (*end == ':' && end[1] >= '0' && end[1] <= '9') {
			*di = strtol(end + 1, &end, 10);
			if (*end == '\0' && *pi < 65536 && *di < 65536)
				return 0;
		}
	}
	return bvhlab_cl_fail(-EINVAL, err, err_size,
		"cl: device '%s' is not auto, gpu, cpu or P:D (platform and device "
		"indices, e.g. 0:0)", spec);
}

/* Whether device d of the kind wanted (0: any). */
static inline int bvhlab_cl_is_kind(cl_device_id d, cl_device_type want)
{
	cl_device_type t = 0;
	if (!want)
		return 1;
	if (clGetDeviceInfo(d, CL_DEVICE_TYPE, sizeof t, &t, NULL) != CL_SUCCESS)
		return 0;
	return (t & want) != 0;
}

/* Looks for the first device of the kind over all platforms; sets
 * cl->platform/device/indices and returns 1 when found, 0 when not, or a
 * negative errno. */
static inline int bvhlab_cl_find(bvhlab_cl *cl, const cl_platform_id *plats, cl_uint np,
	cl_device_type want, long pi, long di, char *err, size_t err_size)
{
	for (cl_uint p = 0; p < np; p++) {
		cl_device_id *devs = NULL;
		cl_uint nd = 0;
		int rc = bvhlab_cl_devices(plats[p], &devs, &nd, err, err_size);
		if (rc < 0)
			return rc;
		for (cl_uint d = 0; d < nd; d++) {
			int match = pi >= 0 ? (long)p == pi && (long)d == di
			                    : bvhlab_cl_is_kind(devs[d], want);
			if (match) {
				cl->platform = plats[p];
				cl->device = devs[d];
				cl->platform_index = p;
				cl->device_index = d;
				free(devs);
				return 1;
			}
		}
		free(devs);
	}
	return 0;
}

/* The device the spec names: 0, or an error naming the spec and what
 * exists. */
static inline int bvhlab_cl_choose(bvhlab_cl *cl, const char *spec, char *err, size_t err_size)
{
	cl_platform_id *plats = NULL;
	cl_uint np = 0;
	cl_device_type want;
	long pi, di;
	int rc = bvhlab_cl_parse_spec(spec, &want, &pi, &di, err, err_size);
	if (rc < 0)
		return rc;
	rc = bvhlab_cl_platforms(&plats, &np, err, err_size);
	if (rc < 0)
		return rc;
	rc = bvhlab_cl_find(cl, plats, np, want ? want : (pi < 0 ? CL_DEVICE_TYPE_GPU : 0),
		pi, di, err, err_size);
	if (rc == 0 && want == 0 && pi < 0) /* auto: no GPU, take any device */
		rc = bvhlab_cl_find(cl, plats, np, 0, -1, -1, err, err_size);
	free(plats);
	if (rc < 0)
		return rc;
	char why[512];
	if (rc == 0 && bvhlab_cl_suspect(why, sizeof why)[0])
		return bvhlab_cl_fail(-ENODEV, err, err_size,
			"cl: device '%s': no such OpenCL device among %u platform(s), most "
			"likely because %s", spec ? spec : "auto", (unsigned)np, why);
	if (rc == 0)
		return bvhlab_cl_fail(-ENODEV, err, err_size,
			"cl: device '%s': no such OpenCL device among %u platform(s) "
			"(clinfo -l lists them; for any device at all, %s)",
			spec ? spec : "auto", (unsigned)np, BVHLAB_CL_INSTALL_HINT);
	return 0;
}

/* Reads the chosen device's name, kind and limits into cl. */
static inline int bvhlab_cl_describe(bvhlab_cl *cl, char *err, size_t err_size)
{
	cl_int rc = clGetDeviceInfo(cl->device, CL_DEVICE_NAME, sizeof cl->name - 1, cl->name, NULL);
	if (rc == CL_SUCCESS)
		rc = clGetDeviceInfo(cl->device, CL_DEVICE_TYPE, sizeof cl->type, &cl->type, NULL);
	if (rc == CL_SUCCESS)
		rc = clGetDeviceInfo(cl->device, CL_DEVICE_MAX_WORK_GROUP_SIZE,
			sizeof cl->max_work_group, &cl->max_work_group, NULL);
	if (rc == CL_SUCCESS)
		rc = clGetDeviceInfo(cl->device, CL_DEVICE_GLOBAL_MEM_SIZE,
			sizeof cl->global_mem, &cl->global_mem, NULL);
	if (rc == CL_SUCCESS)
		rc = clGetDeviceInfo(cl->device, CL_DEVICE_MAX_MEM_ALLOC_SIZE,
			sizeof cl->max_alloc, &cl->max_alloc, NULL);
	cl->name[sizeof cl->name - 1] = '\0';
	return bvhlab_cl_check(rc, "clGetDeviceInfo", err, err_size);
}

/* Releases what bvhlab_cl_init made; safe on a zeroed struct and twice. */
static inline void bvhlab_cl_finish(bvhlab_cl *cl)
{
	if (!cl)
		return;
	if (cl->queue)
		clReleaseCommandQueue(cl->queue);
	if (cl->context)
		clReleaseContext(cl->context);
	memset(cl, 0, sizeof *cl);
}

/* Chooses the device the spec names (NULL is "auto") and makes its
 * context and in-order profiling queue. On error cl is left zeroed. */
static inline int bvhlab_cl_init(bvhlab_cl *cl, const char *spec, char *err, size_t err_size)
{
	cl_int rc = CL_SUCCESS;
	int e;
	memset(cl, 0, sizeof *cl);
	e = bvhlab_cl_choose(cl, spec, err, err_size);
	if (e == 0)
		e = bvhlab_cl_describe(cl, err, err_size);
	if (e < 0)
		goto fail;
	cl->context = clCreateContext(NULL, 1, &cl->device, NULL, NULL, &rc);
	if ((e = bvhlab_cl_check(rc, "clCreateContext", err, err_size)) < 0)
		goto fail;
	cl->queue = clCreateCommandQueue(cl->context, cl->device, CL_QUEUE_PROFILING_ENABLE, &rc);
	if ((e = bvhlab_cl_check(rc, "clCreateCommandQueue", err, err_size)) < 0)
		goto fail;
	return 0;
fail:
	bvhlab_cl_finish(cl);
	return e;
}

/* The program's build log on cl's device (malloc'd; free it), or NULL. */
static inline char *bvhlab_cl_read_log(const bvhlab_cl *cl, cl_program prog)
{
	size_t len = 0;
	char *log = NULL;
	if (clGetProgramBuildInfo(prog, cl->device, CL_PROGRAM_BUILD_LOG, 0, NULL, &len) !=
	    CL_SUCCESS || len == 0 || !(log = (char *)malloc(len + 1)))
		return NULL;
	if (clGetProgramBuildInfo(prog, cl->device, CL_PROGRAM_BUILD_LOG, len, log, NULL) !=
	    CL_SUCCESS) {
		free(log);
		return NULL;
	}
	log[len] = '\0';
	return log;
}

/* Puts "cl: kernel build failed on DEVICE: LOG" into err, the log cut to
 * what fits and the cut said so. */
static inline int bvhlab_cl_build_log(bvhlab_cl *cl, cl_program prog, cl_int code,
	char *err, size_t err_size)
{
	size_t head;
	char why[512];
	char *log = bvhlab_cl_read_log(cl, prog);
	const char *cut = "\n[compiler log truncated]";
	if (!err || !err_size)
		goto out;
	head = (size_t)snprintf(err, err_size, "cl: kernel build failed (%s) on %s: ",
		bvhlab_cl_error_name(code), cl->name);
	if (head >= err_size)
		goto out;
	if (!log) {
		snprintf(err + head, err_size - head, "no compiler log");
	} else if (strlen(log) < err_size - head) {
		memcpy(err + head, log, strlen(log) + 1);
	} else if (err_size - head > strlen(cut) + 1) {
		size_t keep = err_size - head - strlen(cut) - 1;
		memcpy(err + head, log, keep);
		memcpy(err + head + keep, cut, strlen(cut) + 1);
	}
	/* The log's last newline would end a progress line mid-message. */
	for (head = strlen(err); head > 0 && (err[head - 1] == '\n' || err[head - 1] == ' ');)
		err[--head] = '\0';
	if (bvhlab_cl_suspect(why, sizeof why)[0] && head + 16 < err_size)
		snprintf(err + head, err_size - head, " (most likely because %s)", why);
out:
	free(log);
	return bvhlab_cl_errno(code) == -EIO ? -EINVAL : bvhlab_cl_errno(code);
}

/* Builds a program from len bytes of OpenCL C source (len 0: up to its
 * NUL) with the build options (may be NULL). A compile error is -EINVAL
 * with the compiler's log in err. */
static inline int bvhlab_cl_program(bvhlab_cl *cl, const char *src, size_t len,
	const char *options, cl_program *out, char *err, size_t err_size)
{
	cl_int rc = CL_SUCCESS;
	size_t n = len ? len : strlen(src);
	cl_program prog = clCreateProgramWithSource(cl->context, 1, &src, &n, &rc);
	int e;
	*out = NULL;
	if ((e = bvhlab_cl_check(rc, "clCreateProgramWithSource", err, err_size)) < 0)
		return e;
	rc = clBuildProgram(prog, 1, &cl->device, options ? options : "", NULL, NULL);
	if (rc != CL_SUCCESS) {
		e = rc == CL_BUILD_PROGRAM_FAILURE || rc == CL_INVALID_BUILD_OPTIONS
			? bvhlab_cl_build_log(cl, prog, rc, err, err_size)
			: bvhlab_cl_check(rc, "clBuildProgram", err, err_size);
		clReleaseProgram(prog);
		return e;
	}
	*out = prog;
	return 0;
}

/* A kernel of a built program: 0, or an error naming it. */
static inline int bvhlab_cl_kernel(cl_program prog, const char *name, cl_kernel *out,
	char *err, size_t err_size)
{
	cl_int rc = CL_SUCCESS;
	*out = clCreateKernel(prog, name, &rc);
	if (rc != CL_SUCCESS) {
		*out = NULL;
		return bvhlab_cl_fail(bvhlab_cl_errno(rc), err, err_size,
			"cl: kernel '%s': %s (%d)", name, bvhlab_cl_error_name(rc), (int)rc);
	}
	return 0;
}

/* A finished event's profiled time (start to end) in ms; -1 when the
 * queue has no profiling or the event has not run. */
static inline double bvhlab_cl_event_ms(cl_event ev)
{
	cl_ulong t0 = 0, t1 = 0;
	if (!ev || clGetEventProfilingInfo(ev, CL_PROFILING_COMMAND_START, sizeof t0, &t0, NULL)
	    != CL_SUCCESS || clGetEventProfilingInfo(ev, CL_PROFILING_COMMAND_END, sizeof t1,
	    &t1, NULL) != CL_SUCCESS)
		return -1.0;
	return t1 >= t0 ? (double)(t1 - t0) * 1e-6 : 0.0;
}

/* Release helpers that take NULL, so unwinding need not check. */
static inline void bvhlab_cl_release_mem(cl_mem *m)
{
	if (*m)
		clReleaseMemObject(*m);
	*m = NULL;
}

static inline void bvhlab_cl_release_kernel(cl_kernel *k)
{
	if (*k)
		clReleaseKernel(*k);
	*k = NULL;
}

static inline void bvhlab_cl_release_program(cl_program *p)
{
	if (*p)
		clReleaseProgram(*p);
	*p = NULL;
}

static inline void bvhlab_cl_release_event(cl_event *e)
{
	if (*e)
		clReleaseEvent(*e);
	*e = NULL;
}

/* The process's device (spec: auto, gpu, cpu, P:D; NULL is auto) and the
 * program of `len` bytes of src (0: up to its NUL) built on it with the
 * build options (may be NULL), from the host's device layer (ABI 1.6
 * host->device_program): kept by the host for the process's life, the
 * same spec, source and options giving the same program. Both are the
 * host's: never release them (your kernels made from the program are
 * yours). 0, or a negative errno after host->set_error (-ENOTSUP from a
 * host older than 1.6, which has no device layer). */
static inline int bvhlab_cl_host_program(const bvhlab_host *host, bvhlab_build_ctx *ctx,
	const char *spec, const char *src, size_t len, const char *options,
	const bvhlab_cl **cl, cl_program *prog)
{
	const void *device = NULL;
	void *program = NULL;
	int rc;
	*cl = NULL;
	*prog = NULL;
	if (!BVHLAB_HOST_HAS(host, device_program)) {
		host->set_error(ctx, "cl: this host (ABI %u.%u) has no device layer; ABI 1.6 "
			"hosts have one", (unsigned)BVHLAB_ABI_VERSION_MAJOR(host->abi_version),
			(unsigned)BVHLAB_ABI_VERSION_MINOR(host->abi_version));
		return -ENOTSUP;
	}
	rc = host->device_program(ctx, spec, src, len, options, &device, &program);
	if (rc == 0) {
		*cl = (const bvhlab_cl *)device;
		*prog = (cl_program)program;
	}
	return rc;
}

#ifdef __cplusplus
}
#endif

#endif
