/*
 * A ray batch timed in slices (trace_measure.c). bvhlab_trace_measure is
 * one slice of a series; the harness's interleaved rounds
 * (harness/harness_rounds.c) give each of a scene's trees one slice per
 * round, so that a stretch in which a shared machine runs slow lands on a
 * few slices of every tree instead of on the whole measurement of one.
 * The figures (best per tile, median, min and max over passes) are over
 * all passes of all slices.
 */
#ifndef BVHLAB_CORE_TRACE_SERIES_H
#define BVHLAB_CORE_TRACE_SERIES_H

#include <stdbool.h>
#include <stddef.h>

#include <bvhlab/trace.h>

struct trace_series;

/*
 * Copies what the traversal reads (opts->traversal, opts->threads and
 * opts->any_hit are kept for every slice). hits and nodes (may be NULL)
 * get each ray's hit and node count from the series' first pass, with the
 * meaning bvhlab_trace_measure gives them; they must live until then.
 * counters false spares the wide traversal its counting pass: its
 * timing's counters and nodes then stay zero. The device traversals
 * (device_stack, device_stackless, device_wide8) upload the tree and rays to opts->device and
 * count on the device. 0, or a negative errno with err saying why:
 * -EINVAL (bad traversal or tree links), -ENOMEM, and for the device
 * -ENOTSUP (OpenCL not built), -ENODEV (no device), -EIO.
 */
int trace_series_create(const bvhlab_tree *tree, const bvhlab_scene *scene,
                        const bvhlab_ray *rays, size_t count, const bvhlab_trace_options *opts,
                        bvhlab_hit *hits, uint32_t *nodes, bool counters,
                        struct trace_series **out, bvhlab_error *err);

/* A series of other rays (any-hit ones when any) through base's tree with
 * base's traversal, threads and tracing copies (base must outlive it). Its timing's
 * counters are those of its first pass for the stack and stackless
 * traversals and zero for the wide one (no counting pass). 0 or a
 * negative errno (trace_series_error says why). */
int trace_series_create_like(const struct trace_series *base, const bvhlab_ray *rays,
                             size_t count, bool any, struct trace_series **out);

/* Timed passes until this slice meets opts' min_ms, min_rays and
 * min_repeats (counted within the slice); max_repeats bounds the series'
 * passes in all. 0, or a negative errno when no pass could be timed
 * (trace_series_error says why; the passes so far still count). */
int trace_series_slice(struct trace_series *s, const bvhlab_trace_options *opts);

/* Whether the series' passes in all meet opts' minimums (as one slice
 * would have to), or its max_repeats: then more slices add only time. */
bool trace_series_done(const struct trace_series *s, const bvhlab_trace_options *opts);

/* The figures over every pass so far (zeros before the first slice). */
void trace_series_timing(const struct trace_series *s, bvhlab_trace_timing *t);

void trace_series_destroy(struct trace_series *s);

/* Why the series' last slice failed ("" if none). */
const char *trace_series_error(const struct trace_series *s);

/* The device a cl_ series traces on (CL_DEVICE_NAME); NULL for the CPU's. */
const char *trace_series_device(const struct trace_series *s);

/*
 * bvhlab_trace_measure with the reason for a failure in err, and the
 * device's name in device (when a cl_ traversal; may be NULL).
 */
int trace_measure(const bvhlab_tree *tree, const bvhlab_scene *scene, const bvhlab_ray *rays,
                  size_t count, const bvhlab_trace_options *opts, bvhlab_hit *hits,
                  uint32_t *nodes, bvhlab_trace_timing *timing, char *device, size_t device_size,
                  bvhlab_error *err);

/*
 * The same for a two-level scene (trace_instances.h) with opts->traversal
 * at both levels: a CPU one (trace_two_level_prepare), or a device one
 * (trace_cl_two_level_create: the trees and rays uploaded to
 * opts->device, the device's name into device when not NULL). hits (may
 * be NULL) as trace_two_level_hit gives them, the counters the nodes and
 * triangles of both levels. 0, or a negative errno with err saying why
 * (-EINVAL: not a traversal of two-level scenes; for the device, as
 * trace_series_create's).
 */
struct trace_two_level;
int trace_measure_two_level(const struct trace_two_level *tl, const bvhlab_ray *rays,
                            size_t count, const bvhlab_trace_options *opts, bvhlab_hit *hits,
                            bvhlab_trace_timing *timing, char *device, size_t device_size,
                            bvhlab_error *err);

#endif
