/*
 * bvhlab — the builder plugin ABI.
 *
 * Version history (major.minor; a minor only appends fields, marked "since"):
 *   1.0  first version: bvhlab_builder, bvhlab_host, bvhlab_build_input,
 *        bvhlab_build_output, bvhlab_option_decl.
 *   1.1  bvhlab_host.pin_thread (check BVHLAB_HOST_HAS(host, pin_thread));
 *        hardware_threads counts physical cores, not logical CPUs.
 *   1.2  bvhlab_builder.refine: a plugin may improve a finished tree in
 *        place (a refinement stage); a refinement-only plugin leaves
 *        build NULL. Plugins of 1.0 and 1.1 load as before.
 *   1.3  bvhlab_host.phase: a builder may report named phases of a build
 *        (upload, device, download, convert, ...) in milliseconds; the
 *        harness records them per run as build_phases. Older plugins load
 *        as before and report none.
 *   1.4  bvhlab_builder.update: a plugin may update a finished tree in
 *        place for primitives that moved (same count and order), e.g. a
 *        refit; an update-only plugin leaves build and refine NULL.
 *        Older plugins load as before and have none.
 *   1.5  open trees and primitive kinds: bvhlab_build_output.width (a
 *        builder may emit a 2- to 8-wide tree, whose inner nodes mark their
 *        count with BVHLAB_NODE_INNER, see bvhlab_node), and
 *        bvhlab_build_input.prim_kind (triangles, or boxes for a builder
 *        with BVHLAB_BUILDER_BOXES). Older plugins load as before: they
 *        leave width at 2 and are only given triangles.
 *   1.6  options read once, when the config is read: bvhlab_builder's
 *        fill_options and options_size (the plugin fills its own options
 *        struct and checks the rules no declaration states; the host keeps
 *        the struct for the run and gives it to every call as
 *        bvhlab_build_input.options), and `choices` on INT options ("30|63").
 *        Older plugins load as before and read their options per build.
 *        bvhlab_host.device_program: the process's device layer (one
 *        device and program cache shared by every device builder and the
 *        core's device tracer; include/bvhlab/opencl.h's
 *        bvhlab_cl_host_program is the typed call). Older plugins load as
 *        before and keep their own devices.
 *        And the process's executor in bvhlab_host (run, for_each, reduce,
 *        scan, partition, sort, spawn, join; check BVHLAB_HOST_HAS(host,
 *        run)): one pool of threads for the whole process, placed on the
 *        run's CPU set and pinned as pin_thread pins. Older plugins load
 *        as before and start no threads through it.
 *   1.7  bvhlab_builder.peak_bytes_per_prim: the bytes per primitive a
 *        build adds at its peak, as the plugin declares them, from which
 *        the harness estimates a run's memory before it starts, and
 *        peak_bytes_for, the same for one run's options. Older plugins
 *        load as before and declare none (the host's default).
 *
 * A plugin is a shared object that exports exactly one symbol,
 *
 *     const bvhlab_builder *bvhlab_plugin_entry(uint32_t host_abi_major);
 *
 * (BVHLAB_PLUGIN(...) writes the descriptor and the entry point; or write
 * BVHLAB_PLUGIN_EXPORT(descriptor) after a descriptor of your own, or declare
 * the function with BVHLAB_PLUGIN_ENTRY). It returns a static descriptor owned by the
 * plugin, or NULL when it cannot serve that ABI major. C++ plugins include
 * this header as it is: its declarations are extern "C". The host refuses
 * a descriptor of another major and never reads past its struct_size; a
 * plugin built against an older minor therefore keeps working.
 *
 * Rules for plugins: do not link against libbvhlab, never print, exit or
 * abort; return 0 or a negative errno and explain failures with
 * host->set_error. Everything crossing this boundary is plain C data:
 * no JSON, no core structures.
 */
#ifndef BVHLAB_BUILDER_H
#define BVHLAB_BUILDER_H

#include <stdbool.h>
#include <stddef.h>
#include <stdint.h>

#include "types.h"

BVHLAB_BEGIN_DECLS

#define BVHLAB_ABI_MAJOR 1
#define BVHLAB_ABI_MINOR 7
#define BVHLAB_ABI_VERSION(major, minor) (((uint32_t)(major) << 16) | (uint32_t)(minor))
#define BVHLAB_ABI_VERSION_MAJOR(v) ((uint32_t)(v) >> 16)
#define BVHLAB_ABI_VERSION_MINOR(v) ((uint32_t)(v) & 0xffffu)
#define BVHLAB_ABI_CURRENT BVHLAB_ABI_VERSION(BVHLAB_ABI_MAJOR, BVHLAB_ABI_MINOR)

/* The entry point's name, for dlsym, and its signature. */
#define BVHLAB_PLUGIN_ENTRY_NAME "bvhlab_plugin_entry"
typedef const struct bvhlab_builder *(*bvhlab_plugin_entry_fn)(uint32_t host_abi_major);

#if defined(__GNUC__)
#define BVHLAB_EXPORT __attribute__((visibility("default")))
#define BVHLAB_PRINTF(fmt, args) __attribute__((format(printf, fmt, args)))
#else
#define BVHLAB_EXPORT
#define BVHLAB_PRINTF(fmt, args)
#endif

/* The entry point's linkage: C names in a C++ plugin too, so dlsym finds it. */
#ifdef __cplusplus
#define BVHLAB_ENTRY_LINKAGE extern "C"
#else
#define BVHLAB_ENTRY_LINKAGE
#endif

/* Use as: BVHLAB_PLUGIN_ENTRY { return host_abi_major == 1 ? &desc : NULL; } */
#define BVHLAB_PLUGIN_ENTRY                              \
	BVHLAB_ENTRY_LINKAGE BVHLAB_EXPORT const struct bvhlab_builder * \
	bvhlab_plugin_entry(uint32_t host_abi_major)

/*
 * The whole entry point of a plugin with one descriptor, at file scope after
 * it: BVHLAB_PLUGIN_EXPORT(descriptor). Serves this header's ABI major only
 * and returns NULL for any other, which the host reports by name.
 */
#define BVHLAB_PLUGIN_EXPORT(descriptor)                                      \
	BVHLAB_PLUGIN_ENTRY                                                   \
	{                                                                     \
		return host_abi_major == BVHLAB_ABI_MAJOR ? &(descriptor) : NULL; \
	}

/*
 * A C plugin's descriptor and entry point in one, at file scope, from the
 * descriptor's designated fields; abi_version and struct_size are filled in
 * (the ones a hand-written descriptor most easily gets wrong):
 *
 *     BVHLAB_PLUGIN(.name = "mine", .summary = "...", .flags = 0,
 *                   .option_count = 1, .options = options, .build = build)
 *
 * C++17 has no designated initializers: C++ plugins write the descriptor
 * and BVHLAB_PLUGIN_EXPORT(descriptor) (examples/plugin-template-cpp/).
 */
#define BVHLAB_PLUGIN(...)                                                       \
	static const bvhlab_builder bvhlab_plugin_descriptor = {                 \
		.abi_version = BVHLAB_ABI_CURRENT, .struct_size = sizeof(bvhlab_builder), \
		__VA_ARGS__};                                                    \
	BVHLAB_PLUGIN_EXPORT(bvhlab_plugin_descriptor)

/* ---- options -------------------------------------------------------- */

enum bvhlab_option_type {
	BVHLAB_OPTION_BOOL = 1,
	BVHLAB_OPTION_INT = 2,    /* int64_t; JSON numbers without a fraction */
	BVHLAB_OPTION_FLOAT = 3,  /* double; any JSON number */
	BVHLAB_OPTION_STRING = 4, /* one of `choices` when choices is set */
};

/*
 * One option a builder accepts. The host checks a config's options against
 * this list when it reads the config (unknown key, wrong type, out of
 * range, not a choice: a config error naming the builder, the plugin, the
 * key and what it allows) and fills in the defaults, so the getters in
 * bvhlab_host always succeed for declared names. Two rules hold beyond
 * single declarations: an INT or FLOAT pair min_NAME / max_NAME is refused
 * with min_NAME > max_NAME, and a STRING option whose default is not empty
 * may not be set to "" (bvhlab_options_check, host.h). Any other rule is
 * the descriptor's fill_options (1.6), also run when the config is read.
 */
typedef struct bvhlab_option_decl {
	const char *name;     /* key in the config's "options" object */
	uint32_t type;        /* enum bvhlab_option_type */
	const char *help;     /* one line for `bvhlab list` */
	bool def_bool;        /* default, BOOL */
	int64_t def_int;      /* default, INT */
	double def_float;     /* default, FLOAT */
	const char *def_string; /* default, STRING */
	double min, max;      /* inclusive range, INT and FLOAT; ignored if min > max */
	/* STRING: allowed values separated by '|', or NULL. Since 1.6 also INT:
	 * allowed integers, e.g. "30|63" (each within min..max, the default one
	 * of them); a host before 1.6 ignores it on an INT option and checks
	 * the range only. */
	const char *choices;
} bvhlab_option_decl;

/* ---- the host's function table ---------------------------------------- */

/* Opaque per-build context; the host passes it back through every call. */
typedef struct bvhlab_build_ctx bvhlab_build_ctx;

enum bvhlab_log_level {
	BVHLAB_LOG_ERROR = 0,
	BVHLAB_LOG_WARN = 1,
	BVHLAB_LOG_INFO = 2,
	BVHLAB_LOG_DEBUG = 3,
};

struct bvhlab_build_output;

/* A task started by host->spawn (ABI 1.6): the caller's storage, opaque,
 * kept in place from spawn to join. */
typedef struct bvhlab_task {
	uint64_t opaque[24];
} bvhlab_task;

/*
 * Services the host offers a plugin during build(). The table is owned by the
 * host and valid during the call only. A plugin compiled against a newer
 * minor must check struct_size before using a field that came later.
 * All functions are thread-safe unless said otherwise.
 */
typedef struct bvhlab_host {
	uint32_t abi_version; /* BVHLAB_ABI_CURRENT of the host */
	uint32_t struct_size; /* sizeof(bvhlab_host) in the host */

	/* printf-style log line, attributed to the plugin by the host. */
	void (*log)(bvhlab_build_ctx *ctx, int level, const char *fmt, ...)
		BVHLAB_PRINTF(3, 4);
	/* Explains the failure that build() is about to return; last call wins. */
	void (*set_error)(bvhlab_build_ctx *ctx, const char *fmt, ...)
		BVHLAB_PRINTF(2, 3);

	/* Typed option getters: 0, or -ENOENT for an undeclared name, -EINVAL
	 * for a name declared with another type. Strings stay valid during build. */
	int (*option_bool)(bvhlab_build_ctx *ctx, const char *name, bool *out);
	int (*option_int)(bvhlab_build_ctx *ctx, const char *name, int64_t *out);
	int (*option_float)(bvhlab_build_ctx *ctx, const char *name, double *out);
	int (*option_string)(bvhlab_build_ctx *ctx, const char *name, const char **out);

	/* Grows the output buffers to hold at least `nodes` nodes and `indices`
	 * primitive references, keeping their contents; updates out's pointers
	 * and capacities. Not thread-safe: call it from one thread while no
	 * other thread touches the buffers. 0 or -ENOMEM. */
	int (*grow_output)(bvhlab_build_ctx *ctx, struct bvhlab_build_output *out,
	                   uint32_t nodes, uint32_t indices);

	/* Optional progress report, fraction in [0, 1]; may be a no-op. */
	void (*progress)(bvhlab_build_ctx *ctx, double fraction);

	/* What threads = 0 resolves to: the physical cores the calling thread
	 * may run on (its affinity mask and cgroup cpuset; SMT siblings count
	 * once). Logical CPUs before 1.1. */
	uint32_t (*hardware_threads)(bvhlab_build_ctx *ctx);

	/* since 1.1. Binds the calling thread to the worker-th distinct
	 * physical core of the set the build started with (wrapping around
	 * past the last core), when the user enabled pinning; otherwise does
	 * nothing. Call it first thing in each worker, with distinct workers
	 * 0 .. input->threads - 1; the host restores the affinity of the
	 * thread that called build() afterwards. 0, or a negative errno (the
	 * thread then keeps running unpinned). */
	int (*pin_thread)(bvhlab_build_ctx *ctx, uint32_t worker);

	/* since 1.3. Adds `ms` milliseconds to the named phase of this build
	 * or refinement (a call with a name already reported adds to it), so
	 * a builder can say where its time went: e.g. "upload", "device" (a
	 * device's own kernel time, from its events), "download", "convert"
	 * (a peer library's tree turned into the standard layout). Names are
	 * [a-z0-9_], 1 to BVHLAB_PHASE_NAME_MAX - 1 characters, at most
	 * BVHLAB_MAX_PHASES distinct ones per call of build(); anything else,
	 * an ms that is negative, non-finite or over 1e12, or a phase longer
	 * than the whole call, fails the build with a message naming the
	 * phase and the rule. The phases need not add up to the whole call,
	 * which the host times itself (build_ms). Call it from the thread
	 * that called build(). Check BVHLAB_HOST_HAS(host, phase) first. */
	void (*phase)(bvhlab_build_ctx *ctx, const char *name, double ms);

	/* since 1.6. The process's device layer, shared by every device
	 * builder and the core's device tracer and kept for the life of the
	 * process: the device `spec` names (NULL: "auto"; for OpenCL "auto",
	 * "gpu", "cpu" or "P:D") opened once, and the program of `len` bytes
	 * of `source` (0: up to its NUL) built on it with the build `options`
	 * (may be NULL; the host adds correctly rounded division and square
	 * root where the device has them) once: the same spec, source and
	 * options give the same program. *device and *program are the
	 * backend's handles, owned by the host (never release them): for
	 * OpenCL, the only backend so far, a const bvhlab_cl * and a
	 * cl_program, which include/bvhlab/opencl.h's bvhlab_cl_host_program
	 * hands out typed. 0, or a negative errno after set_error: -ENOTSUP
	 * (the host was built without a device backend), -ENODEV (no such
	 * device; the message says what to install), -EINVAL (a bad spec, or
	 * the source does not compile: the compiler's log), -ENOMEM, -EIO.
	 * Check BVHLAB_HOST_HAS(host, device_program) first. */
	int (*device_program)(bvhlab_build_ctx *ctx, const char *spec, const char *source,
	                      size_t len, const char *options, const void **device,
	                      void **program);

	/*
	 * since 1.6: the process's executor, one pool of threads kept for the
	 * whole process and shared by every build, tracing and validation.
	 * Its threads run on the CPU set the build started with, each bound
	 * to one core (as pin_thread binds worker `member`) when the user
	 * enabled pinning: a plugin that uses them does not pin. The calls
	 * may nest (a task may run a team) and come from any thread of the
	 * build; `threads` below means input->threads. Nothing is allocated
	 * per task or per member. Check BVHLAB_HOST_HAS(host, join) (every
	 * field of 1.6 came together).
	 */
	/* Runs fn(arg, member) for member = 0 .. members - 1 all at the same
	 * time (they may wait for each other, e.g. at a barrier), the calling
	 * thread as member 0, and returns when all have returned; their
	 * writes are then visible. 0, or -EAGAIN having run nothing when that
	 * many threads cannot be had (ask again with fewer). */
	int (*run)(bvhlab_build_ctx *ctx, uint32_t members,
	           void (*fn)(void *arg, uint32_t member), void *arg);
	/* fn(arg, lo, hi, member) over ranges that cover [0, count) once, none
	 * longer than grain (0: count / threads), handed to whichever of up
	 * to `threads` members asks first (member < threads: an index for
	 * per-member scratch). 0, or -EINVAL for a NULL fn. */
	int (*for_each)(bvhlab_build_ctx *ctx, uint32_t count, uint32_t grain,
	                void (*fn)(void *arg, uint32_t lo, uint32_t hi, uint32_t member),
	                void *arg);
	/* Reduces [0, count): fixed contiguous shares (one per thread, 4096
	 * items each at least) are each reduced by fn into a copy of *acc
	 * (`size` bytes, holding join's identity on entry), and the copies
	 * are joined into *acc in share order. 0 or -ENOMEM. */
	int (*reduce)(bvhlab_build_ctx *ctx, uint32_t count, void *acc, size_t size,
	              void (*fn)(void *arg, uint32_t lo, uint32_t hi, void *acc),
	              void (*join)(void *arg, void *acc, const void *part), void *arg);
	/* Exclusive prefix sums of in[0 .. count) into out (out may be in);
	 * *total (may be NULL) the sum, in uint32 arithmetic. The same for
	 * every thread count. 0 or -ENOMEM. */
	int (*scan)(bvhlab_build_ctx *ctx, const uint32_t *in, uint32_t *out, uint32_t count,
	            uint32_t *total);
	/* Stable partition of in[0 .. count) into out (not in): the values
	 * pred holds for first, in their order, then the rest; *kept (may be
	 * NULL) how many held. pred is called twice per value and must give
	 * the same answer. 0, -EINVAL or -ENOMEM. */
	int (*partition)(bvhlab_build_ctx *ctx, const uint32_t *in, uint32_t *out,
	                 uint32_t count, bool (*pred)(void *arg, uint32_t value), void *arg,
	                 uint32_t *kept);
	/* Sorts keys[0 .. count), each below 2^key_bits (1 to 64), ascending,
	 * with values (may be NULL) carried along; stable (a radix sort), so
	 * the same for every thread count. 0, -EINVAL or -ENOMEM. */
	int (*sort)(bvhlab_build_ctx *ctx, uint64_t *keys, uint32_t *values, uint32_t count,
	            uint32_t key_bits);
	/* Starts fn(arg) on a thread of the pool, as the next worker number
	 * after the members of a team. 0, or -EAGAIN with fn not run (do the
	 * work on the calling thread then). *task stays put until join. */
	int (*spawn)(bvhlab_build_ctx *ctx, bvhlab_task *task, void (*fn)(void *arg),
	             void *arg);
	/* Waits for a task that spawn started (nothing for one it refused);
	 * its writes are then visible. Every started task must be joined
	 * before build() returns. */
	void (*join)(bvhlab_build_ctx *ctx, bvhlab_task *task);
} bvhlab_host;

/* Limits of host->phase (ABI 1.3). */
#define BVHLAB_MAX_PHASES 8
#define BVHLAB_PHASE_NAME_MAX 32

/* True when `host` has `field`: a host older than the plugin lacks fields
 * that came in later minors, e.g. BVHLAB_HOST_HAS(host, pin_thread). */
#define BVHLAB_HOST_HAS(host, field) \
	((host)->struct_size >= offsetof(bvhlab_host, field) + sizeof((host)->field))

/* ---- build input and output ------------------------------------------- */

/* What the primitives of a build are (bvhlab_build_input.prim_kind, 1.5). */
enum bvhlab_prim_kind {
	/* primitive i is triangle i: indices[3i .. 3i + 3) into vertices */
	BVHLAB_PRIM_TRIANGLES = 0,
	/* primitive i is the box prim_bounds[i], its id i (an instance, a user's
	 * primitive); vertices and indices are NULL, vertex_count 0. Only given
	 * to a builder whose flags have BVHLAB_BUILDER_BOXES. */
	BVHLAB_PRIM_BOXES = 1,
};

/*
 * What a builder builds over: read-only, owned by the host, valid during
 * build(). Primitive i is triangle i of the scene, or box i (prim_kind).
 */
typedef struct bvhlab_build_input {
	uint32_t struct_size;       /* sizeof(bvhlab_build_input) in the host */
	uint32_t prim_count;        /* number of primitives, >= 1 */
	const bvhlab_aabb *prim_bounds; /* [prim_count] box of each primitive */
	const float *centroids;     /* [3 * prim_count] box centre of each primitive */
	bvhlab_aabb bounds;         /* union of all prim_bounds */
	bvhlab_aabb centroid_bounds; /* bounds of all centroids */
	const float *vertices;      /* [3 * vertex_count] triangle vertices */
	uint32_t vertex_count;
	const uint32_t *indices;    /* [3 * prim_count] vertex indices per triangle */
	uint32_t threads;           /* threads the builder may use, >= 1 (0 resolved) */
	uint32_t reserved;          /* zero; keeps the struct 8-byte aligned */
	/* since 1.5: enum bvhlab_prim_kind. A plugin built against an older
	 * minor never sees it, and is only given triangles. */
	uint32_t prim_kind;
	uint32_t reserved2;         /* zero */
	/* since 1.6: the struct the descriptor's fill_options filled from this
	 * call's options (the builder's own, or the refine or update stage's),
	 * options_size bytes, read-only, valid during the call; the same one
	 * for every call of a run. NULL when the host has none (a host before
	 * 1.6 lacks the field: check struct_size; a caller that never read
	 * the options in advance): the plugin then calls its fill_options. */
	const void *options;
} bvhlab_build_input;

/*
 * Where a builder writes its tree. On entry the host has allocated
 * nodes[2 * prim_count - 1] and prim_index[prim_count]; grow them with
 * host->grow_output (e.g. for spatial splits). On success the builder sets
 * node_count and index_count; nodes[0] is the root. Until then the whole
 * capacity is the builder's, and the host ignores what lies past the
 * counts, so a builder may keep scratch there (lbvh does). The harness
 * builds its timed repeats into the same output, so room grown once stays
 * allocated and paged in; its contents on entry are unspecified.
 */
typedef struct bvhlab_build_output {
	uint32_t struct_size;     /* sizeof(bvhlab_build_output) in the host */
	uint32_t node_capacity;   /* nodes allocated */
	bvhlab_node *nodes;       /* [node_capacity] */
	uint32_t *prim_index;     /* [index_capacity] primitive ids referenced by leaves */
	uint32_t index_capacity;  /* prim_index slots allocated */
	uint32_t node_count;      /* set by the builder: nodes used */
	uint32_t index_count;     /* set by the builder: prim_index slots used */
	uint32_t reserved;        /* zero */
	/* since 1.5: the tree's branching factor, 2 to BVHLAB_MAX_WIDTH. The
	 * host sets it to 2 on entry (to the input tree's width for refine and
	 * update, which are only given binary trees); a builder of wider trees
	 * sets it with the counts. Older plugins never touch it: binary. */
	uint32_t width;
	uint32_t reserved2;       /* zero */
} bvhlab_build_output;

/* ---- the descriptor ------------------------------------------------------ */

enum bvhlab_builder_flags {
	BVHLAB_BUILDER_PARALLEL = 1u << 0,      /* uses input->threads > 1 */
	/* Same tree for any thread count and run, as bvhlab_tree_compare judges
	 * it: the same shape, bit-identical boxes and leaf contents; the order
	 * of nodes in the array may differ (parallel builders place subtrees as
	 * their tasks finish). */
	BVHLAB_BUILDER_DETERMINISTIC = 1u << 1,
	/* may reference a primitive more than once, and give a leaf a box that
	 * holds only the part of a triangle inside it (judged by coverage) */
	BVHLAB_BUILDER_SPATIAL_SPLITS = 1u << 2,
	BVHLAB_BUILDER_UNFINISHED = 1u << 3,    /* work in progress: reported as such */
	/* since 1.5: build() accepts prim_kind BVHLAB_PRIM_BOXES (the host
	 * refuses a box build to a builder without it, by name) */
	BVHLAB_BUILDER_BOXES = 1u << 4,
	/* Builds on an OpenCL device that its string option "device" names
	 * (auto, gpu, cpu or P:D, as bvhlab_cl_init in <bvhlab/opencl.h>
	 * takes): the harness records that device with each run (name, kind,
	 * compute units), measures the OpenCL runtime's memory apart from the
	 * build's, and reports the runs in a group of the device, not at a CPU
	 * thread count. Since 1.5; a host that predates the flag
	 * ignores it. */
	BVHLAB_BUILDER_DEVICE = 1u << 5,
};

/*
 * The plugin's descriptor: static, owned by the plugin, never freed.
 * Fields are only ever appended; each later one names the minor it came in.
 */
typedef struct bvhlab_builder {
	uint32_t abi_version;  /* BVHLAB_ABI_CURRENT the plugin was built against */
	uint32_t struct_size;  /* sizeof(bvhlab_builder) the plugin was built with */
	const char *name;      /* short name, [a-z0-9_]+, e.g. "sah_seq" */
	const char *summary;   /* one line for `bvhlab list` */
	uint32_t flags;        /* enum bvhlab_builder_flags */
	uint32_t option_count; /* entries in options */
	const bvhlab_option_decl *options; /* [option_count] */

	/* Builds one tree. Returns 0, or a negative errno after host->set_error.
	 * May be called many times, from one thread at a time. NULL (since
	 * 1.2) in a plugin that only refines. */
	int (*build)(const bvhlab_host *host, bvhlab_build_ctx *ctx,
	             const bvhlab_build_input *input, bvhlab_build_output *output);

	/*
	 * since 1.2, may be NULL. Improves a finished tree in place: on entry
	 * `tree` holds a valid tree in the standard layout (node_count,
	 * index_count set, nodes[0] the root) over the primitives of `input`,
	 * built by any builder; input->threads is the thread count to use.
	 * On return it must hold a valid tree over the same primitives, with
	 * the counts updated; the capacity past the counts is scratch, and
	 * host->grow_output works as in build(). The harness times it as a
	 * stage of its own and reports the SAH cost before and after.
	 * Returns 0, or a negative errno after host->set_error (the tree is
	 * then discarded). Same calling rules as build.
	 */
	int (*refine)(const bvhlab_host *host, bvhlab_build_ctx *ctx,
	              const bvhlab_build_input *input, bvhlab_build_output *tree);

	/*
	 * since 1.4, may be NULL. Updates a finished tree in place after its
	 * primitives moved: on entry `tree` holds a valid tree in the standard
	 * layout (any builder's, counts set) over primitives of the same count
	 * and order as `input`'s, which gives their new boxes and vertices
	 * (the topology is kept; only positions changed). On return it must
	 * hold a valid tree over `input`, with the counts updated; it may
	 * reorder the nodes and prim_index (refit does, into an order it
	 * streams), so a caller keeps no node or slot index across it. The
	 * capacity past the counts is scratch, and host->grow_output works as
	 * in build(). A tree whose references do not fit input (another
	 * triangle count) must be refused with host->set_error, not walked
	 * out of bounds; the host refuses the plainest mismatches before the
	 * call. The harness times it per frame of an animated scene in place
	 * of a rebuild. Returns 0, or a negative errno after host->set_error.
	 * Same calling rules as build.
	 */
	int (*update)(const bvhlab_host *host, bvhlab_build_ctx *ctx,
	              const bvhlab_build_input *input, bvhlab_build_output *tree);

	/*
	 * since 1.6, may be NULL (options_size then 0). Reads this plugin's
	 * options with the host's getters into `out`, options_size bytes the
	 * host zeroed (the plugin's own options struct, choices turned into
	 * what the plugin uses), and checks what no declaration states: a
	 * rule between options, or what this machine allows (e.g. AVX2). The
	 * host calls it once per builder or stage when it reads the config,
	 * where a refusal is a config error (exit 2 before any output, the
	 * message naming the builder and the plugin), and hands the struct to
	 * every build, refine and update of the run as input->options.
	 * Returns 0, or -EINVAL after host->set_error naming the option and
	 * what it allows. Only log, set_error, hardware_threads and the option
	 * getters may be called; the ctx has no output. Must be thread-safe
	 * and keep no state: the struct is all it leaves.
	 */
	int (*fill_options)(const bvhlab_host *host, bvhlab_build_ctx *ctx, void *out);
	uint32_t options_size; /* since 1.6: bytes fill_options writes; 0 without it */
	uint32_t reserved;     /* zero */

	/*
	 * since 1.7, 0: not declared. The most bytes per primitive one build
	 * (or, for a refine or update stage, one call) adds to the process's
	 * resident memory at its peak, for any of its options and thread
	 * counts: its scratch and the output it grows, as a run's
	 * memory.peak_bytes / triangles measures it (the host's output buffers
	 * of 2n - 1 nodes and n indices, 68 bytes, included; the input's
	 * arrays, the scene's share, not). Round up: the harness multiplies it
	 * by the primitive count, adds the scene's own bytes and the stages',
	 * and refuses before building a run whose estimate exceeds
	 * memory_limit_mb (or the memory available), naming both. A builder
	 * that declares none is estimated at BVHLAB_UNDECLARED_BYTES_PER_PRIM.
	 */
	uint32_t peak_bytes_per_prim;
	uint32_t reserved3; /* zero */
	/*
	 * since 1.7, may be NULL. peak_bytes_per_prim for one run's options,
	 * where they differ by option (the SAH plugins' exact sweep keeps
	 * sorted arrays that binning does not): given the struct fill_options
	 * filled for the run (options_size bytes), or 0 to use
	 * peak_bytes_per_prim, which stays the most over all options.
	 */
	uint32_t (*peak_bytes_for)(const void *options);
} bvhlab_builder;

/* What the harness assumes of a builder that declares no
 * peak_bytes_per_prim (one of before 1.7, or 0): above every in-tree
 * builder's declaration, so an undeclared one is not let into a run that
 * the declared ones would not fit. */
#define BVHLAB_UNDECLARED_BYTES_PER_PRIM 400u

/* True when descriptor `b` has `field`: one built against an older minor
 * lacks the fields that came later, e.g. BVHLAB_BUILDER_HAS(b, refine). */
#define BVHLAB_BUILDER_HAS(b, field) \
	((b)->struct_size >= offsetof(bvhlab_builder, field) + sizeof((b)->field))

BVHLAB_END_DECLS

#endif /* BVHLAB_BUILDER_H */
