/*
 * What the device builders (cl_lbvh, cl_ploc, cl_hploc) share on the host
 * side, over the device layer of include/bvhlab/opencl.h (a static library
 * linked into each plugin):
 *
 *   - cl_dev: the device and the built program, from the process's device
 *     layer (the host's, ABI 1.6: shared with every device builder and the
 *     device tracer, kept for the process's life, so compiling is never a
 *     build's work), and this builder's kernels, made again when the
 *     layer hands out another program (the `device` option changed);
 *   - cl_buf, cl_launch, cl_events: the device layer's buffers that grow
 *     (all sized before any kernel runs), launches and events (summed
 *     into the phase "device"), core/device/device_run.h, on d's device;
 *   - what a builder keeps between builds (CL_KEPT) and the chunks of its
 *     one-work-item-each kernels (cl_chunks);
 *   - the Morton codes and their radix sort (cl_sort.c, kernels in
 *     morton_sort.cl after box.cl), mirroring plugins/common/morton;
 *   - the start of a build and the report of its phases (cl_build.c), and
 *     the build() and descriptor of a builder on it (CL_PLUGIN).
 */
#ifndef BVHLAB_CL_DEV_H
#define BVHLAB_CL_DEV_H

#include <stdbool.h>
#include <stddef.h>
#include <stdint.h>

#include <bvhlab/opencl.h>
#include <bvhlab/builder.h>

#include "device_run.h"
#include "plugin_options.h"

/* The device layer builds every program with correctly rounded division
 * and square root where the device has them, as the CPU's. (The kernels
 * also turn contraction into fma off, by pragma; none divides today: the
 * quantiser's scale comes from the host.) */
#define CL_DEV_MAX_KERNELS 24

/* The option every device builder has, in its table (plugin_options.h),
 * into the member `device` (const char *) of its struct `owner`. */
#define CL_DEVICE_OPTION(owner)                                                              \
	PLUGIN_OPTION(owner, device, STRING, .name = "device",                               \
	              .help = "OpenCL device: auto (the first GPU, else the first device), " \
	                      "gpu, cpu, or P:D (platform and device indices, as clinfo -l " \
	                      "lists them)",                                                 \
	              .def_string = "auto")

/* The device option's form (auto, gpu, cpu or P:D), for the plugin's
 * fill_options check (plugin_options.h): a config error when the config
 * is read, not a failed build. Whether such a device exists is the
 * build's to find out (the runs record it). */
#define CL_DEVICE_CHECK(owner)                                                            \
	static int cl_device_check(const bvhlab_host *host, bvhlab_build_ctx *ctx, void *o) \
	{                                                                                 \
		cl_device_type want;                                                      \
		long pi, di;                                                              \
		char why[160];                                                            \
		if (bvhlab_cl_parse_spec(((owner *)o)->device, &want, &pi, &di, why,     \
		                         sizeof(why)) == 0)                               \
			return 0;                                                         \
		host->set_error(ctx, "option 'device' is '%s': allowed are auto, gpu, cpu " \
		                "or P:D (platform and device indices, e.g. 0:0)",         \
		                ((owner *)o)->device);                                    \
		return -EINVAL;                                                           \
	}

typedef struct cl_dev {
	bvhlab_cl cl;    /* the layer's device, copied: not ours to release */
	cl_program prog; /* the layer's */
	cl_kernel k[CL_DEV_MAX_KERNELS];
	unsigned kernel_count;
} cl_dev;

/* The device of `spec` with the program of `src` from the host's device
 * layer and its kernels (`names`, in order, into d->k) made; keeps the
 * kernels while the layer hands out the same program. 0, or a negative
 * errno after host->set_error. */
int cl_dev_open(cl_dev *d, const bvhlab_host *host, bvhlab_build_ctx *ctx, const char *spec,
                const char *src, size_t len, const char *const *names, unsigned count);
/* Releases the kernels; safe on a zeroed or closed cl_dev. */
void cl_dev_close(cl_dev *d);

/* The head of what a device builder keeps between builds (one build at a
 * time, ABI rule) in its static struct S, which CL_BUILD_FN reads: the
 * device, the sort, and its own `count` buffers. */
#define CL_KEPT(count) \
	cl_dev dev;    \
	cl_sort sort;  \
	cl_buf b[count]

/* Releases what CL_KEPT(count) holds (the plugin's destructor). */
#define CL_KEPT_FREE(kept, count) cl_kept_free(&(kept).dev, &(kept).sort, (kept).b, count)

/* The device layer's buffers, launches and events (core/device/device_run.h)
 * on a cl_dev's device. */
static inline int cl_bufs_fit(const cl_dev *d, const size_t *want, unsigned count, char *err,
                              size_t err_size)
{
	return cl_bufs_fit_on(&d->cl, want, count, err, err_size);
}

static inline int cl_bufs_size(cl_dev *d, cl_buf *bufs, const size_t *want, unsigned count,
                               char *err, size_t err_size)
{
	return cl_bufs_size_on(&d->cl, bufs, want, count, err, err_size);
}

static inline int cl_launch(cl_dev *d, cl_kernel k, size_t items, const cl_arg *args,
                            unsigned nargs, cl_events *ev, char *err, size_t err_size)
{
	return cl_launch_on(&d->cl, k, items, args, nargs, ev, err, err_size);
}

/* Work on n items in chunks of one work-item each, in order: the count of
 * chunks, at most `most` (but for n = 0), with the size of each, at least
 * `least` items, into *chunk. */
static inline uint32_t cl_chunks(uint32_t n, uint32_t most, uint32_t least, uint32_t *chunk)
{
	uint32_t c = (n + most - 1) / most;

	*chunk = c < least ? least : c;
	return (n + *chunk - 1) / *chunk;
}

/* ---- Morton codes and sort (cl_sort.c) -------------------------------- */

/* Kernel names the program must have, first in the names given to
 * cl_dev_open (cl_sort uses d->k[0..CL_SORT_KERNELS - 1]). */
#define CL_SORT_KERNEL_NAMES "morton_codes", "morton_varying", "radix_hist", \
	"radix_scan", "radix_scatter", "radix_ranges", "radix_buckets"
#define CL_SORT_KERNELS 7

/* The sort's buffers. */
enum { SB_CENTROIDS, SB_KEYS0, SB_KEYS1, SB_VALS0, SB_VALS1, SB_HIST, SB_PART, SB_RANGE,
       SB_COUNT };

typedef struct cl_sort {
	cl_buf b[SB_COUNT];
	unsigned sorted; /* after cl_sort_run: keys/vals[sorted] hold the order */
	/* When set, the centroids' buffer for the next cl_sort_run instead of
	 * b[SB_CENTROIDS] and its upload: on a CPU device, a buffer over the
	 * input's own array (CL_MEM_USE_HOST_PTR), no copy. The caller owns it. */
	cl_mem centroids;
	/* The sort's shape: CL_SORT_AUTO (buckets on a CPU device, passes
	 * elsewhere), CL_SORT_PASSES (every varying digit a pass over all
	 * keys, the GPU's shape) or CL_SORT_BUCKETS (passes on the two top
	 * digits, then a work-item per bucket of those 16 bits sorts it in
	 * cache, morton_sort.cl; from 65,536 primitives on, passes below).
	 * The order is the same. */
	int shape;
} cl_sort;

enum { CL_SORT_AUTO, CL_SORT_PASSES, CL_SORT_BUCKETS };

/* Bytes of each of the sort's buffers for n primitives (into want[]). */
void cl_sort_sizes(uint32_t n, size_t want[SB_COUNT]);
/*
 * Uploads the centroids unless s->centroids holds them (blocking; its
 * wall-clock time into *ms_upload),
 * computes the codes of `bits` (30 or 63) as plugins/common/morton does,
 * and sorts the (code, id) pairs, the kernels' events into ev. Reads back
 * once, the bits in which the codes vary (which digits need a pass).
 */
int cl_sort_run(cl_dev *d, cl_sort *s, const bvhlab_build_input *in, unsigned bits,
                cl_events *ev, double *ms_upload, char *err, size_t err_size);

/* The sort's and the builder's buffers freed, d closed (CL_KEPT_FREE). */
void cl_kept_free(cl_dev *d, cl_sort *s, cl_buf *b, unsigned count);

/* ---- a build's start and phases (cl_build.c) ------------------------- */

/* A device builder's program and the most primitives it builds over. */
typedef struct cl_builder {
	const char *src; /* morton_sort.cl, then the builder's kernels */
	size_t len;
	const char *const *kernels; /* CL_SORT_KERNEL_NAMES first */
	unsigned kernel_count;
	uint32_t max_prims;
} cl_builder;

/* The cl_builder of the program array `prog` (its length prog##_LEN, as
 * scripts/embed-cl.py writes it) and the array of kernel names `names`. */
#define CL_BUILDER(prog, names, most)                       \
	{ .src = prog, .len = prog##_LEN, .kernels = names, \
	  .kernel_count = sizeof(names) / sizeof(names[0]), .max_prims = most }

/*
 * The start of a device builder's build, after its options: the count of
 * primitives checked, the output's room, the device `spec` opened with
 * cb's program (kept in d between builds). 0 to go on (two primitives or
 * more), 1 when that was the build (one primitive: its leaf written), or a
 * negative errno after host->set_error.
 */
int cl_build_begin(const cl_builder *cb, cl_dev *d, const char *spec, const bvhlab_host *host,
                   bvhlab_build_ctx *ctx, const bvhlab_build_input *in,
                   bvhlab_build_output *out);

/* The phases every device builder reports, in this order. */
enum { CL_PHASE_UPLOAD, CL_PHASE_DEVICE, CL_PHASE_DOWNLOAD, CL_PHASE_CONVERT, CL_PHASES };

/* Reports ms[] as the phases upload, device, download and convert, where
 * the host takes phases. */
void cl_report_phases(const bvhlab_host *host, bvhlab_build_ctx *ctx,
                      const double ms[CL_PHASES]);

/* A device builder's run, after the start: the tree into out, its phases
 * into the builder's ms[]; 0, or a negative errno with the message in err. */
typedef int (*cl_run_fn)(void *b, bvhlab_build_output *out, char *err, size_t err_size);

/* What cl_build_run needs of a builder besides its program: its options'
 * table (MORTON_OPTIONS and CL_DEVICE_OPTION in it), where its struct
 * keeps the `device` spec and the phases `ms[CL_PHASES]`, and its run. */
typedef struct cl_run_spec {
	size_t device_at, ms_at;
	cl_run_fn run;
} cl_run_spec;

/* The cl_run_spec of struct `type` (members device and ms) and run `fn`. */
#define CL_RUN_SPEC(type, fn) \
	{ .device_at = offsetof(type, device), .ms_at = offsetof(type, ms), .run = fn }

/*
 * A device builder's build() on its struct b (its options and the rest
 * set by the caller, PLUGIN_OPTIONS_GET first: it copies the whole
 * struct): cl_build_begin
 * on b's device spec, rs->run(b, ...) with its message into
 * host->set_error, a debug line, and b's phases reported. 0 or the errno.
 */
int cl_build_run(const cl_builder *cb, const cl_run_spec *rs, cl_dev *d, void *b,
                 const bvhlab_host *host, bvhlab_build_ctx *ctx, const bvhlab_build_input *in,
                 bvhlab_build_output *out);

/*
 * The build() of a device builder on cl_build_run: its struct `type` (with
 * members in, n, dev, sort, b) gets its options first (PLUGIN_OPTIONS_GET
 * copies the whole struct), then the input and the plugin's state; the
 * file keeps that state in `S` (dev, sort, b), its cl_builder `program` and
 * its cl_run_spec `job`.
 */
#define CL_BUILD_FN(type)                                                         \
	PLUGIN_BUILD_FN(type, b.dev = &S.dev, b.sort = &S.sort, b.b = S.b;           \
	                return cl_build_run(&program, &job, &S.dev, &b, host, ctx, input, \
	                                    output);)

/*
 * A device builder on cl_build_run, at the end of its file: its cl_run_spec
 * `job` (struct `type`, run `fn`), its build() (CL_BUILD_FN) and its
 * descriptor, deterministic and a device builder's; the arguments after
 * fn name and describe it (.name, .summary).
 */
#define CL_PLUGIN(type, fn, ...)                                                        \
	static const cl_run_spec job = CL_RUN_SPEC(type, fn);                           \
	CL_BUILD_FN(type)                                                               \
	PLUGIN_WITH_OPTIONS(options,                                                    \
	                    .flags = BVHLAB_BUILDER_DETERMINISTIC | BVHLAB_BUILDER_DEVICE, \
	                    .build = build, __VA_ARGS__)

/* A device builder's option of how it runs, a string of `choices` after
 * auto, its default, which picks by the device's kind (`help` says how);
 * the tree is the same for every value. */
#define CL_SHAPE_OPTION(owner, member, option, text, more)                              \
	PLUGIN_OPTION(owner, member, STRING, .name = option,                            \
	              .help = text "; the tree is the same", .def_string = "auto",      \
	              .choices = "auto|" more)

#endif /* BVHLAB_CL_DEV_H */
