/*
 * One fake builder plugin, compiled several times with different -D flags
 * into plugins that are broken in exactly one way each (see meson.build).
 * The good variant builds a single leaf holding every primitive: a valid,
 * if useless, tree.
 */
#include <errno.h>
#include <stdlib.h>
#include <string.h>
#include <time.h>
#include <unistd.h>

#include <bvhlab/builder.h>

#ifndef FAKE_NAME
#define FAKE_NAME "fake_good"
#endif

static const bvhlab_option_decl options[] = {
	{.name = "alpha", .type = BVHLAB_OPTION_INT, .help = "an integer in [1, 10]",
	 .def_int = 3, .min = 1, .max = 10},
	{.name = "mode", .type = BVHLAB_OPTION_STRING, .help = "a or b", .def_string = "a",
	 .choices = "a|b"},
	{.name = "flag", .type = BVHLAB_OPTION_BOOL, .help = "a switch", .min = 1, .max = 0},
	{.name = "scale", .type = BVHLAB_OPTION_FLOAT, .help = "a positive number",
	 .def_float = 0.5, .min = 0.0, .max = 100.0},
	{.name = "fail", .type = BVHLAB_OPTION_STRING, .help = "how build() fails or misbehaves",
	 .def_string = "no",
	 .choices = "no|error|silent|positive|segfault|abort|loop|exit|invalid|alloc|shared|hog"},
#ifdef FAKE_BAD_OPTION
	{.name = "broken", .type = 0, .help = "an option of no type"},
#endif
	{.name = "phases", .type = BVHLAB_OPTION_STRING,
	 .help = "phases build() reports (ABI 1.3): none, two (upload twice, device), or broken",
	 .def_string = "none", .choices = "none|two|bad_name|negative|too_many|huge|long"},
	{.name = "wait_for", .type = BVHLAB_OPTION_STRING,
	 .help = "a file build() waits for first (up to a minute)", .def_string = ""},
};

#define MB (1024 * 1024)
#define ALLOC_CHUNK (16 * MB)
#define ALLOC_CAP ((size_t)4096 * MB) /* stop here should no limit apply */

/* Real crashes, not sanitizer reports: the host is to see the signal. */
__attribute__((no_sanitize("address", "undefined"))) static void segfault(void)
{
	volatile int *volatile p = NULL;
	*p = 1;
}

static void spin(void)
{
	volatile unsigned long n = 0;
	for (;;)
		n++;
}

/* A runaway allocation: chunks, each touched, until malloc says no. */
static int allocate(const bvhlab_host *host, bvhlab_build_ctx *ctx)
{
	void *head = NULL;
	size_t total = 0;
	for (; total < ALLOC_CAP; total += ALLOC_CHUNK) {
		void **chunk = malloc(ALLOC_CHUNK);
		if (!chunk)
			break;
		memset(chunk, 1, ALLOC_CHUNK);
		*chunk = head;
		head = chunk;
	}
	while (head) {
		void *next = *(void **)head;
		free(head);
		head = next;
	}
	host->set_error(ctx, "%s after %zu MB", total < ALLOC_CAP ? "out of memory" :
	                "no memory limit", total / MB);
	return -ENOMEM;
}

/* "hog": a good tree, then all the address space the memory limit leaves
 * is taken and kept (chunks from 16 MB down to 64 bytes, untouched: the
 * limit is on address space), so what comes after the build (validation)
 * runs out of memory. Only ever run under a memory limit. */
static void hog(void)
{
	for (size_t chunk = ALLOC_CHUNK; chunk >= 64; chunk /= 4)
		for (size_t total = 0; total < ALLOC_CAP; total += chunk)
			if (!malloc(chunk))
				break;
}

/* Blocks until the file named by "wait_for" exists: tests stop a sweep there. */
static int wait_for(const bvhlab_host *host, bvhlab_build_ctx *ctx)
{
	const char *path = "";
	const struct timespec pause = {.tv_nsec = 10 * 1000 * 1000};
	if (host->option_string(ctx, "wait_for", &path) < 0)
		return -EINVAL;
	for (int k = 0; *path && k < 6000; k++) {
		if (access(path, F_OK) == 0)
			return 0;
		nanosleep(&pause, NULL);
	}
	if (*path)
		host->set_error(ctx, "%s never appeared", path);
	return *path ? -ETIMEDOUT : 0;
}

/* Fails as the "fail" option says, to exercise the host's error paths. */
static int maybe_fail(const bvhlab_host *host, bvhlab_build_ctx *ctx)
{
	const char *fail = "no";
	if (host->option_string(ctx, "fail", &fail) < 0)
		return -EINVAL;
	if (strcmp(fail, "error") == 0) {
		host->set_error(ctx, "asked to fail (alpha was %d)", 3);
		return -EIO;
	}
	if (strcmp(fail, "silent") == 0)
		return -EIO;
	if (strcmp(fail, "positive") == 0)
		return 1;
	if (strcmp(fail, "segfault") == 0)
		segfault();
	if (strcmp(fail, "abort") == 0)
		abort();
	if (strcmp(fail, "loop") == 0)
		spin();
	if (strcmp(fail, "exit") == 0)
		exit(3);
	if (strcmp(fail, "alloc") == 0)
		return allocate(host, ctx);
	return wait_for(host, ctx);
}

static bool fail_is(const bvhlab_host *host, bvhlab_build_ctx *ctx, const char *how)
{
	const char *fail = "no";
	return host->option_string(ctx, "fail", &fail) == 0 && strcmp(fail, how) == 0;
}

/* "shared": two inner nodes share their pair of leaves, so the links form
 * a DAG and not a tree (each primitive still lies in one leaf). */
static int build_shared(const bvhlab_host *host, bvhlab_build_ctx *ctx,
                        const bvhlab_build_input *in, bvhlab_build_output *out)
{
	static const uint32_t first[5] = { 1, 3, 3, 0, 0 };
	uint32_t half = in->prim_count / 2;

	if (in->prim_count < 2 || (out->node_capacity < 5 &&
	                           host->grow_output(ctx, out, 5, in->prim_count) < 0))
		return -EINVAL;
	for (uint32_t i = 0; i < 5; i++) {
		memcpy(out->nodes[i].lo, in->bounds.lo, sizeof(out->nodes[i].lo));
		memcpy(out->nodes[i].hi, in->bounds.hi, sizeof(out->nodes[i].hi));
		out->nodes[i].first = i == 4 ? half : first[i];
		out->nodes[i].count = i == 3 ? half : i == 4 ? in->prim_count - half : 0;
	}
	for (uint32_t k = 0; k < in->prim_count; k++)
		out->prim_index[k] = k;
	out->node_count = 5;
	out->index_count = in->prim_count;
	return 0;
}

/* Busy for ms milliseconds of the monotonic clock. */
static void spend_ms(double ms)
{
	struct timespec t0, t;
	clock_gettime(CLOCK_MONOTONIC, &t0);
	do
		clock_gettime(CLOCK_MONOTONIC, &t);
	while ((double)(t.tv_sec - t0.tv_sec) * 1e3 + (double)(t.tv_nsec - t0.tv_nsec) / 1e6 < ms);
}

/* The "phases" option: upload is reported twice to show that calls add up. */
static void report_phases(const bvhlab_host *host, bvhlab_build_ctx *ctx)
{
	static const char *const many[] = {"p0", "p1", "p2", "p3", "p4", "p5", "p6", "p7", "p8"};
	const char *how = "none";
	if (!BVHLAB_HOST_HAS(host, phase) || host->option_string(ctx, "phases", &how) < 0)
		return;
	if (strcmp(how, "two") == 0) {
		spend_ms(4.0); /* the phases' 4 ms, for real: a phase is part of the build */
		host->phase(ctx, "upload", 1.0);
		host->phase(ctx, "device", 2.5);
		host->phase(ctx, "upload", 0.5);
	} else if (strcmp(how, "bad_name") == 0) {
		host->phase(ctx, "Device Time", 1.0);
	} else if (strcmp(how, "negative") == 0) {
		host->phase(ctx, "device", -1.0);
	} else if (strcmp(how, "huge") == 0) {
		host->phase(ctx, "device", 2e12);
	} else if (strcmp(how, "long") == 0) {
		host->phase(ctx, "device", 5000.0);
	} else if (strcmp(how, "too_many") == 0) {
		for (size_t k = 0; k < sizeof(many) / sizeof(many[0]); k++)
			host->phase(ctx, many[k], 1.0);
	}
}

/* unused in the variant without a build function */
__attribute__((unused)) static int build(const bvhlab_host *host, bvhlab_build_ctx *ctx,
                 const bvhlab_build_input *in, bvhlab_build_output *out)
{
	int r = maybe_fail(host, ctx);
	if (r != 0)
		return r;
	report_phases(host, ctx);
	if (fail_is(host, ctx, "shared"))
		return build_shared(host, ctx, in, out);
	bvhlab_node *root = &out->nodes[0];
	memcpy(root->lo, in->bounds.lo, sizeof(root->lo));
	memcpy(root->hi, in->bounds.hi, sizeof(root->hi));
	/* "invalid": the last primitive goes missing. */
	uint32_t count = in->prim_count - fail_is(host, ctx, "invalid");
	root->first = 0;
	root->count = count;
	for (uint32_t k = 0; k < count; k++)
		out->prim_index[k] = k;
	out->node_count = 1;
	out->index_count = count;
	if (fail_is(host, ctx, "hog"))
		hog();
	return 0;
}

#ifdef FAKE_UPDATE_CRASH
/* An update (ABI 1.4) that crashes: frame 1 of an animation dies in it. */
static int update(const bvhlab_host *host, bvhlab_build_ctx *ctx,
                  const bvhlab_build_input *in, bvhlab_build_output *out)
{
	(void)host;
	(void)ctx;
	(void)in;
	(void)out;
	segfault();
	return 0;
}
#endif

#ifdef FAKE_ABI_MAJOR
#define ABI BVHLAB_ABI_VERSION(FAKE_ABI_MAJOR, 0)
#else
#define ABI BVHLAB_ABI_CURRENT
#endif

#ifdef FAKE_STRUCT_SIZE
#define SIZE FAKE_STRUCT_SIZE
#else
#define SIZE sizeof(bvhlab_builder)
#endif

static const bvhlab_builder desc = {
	.abi_version = ABI,
	.struct_size = SIZE,
	.name = FAKE_NAME,
	.summary = "test plugin: one leaf with every primitive",
	.flags = BVHLAB_BUILDER_DETERMINISTIC,
	.option_count = sizeof(options) / sizeof(options[0]),
	.options = options,
#ifndef FAKE_NULL_BUILD
	.build = build,
#endif
#ifdef FAKE_UPDATE_CRASH
	.update = update,
#endif
};

#ifdef FAKE_NO_ENTRY
BVHLAB_EXPORT const bvhlab_builder *not_the_entry(uint32_t host_abi_major)
#else
BVHLAB_PLUGIN_ENTRY
#endif
{
#ifdef FAKE_NULL_DESCRIPTOR
	/* Serves no real ABI major (the check keeps desc referenced). */
	return host_abi_major == 0xffff ? &desc : NULL;
#else
	return host_abi_major == BVHLAB_ABI_MAJOR ? &desc : NULL;
#endif
}
