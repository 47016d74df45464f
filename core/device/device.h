/*
 * The process's device layer: one place that opens a device and builds a
 * program on it, kept for the life of the process, for the device tracer
 * (core/trace/trace_cl.c) and the device builders alike (through the
 * host table's device_program, ABI 1.6, and include/bvhlab/opencl.h's
 * bvhlab_cl_host_program). OpenCL is its backend (device_cl.c); a build
 * without OpenCL refuses every request with the reason (device_none.c).
 *
 * Why one: PoCL takes seconds to compile a program, a device's context
 * and queue are not free either, and a device builder and the tracer in
 * one process (a sweep's child builds, then traces) should share both.
 * The same spec, source and options give the same program; the entries
 * made before a fork are not used in the child (their driver threads are
 * not there): the child opens its own.
 */
#ifndef BVHLAB_CORE_DEVICE_H
#define BVHLAB_CORE_DEVICE_H

#include <stddef.h>

/*
 * The device `spec` names (NULL: "auto") and the program of `len` bytes of
 * source (0: up to its NUL) built on it with `options` (may be NULL), plus
 * correctly rounded division and square root where the device has them
 * (the CPU's IEEE results: both the tracer's hits and the builders' boxes
 * depend on it). *device is the backend's device (OpenCL: const bvhlab_cl
 * *), *program its program (cl_program); both stay the layer's: never
 * release them. 0, or a negative errno with the message in err (-ENOTSUP
 * no backend built, -ENODEV, -EINVAL a bad spec or a compile error with
 * the compiler's log, -ENOMEM, -EIO).
 */
int device_program(const char *spec, const char *src, size_t len, const char *options,
                   const void **device, void **program, char *err, size_t err_size);

#endif
