/*
 * embree: Intel Embree 3's rtcBuildBVH as a peer in the same harness, so a
 * builder's time and tree quality are measured against the industry
 * reference in one run.
 *
 * quality "low" is Embree's Morton builder, "medium" its binned SAH, "high"
 * binned SAH with spatial splits (references to one triangle may repeat;
 * the primitive array gets split_factor times the triangles as capacity).
 * The descriptor therefore declares BVHLAB_BUILDER_SPATIAL_SPLITS for every
 * quality: the flag is per descriptor, and the validator still demands at
 * least one reference per primitive (the tests check "low" and "medium"
 * reference each exactly once).
 *
 * Over boxes (BVHLAB_PRIM_BOXES: a two-level scene's top, over the
 * instances' world boxes) the same rtcBuildBVH builds from the boxes
 * alone (the primitive id the instance); "high" is refused there, since
 * its spatial splits clip triangles.
 *
 * Embree's tasking (TBB on Debian) sizes its thread pool per device, and
 * creating one costs far more than a small build, so one device is kept
 * for the last thread count asked for and replaced when it changes. Only
 * one lives at a time: TBB caps parallelism at the smallest limit of all
 * live devices. The last device stays until the process exits (reachable,
 * not leaked): releasing it from an exit handler runs after Embree's own
 * static destructors and fails. The plugin is linked with -z nodelete so
 * that dlclose never unmaps Embree under its sleeping worker threads.
 *
 * As the harness keeps a builder's output between the repeats of a run
 * ("host-kept output"), the device's RTCBVH (whose allocator keeps its
 * blocks: Embree's own bvh_builder tutorial builds into one) and the
 * primitive array are kept and reused by the next build; filling the array
 * is reported as phase "input", the tree's conversion as "convert", so
 * the library's own time is build_ms without both (what
 * bench/peers-standalone/ compares against Embree alone).
 */
#include <errno.h>
#include <math.h>
#include <pthread.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/resource.h>
#include <time.h>

#include "embree_internal.h"
#include "plugin_options.h"

/* Embree's recursion depth limit; larger leaves are split before it. */
#define MAX_DEPTH 64

/* The cached device, its BVH and the primitive array; build() holds the
 * lock throughout. */
static struct {
	pthread_mutex_t lock;
	RTCDevice device;
	RTCBVH bvh;                      /* of `device`, or NULL */
	struct RTCBuildPrimitive *prims; /* [capacity] */
	size_t capacity;
	uint32_t threads;
	char error[256]; /* the device's last error message */
} cache = {.lock = PTHREAD_MUTEX_INITIALIZER};

static void on_error(void *user, enum RTCError code, const char *str)
{
	(void)user;
	snprintf(cache.error, sizeof(cache.error), "Embree error %d: %s", (int)code,
	         str ? str : "(no message)");
}

static RTCDevice device_for(uint32_t threads)
{
	char config[64];
	if (cache.device && cache.threads == threads)
		return cache.device;
	if (cache.bvh)
		rtcReleaseBVH(cache.bvh);
	cache.bvh = NULL;
	if (cache.device)
		rtcReleaseDevice(cache.device);
	snprintf(config, sizeof(config), "threads=%u,verbose=0", threads);
	cache.device = rtcNewDevice(config);
	cache.threads = threads;
	if (cache.device)
		rtcSetDeviceErrorFunction(cache.device, on_error, NULL);
	return cache.device;
}

/* Why rtcNewDevice failed: Embree's error code for it (rtcGetDeviceError
 * on no device), and an address-space limit, which its allocators and
 * threads run into first. */
static int device_failed(const bvhlab_host *host, bvhlab_build_ctx *ctx, uint32_t threads)
{
	static const char *const names[] = {"no error code", "unknown error", "invalid argument",
	                                    "invalid operation", "out of memory",
	                                    "unsupported CPU", "cancelled"};
	enum RTCError code = rtcGetDeviceError(NULL);
	struct rlimit rl;
	char limit[160] = "";
	if (getrlimit(RLIMIT_AS, &rl) == 0 && rl.rlim_cur != RLIM_INFINITY)
		snprintf(limit, sizeof(limit), "; the address space is limited to %llu MB "
		         "(memory_limit_mb): raise it or drop it for Embree",
		         (unsigned long long)(rl.rlim_cur >> 20));
	host->set_error(ctx, "rtcNewDevice(threads=%u) failed: %s%s", threads,
	                (unsigned)code < sizeof(names) / sizeof(names[0]) ? names[code]
	                                                                  : "unknown error",
	                limit);
	return code == RTC_ERROR_OUT_OF_MEMORY || limit[0] ? -ENOMEM : -ENODEV;
}

typedef struct settings {
	enum RTCBuildQuality quality;
	int quality_choice; /* low|medium|high, as the option says */
	int64_t width;      /* Embree's maxBranchingFactor: 2, or its 4- and 8-wide trees */
	int64_t max_leaf, min_leaf;
	double c_trav, c_isect, split_factor;
} settings;

static const plugin_option options[] = {
	PLUGIN_OPTION(settings, quality_choice, CHOICE, .name = "quality",
	              .help = "low (Morton), medium (binned SAH) or high (SAH with spatial "
	                      "splits)",
	              .def_string = "medium", .choices = "low|medium|high"),
	PLUGIN_OPTION(settings, width, I64, .name = "width",
	              .help = "children per inner node (maxBranchingFactor): 2, or Embree's own "
	                      "4- and 8-wide trees (BVH4, BVH8), written as bvhlab wide trees",
	              .def_int = 2, .min = 2, .max = 8, .choices = "2|4|8"),
	PLUGIN_MAX_LEAF(settings, max_leaf, I64, RTC_BUILD_MAX_PRIMITIVES_PER_LEAF,
	                "most primitives in a leaf (Embree allows up to 32)"),
	PLUGIN_OPTION(settings, min_leaf, I64, .name = "min_leaf",
	              .help = "always a leaf at this size or below; low (Morton) makes every "
	                      "leaf this small",
	              .def_int = 1, .min = 1, .max = RTC_BUILD_MAX_PRIMITIVES_PER_LEAF),
	PLUGIN_OPTION(settings, c_trav, DOUBLE, .name = "c_trav",
	              .help = "SAH cost of traversing an inner node (Embree's traversalCost)",
	              .def_float = 1.0, .min = 1e-6, .max = 1e6),
	PLUGIN_OPTION(settings, c_isect, DOUBLE, .name = "c_isect",
	              .help = "SAH cost of intersecting one primitive (Embree's "
	                      "intersectionCost)",
	              .def_float = 1.0, .min = 1e-6, .max = 1e6),
	PLUGIN_OPTION(settings, split_factor, DOUBLE, .name = "split_factor",
	              .help = "high: room for references, in triangles (Embree's own default "
	                      "1.2)",
	              .def_float = 1.2, .min = 1.0, .max = 4.0),
};

/* The quality choice into Embree's enum, once per run (min_leaf <=
 * max_leaf is the host's rule for min_/max_ pairs). */
static int derive_quality(const bvhlab_host *host, bvhlab_build_ctx *ctx, void *opt)
{
	static const enum RTCBuildQuality quality[] = {
		RTC_BUILD_QUALITY_LOW, RTC_BUILD_QUALITY_MEDIUM, RTC_BUILD_QUALITY_HIGH,
	};
	settings *s = opt;
	(void)host;
	(void)ctx;
	s->quality = quality[s->quality_choice];
	return 0;
}
PLUGIN_DECLS(options, settings, derive_quality)

/* Embree's input: one 32-byte record per triangle, room for splits after,
 * in the kept array (grown when too small); NULL when out of memory. */
static struct RTCBuildPrimitive *make_prims(const bvhlab_build_input *in, size_t capacity)
{
	if (capacity > cache.capacity) {
		size_t bytes = capacity * sizeof(struct RTCBuildPrimitive);
		free(cache.prims);
		cache.capacity = 0;
		cache.prims = aligned_alloc(32, (bytes + 31) & ~(size_t)31);
		if (!cache.prims)
			return NULL;
		cache.capacity = capacity;
	}
	struct RTCBuildPrimitive *p = cache.prims;
	for (uint32_t i = 0; i < in->prim_count; i++) {
		const bvhlab_aabb *b = &in->prim_bounds[i];
		p[i] = (struct RTCBuildPrimitive){b->lo[0], b->lo[1], b->lo[2], 0,
		                                  b->hi[0], b->hi[1], b->hi[2], i};
	}
	return p;
}

/* The device's kept BVH, made on first use. */
static RTCBVH bvh_for(RTCDevice dev)
{
	if (!cache.bvh)
		cache.bvh = rtcNewBVH(dev);
	return cache.bvh;
}

static void fill_args(struct RTCBuildArguments *a, const settings *s, RTCBVH bvh,
                      struct RTCBuildPrimitive *prims, size_t count, size_t capacity,
                      embree_job *job)
{
	*a = rtcDefaultBuildArguments();
	a->buildQuality = s->quality;
	a->maxBranchingFactor = (unsigned int)s->width;
	a->maxDepth = MAX_DEPTH;
	a->minLeafSize = (unsigned int)s->min_leaf;
	a->maxLeafSize = (unsigned int)s->max_leaf;
	a->traversalCost = (float)s->c_trav;
	a->intersectionCost = (float)s->c_isect;
	a->bvh = bvh;
	a->primitives = prims;
	a->primitiveCount = count;
	a->primitiveArrayCapacity = capacity;
	a->userPtr = job;
	embree_set_callbacks(a, s->quality == RTC_BUILD_QUALITY_HIGH);
}

static double now_ms(void)
{
	struct timespec ts;
	clock_gettime(CLOCK_MONOTONIC, &ts);
	return ts.tv_sec * 1e3 + ts.tv_nsec * 1e-6;
}

/* Runs Embree and converts its tree; the device lock is held. */
static int build_locked(const bvhlab_host *host, bvhlab_build_ctx *ctx,
                        const bvhlab_build_input *input, const settings *s,
                        bvhlab_build_output *output)
{
	size_t n = input->prim_count, capacity = n;
	if (s->quality == RTC_BUILD_QUALITY_HIGH)
		capacity = (size_t)ceil(s->split_factor * (double)n);
	double t0 = now_ms();
	RTCDevice dev = device_for(input->threads);
	if (!dev)
		return device_failed(host, ctx, input->threads);
	double t1 = now_ms();
	struct RTCBuildPrimitive *prims = make_prims(input, capacity);
	RTCBVH bvh = prims ? bvh_for(dev) : NULL;
	if (!bvh) {
		host->set_error(ctx, "out of memory for %zu build primitives", capacity);
		return -ENOMEM;
	}
	struct RTCBuildArguments args;
	embree_job job = {.input = input};
	fill_args(&args, s, bvh, prims, n, capacity, &job);
	cache.error[0] = '\0';
	double t2 = now_ms();
	const tnode *root = rtcBuildBVH(&args);
	double t3 = now_ms();
	if (!root) {
		host->set_error(ctx, "rtcBuildBVH failed: %s", cache.error[0] ? cache.error : "?");
		return -EIO;
	}
	int rc = embree_write_tree(host, ctx, root, output);
	if (rc == 0)
		output->width = (uint32_t)s->width;
	double t4 = now_ms();
	/* The input and the conversion are bvhlab's cost, not Embree's:
	 * reported apart so the report shows the library's own time beside
	 * the whole call. */
	if (BVHLAB_HOST_HAS(host, phase)) {
		host->phase(ctx, "input", t2 - t1);
		host->phase(ctx, "convert", t4 - t3);
	}
	host->log(ctx, BVHLAB_LOG_DEBUG, "ms: device %.2f, primitives %.2f, rtcBuildBVH %.2f, "
	          "conversion %.2f", t1 - t0, t2 - t1, t3 - t2, t4 - t3);
	return rc;
}

static int build(const bvhlab_host *host, bvhlab_build_ctx *ctx,
                 const bvhlab_build_input *input, bvhlab_build_output *output)
{
	settings s;
	int rc;
	if (input->prim_count == 0 || input->prim_count > UINT32_MAX / 8) {
		host->set_error(ctx, "cannot build over %u primitives", input->prim_count);
		return -EINVAL;
	}
	if ((rc = PLUGIN_OPTIONS_GET(host, ctx, input, &s)) < 0)
		return rc;
	if (input->prim_kind == BVHLAB_PRIM_BOXES && s.quality == RTC_BUILD_QUALITY_HIGH) {
		host->set_error(ctx, "quality 'high' splits triangles; a build over boxes (a "
		                "two-level top) takes 'low' or 'medium'");
		return -EINVAL;
	}
	pthread_mutex_lock(&cache.lock);
	rc = build_locked(host, ctx, input, &s, output);
	pthread_mutex_unlock(&cache.lock);
	return rc;
}

PLUGIN_WITH_OPTIONS(options, .name = "embree",
	.flags = BVHLAB_BUILDER_PARALLEL | BVHLAB_BUILDER_SPATIAL_SPLITS |
	         BVHLAB_BUILDER_BOXES,
	.summary = "Intel Embree 3 rtcBuildBVH: low (Morton), "
	           "medium (binned SAH), high (spatial splits); low and medium over boxes",
	.build = build,
	.peak_bytes_per_prim = 256 /* measured 129-199 (low the most) */)
