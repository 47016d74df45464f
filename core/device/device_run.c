/*
 * The device layer's runs (device_run.h): buffers sized against the
 * device's memory, launches and their events' times. Compiled into the
 * core (the device tracer) and into the device builders' common library.
 */
#define _POSIX_C_SOURCE 200809L /* clock_gettime */
#include <errno.h>
#include <stdlib.h>
#include <string.h>
#include <time.h>

#include "device_run.h"

double cl_now_ms(void)
{
	struct timespec ts;

	clock_gettime(CLOCK_MONOTONIC, &ts);
	return ts.tv_sec * 1e3 + ts.tv_nsec / 1e6;
}

void cl_bufs_free(cl_buf *bufs, unsigned count)
{
	for (unsigned k = 0; k < count; k++) {
		bvhlab_cl_release_mem(&bufs[k].mem);
		bufs[k].bytes = 0;
	}
}

/* Round sizes up, so that small changes in n do not reallocate. */
static size_t rounded(size_t bytes)
{
	return bytes < 4096 ? 4096 : (bytes + 65535) & ~(size_t)65535;
}

/* The device's memory and largest allocation, both capped at
 * $BVHLAB_CL_MEM_CAP_MB MiB when that is set: how the tests make a small
 * scene not fit. */
static void mem_limits(const bvhlab_cl *cl, double *global, double *alloc, const char **cap_note)
{
	const char *cap = getenv("BVHLAB_CL_MEM_CAP_MB");
	char *end = NULL;
	double mb = cap ? strtod(cap, &end) : 0.0;

	*global = (double)cl->global_mem;
	*alloc = (double)cl->max_alloc;
	*cap_note = "";
	if (!cap || end == cap || *end || !(mb > 0.0))
		return;
	mb *= 1024.0 * 1024.0;
	*cap_note = mb < *global || mb < *alloc ? " (capped by $BVHLAB_CL_MEM_CAP_MB)" : "";
	*global = mb < *global ? mb : *global;
	*alloc = mb < *alloc ? mb : *alloc;
}

#define MIB(x) ((double)(x) / (1024.0 * 1024.0))

int cl_bufs_fit_on(const bvhlab_cl *cl, const size_t *want, unsigned count, char *err,
                   size_t err_size)
{
	double total = 0, global, alloc;
	const char *note;

	mem_limits(cl, &global, &alloc, &note);
	for (unsigned k = 0; k < count; k++) {
		total += (double)rounded(want[k]);
		if ((double)rounded(want[k]) > alloc)
			return bvhlab_cl_fail(-ENOMEM, err, err_size,
				"cl: a buffer of %.2f MiB is more than %s allows in one allocation, "
				"%.2f MiB%s", MIB(rounded(want[k])), cl->name, MIB(alloc), note);
	}
	if (total > global)
		return bvhlab_cl_fail(-ENOMEM, err, err_size,
			"cl: %.2f MiB of device memory needed, %s has %.2f MiB%s",
			MIB(total), cl->name, MIB(global), note);
	return 0;
}

int cl_bufs_size_on(const bvhlab_cl *cl, cl_buf *bufs, const size_t *want, unsigned count,
                    char *err, size_t err_size)
{
	cl_int rc = CL_SUCCESS;
	int fit = cl_bufs_fit_on(cl, want, count, err, err_size);

	if (fit < 0)
		return fit;
	for (unsigned k = 0; k < count; k++) {
		if (bufs[k].bytes >= want[k] && bufs[k].mem)
			continue;
		bvhlab_cl_release_mem(&bufs[k].mem);
		bufs[k].bytes = 0;
		bufs[k].mem = clCreateBuffer(cl->context, CL_MEM_READ_WRITE, rounded(want[k]),
		                             NULL, &rc);
		if (rc != CL_SUCCESS) {
			bufs[k].mem = NULL;
			return bvhlab_cl_check(rc, "clCreateBuffer", err, err_size);
		}
		bufs[k].bytes = rounded(want[k]);
	}
	return 0;
}

static double sum_events(cl_events *ev)
{
	double ms = 0;

	for (unsigned k = 0; k < ev->count; k++) {
		double t = bvhlab_cl_event_ms(ev->ev[k]);
		ms += t > 0 ? t : 0;
		bvhlab_cl_release_event(&ev->ev[k]);
	}
	ev->count = 0;
	return ms;
}

cl_event *cl_events_next(cl_events *ev)
{
	if (ev->count == CL_EVENTS_MAX) {
		clWaitForEvents(ev->count, ev->ev);
		ev->ms += sum_events(ev);
	}
	return &ev->ev[ev->count++];
}

double cl_events_ms(cl_events *ev)
{
	double ms = ev->ms + sum_events(ev);

	ev->ms = 0;
	return ms;
}

int cl_launch_on(const bvhlab_cl *cl, cl_kernel k, size_t items, const cl_arg *args,
                 unsigned nargs, cl_events *ev, char *err, size_t err_size)
{
	size_t local = cl->max_work_group < 64 ? cl->max_work_group : 64;
	size_t global = (items + local - 1) / local * local;
	cl_int rc = CL_SUCCESS;

	for (unsigned a = 0; a < nargs && rc == CL_SUCCESS; a++)
		rc = clSetKernelArg(k, a, args[a].size, args[a].value);
	if (rc != CL_SUCCESS)
		return bvhlab_cl_check(rc, "clSetKernelArg", err, err_size);
	if (items == 0)
		return 0;
	rc = clEnqueueNDRangeKernel(cl->queue, k, 1, NULL, &global, &local, 0, NULL,
	                            cl_events_next(ev));
	return bvhlab_cl_check(rc, "clEnqueueNDRangeKernel", err, err_size);
}
