/*
 * The device layer's runs, beside its devices and programs (device.h):
 * device buffers that grow and are checked against the device's memory
 * first, kernel launches, and the launches' events summed into a time.
 * One source, compiled into the core (the device tracer) and into the
 * device builders' common library (plugins/common/cl), which cannot link
 * the core. OpenCL, the layer's backend, shows here: the callers are the
 * OpenCL parts of each.
 */
#ifndef BVHLAB_DEVICE_RUN_H
#define BVHLAB_DEVICE_RUN_H

#include <stddef.h>

#include <bvhlab/opencl.h>

/* A device buffer of at least `bytes`, kept and grown between builds. */
typedef struct cl_buf {
	cl_mem mem;
	size_t bytes;
} cl_buf;

/* Whether buffers of want[k] bytes fit the device (each its largest
 * allocation, the sum its global memory): 0, or -ENOMEM with a message
 * giving both figures, the need and the device's. Every device builder
 * calls it with all its buffers (its own and the sort's) before it makes
 * any, so a scene too big fails here, never in the driver. For tests,
 * $BVHLAB_CL_MEM_CAP_MB caps both limits. The device tracer checks its
 * tree and rays the same way. */
int cl_bufs_fit_on(const bvhlab_cl *cl, const size_t *want, unsigned count, char *err,
                   size_t err_size);
/* Makes every buffer at least its wanted size (want[k] bytes), after
 * cl_bufs_fit_on. Done before any kernel runs. */
int cl_bufs_size_on(const bvhlab_cl *cl, cl_buf *bufs, const size_t *want, unsigned count,
                    char *err, size_t err_size);
void cl_bufs_free(cl_buf *bufs, unsigned count);

/* The events of one build's kernels (the phase "device"), or a pass's. */
#define CL_EVENTS_MAX 256
typedef struct cl_events {
	cl_event ev[CL_EVENTS_MAX];
	unsigned count;
	double ms; /* of events already summed and released (a full list) */
} cl_events;

/* Runs kernel k over `items` work-items (rounded up to a work-group
 * multiple; kernels check their bounds) after setting its arguments:
 * pairs of (size, pointer) in args, `nargs` of them. */
typedef struct cl_arg {
	size_t size;
	const void *value;
} cl_arg;
#define CL_ARG(x) ((cl_arg){ sizeof(x), &(x) })

int cl_launch_on(const bvhlab_cl *cl, cl_kernel k, size_t items, const cl_arg *args,
                 unsigned nargs, cl_events *ev, char *err, size_t err_size);
/* An event slot for a kernel, copy or fill; a full list is waited for
 * and summed first. */
cl_event *cl_events_next(cl_events *ev);
/* Sum of the events' profiled times in ms (after clFinish); releases them. */
double cl_events_ms(cl_events *ev);

/* Monotonic clock, ms. */
double cl_now_ms(void);

#endif
