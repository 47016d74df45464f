/*
 * template_cl: a minimal OpenCL device builder to copy and grow your own
 * GPU builder from. The device computes the primitives' 30-bit Morton
 * codes (one work-item each); the host sorts them and splits each range
 * at the highest bit in which its first and last codes differ (an LBVH
 * built top-down), with leaves of at most max_leaf primitives.
 *
 * It uses only <bvhlab/opencl.h>, header-only like the rest of the SDK:
 * the device the "device" option names (auto, gpu, cpu or P:D) and the
 * program built on it come from the host's device layer (ABI 1.6,
 * bvhlab_cl_host_program: shared with every device builder and the
 * tracer, kept for the process's life, the compiler's log in any error);
 * the kernel made from it is the plugin's, kept between builds (the host
 * runs one build at a time) and released when the plugin is unloaded; the
 * kernel is timed with its profiling event; a build reports its phases
 * (ABI 1.3): upload, device (the kernel's own time), download, and host.
 * Build it out of tree (meson.build beside this file), then:
 *   bvhlab build ./build/template_cl.so icosphere:frequency=64 -o device=cpu
 */
#define _POSIX_C_SOURCE 200809L /* clock_gettime */
#include <errno.h>
#include <stdlib.h>
#include <time.h>

#include <bvhlab/opencl.h> /* before CL/cl.h: picks the OpenCL 1.2 API */
#include <bvhlab/aabb.h>
#include <bvhlab/builder.h>

static const bvhlab_option_decl options[] = {
	{.name = "max_leaf", .type = BVHLAB_OPTION_INT,
	 .help = "most primitives in a leaf", .def_int = 4, .min = 1, .max = 64},
	{.name = "device", .type = BVHLAB_OPTION_STRING, .def_string = "auto",
	 .help = "OpenCL device: auto, gpu, cpu or P:D (bvhlab info --machine lists them)"},
};

/* Spreads the low 10 bits of x to every third bit; the code interleaves
 * the three quantised centroid coordinates. */
static const char kernel_src[] =
	"static uint spread(uint x) {\n"
	"  x = (x | (x << 16)) & 0x030000ffu;\n"
	"  x = (x | (x << 8)) & 0x0300f00fu;\n"
	"  x = (x | (x << 4)) & 0x030c30c3u;\n"
	"  return (x | (x << 2)) & 0x09249249u;\n"
	"}\n"
	"__kernel void morton(__global const float *c, uint n, float lx, float ly, float lz,\n"
	"                     float sx, float sy, float sz, __global uint *codes) {\n"
	"  uint i = get_global_id(0);\n"
	"  if (i >= n) return;\n"
	"  uint x = (uint)clamp((c[3 * i] - lx) * sx, 0.0f, 1023.0f);\n"
	"  uint y = (uint)clamp((c[3 * i + 1] - ly) * sy, 0.0f, 1023.0f);\n"
	"  uint z = (uint)clamp((c[3 * i + 2] - lz) * sz, 0.0f, 1023.0f);\n"
	"  codes[i] = spread(x) << 2 | spread(y) << 1 | spread(z);\n"
	"}\n";

/* The host's device and program (not ours to release), and our kernel
 * made from that program, kept between builds. */
static struct {
	const bvhlab_cl *cl;
	cl_program program;
	cl_kernel kernel;
} S;

__attribute__((destructor)) static void release(void)
{
	bvhlab_cl_release_kernel(&S.kernel);
}

/* 0, or a negative errno after host->set_error. */
static int open_device(const bvhlab_host *host, bvhlab_build_ctx *ctx, const char *spec)
{
	char err[BVHLAB_CL_ERROR_SIZE];
	const bvhlab_cl *cl;
	cl_program program;
	int rc = bvhlab_cl_host_program(host, ctx, spec, kernel_src, 0, "-cl-std=CL1.2", &cl,
	                                &program);
	if (rc < 0 || (S.kernel && program == S.program))
		return rc;
	release();
	S.cl = cl;
	S.program = program;
	rc = bvhlab_cl_kernel(program, "morton", &S.kernel, err, sizeof(err));
	if (rc < 0)
		host->set_error(ctx, "%s", err);
	return rc;
}

static double now_ms(void)
{
	struct timespec t;
	clock_gettime(CLOCK_MONOTONIC, &t);
	return (double)t.tv_sec * 1e3 + (double)t.tv_nsec * 1e-6;
}

/* What one build needs; ms: upload, device, download, host. */
typedef struct job {
	const bvhlab_build_input *in;
	bvhlab_build_output *out;
	uint32_t max_leaf;
	uint64_t *keys; /* code << 32 | primitive, sorted */
	double ms[4];
} job;

static void set_args(cl_mem c, cl_mem codes, uint32_t n, const float lo[3], const float s[3])
{
	clSetKernelArg(S.kernel, 0, sizeof(cl_mem), &c);
	clSetKernelArg(S.kernel, 1, sizeof(cl_uint), &n);
	for (int k = 0; k < 3; k++) {
		clSetKernelArg(S.kernel, 2 + (cl_uint)k, sizeof(float), &lo[k]);
		clSetKernelArg(S.kernel, 5 + (cl_uint)k, sizeof(float), &s[k]);
	}
	clSetKernelArg(S.kernel, 8, sizeof(cl_mem), &codes);
}

/* The Morton codes on the device, into codes[n]. */
static int device_codes(job *j, uint32_t *codes, char *err, size_t size)
{
	const bvhlab_build_input *in = j->in;
	uint32_t n = in->prim_count;
	float lo[3], hi[3], s[3];
	bvhlab_box_empty(lo, hi);
	for (uint32_t i = 0; i < n; i++)
		bvhlab_box_grow(lo, hi, &in->centroids[3 * (size_t)i], &in->centroids[3 * (size_t)i]);
	for (int k = 0; k < 3; k++)
		s[k] = hi[k] > lo[k] ? 1023.0f / (hi[k] - lo[k]) : 0.0f;
	cl_int rc;
	cl_event ev = NULL;
	size_t global = n;
	double t0 = now_ms();
	cl_mem c = clCreateBuffer(S.cl->context, CL_MEM_READ_ONLY | CL_MEM_COPY_HOST_PTR,
	                          3 * sizeof(float) * n, (void *)in->centroids, &rc);
	cl_mem out = rc == CL_SUCCESS ? clCreateBuffer(S.cl->context, CL_MEM_WRITE_ONLY,
	                                               sizeof(uint32_t) * n, NULL, &rc) : NULL;
	j->ms[0] = now_ms() - t0;
	if (rc == CL_SUCCESS) {
		set_args(c, out, n, lo, s);
		rc = clEnqueueNDRangeKernel(S.cl->queue, S.kernel, 1, NULL, &global, NULL, 0, NULL, &ev);
	}
	if (rc == CL_SUCCESS)
		rc = clWaitForEvents(1, &ev);
	j->ms[1] = rc == CL_SUCCESS ? bvhlab_cl_event_ms(ev) : 0;
	t0 = now_ms();
	if (rc == CL_SUCCESS)
		rc = clEnqueueReadBuffer(S.cl->queue, out, CL_TRUE, 0, sizeof(uint32_t) * n, codes, 0,
		                         NULL, NULL);
	j->ms[2] = now_ms() - t0;
	bvhlab_cl_release_event(&ev);
	bvhlab_cl_release_mem(&c);
	bvhlab_cl_release_mem(&out);
	return bvhlab_cl_check(rc, "morton codes", err, size);
}

static int cmp_key(const void *a, const void *b)
{
	uint64_t x = *(const uint64_t *)a, y = *(const uint64_t *)b;
	return (x > y) - (x < y);
}

/* Where [begin, end) splits: the first key with the highest bit in which
 * the range's first and last codes differ; the middle if they are equal. */
static uint32_t split_at(const job *j, uint32_t begin, uint32_t end)
{
	uint32_t a = (uint32_t)(j->keys[begin] >> 32), b = (uint32_t)(j->keys[end - 1] >> 32);
	if (a == b)
		return begin + (end - begin) / 2;
	uint32_t bit = 1u << (31 - __builtin_clz(a ^ b)), lo = begin + 1, hi = end - 1;
	while (lo < hi) { /* the first code with that bit set */
		uint32_t mid = lo + (hi - lo) / 2;
		if ((uint32_t)(j->keys[mid] >> 32) & bit)
			hi = mid;
		else
			lo = mid + 1;
	}
	return lo;
}

static void build_node(job *j, uint32_t node, uint32_t begin, uint32_t end)
{
	bvhlab_node *n = &j->out->nodes[node];
	if (end - begin <= j->max_leaf) {
		bvhlab_box_empty(n->lo, n->hi);
		for (uint32_t i = begin; i < end; i++) {
			const bvhlab_aabb *b = &j->in->prim_bounds[j->out->prim_index[i]];
			bvhlab_box_grow(n->lo, n->hi, b->lo, b->hi);
		}
		n->first = begin;
		n->count = end - begin;
		return;
	}
	uint32_t mid = split_at(j, begin, end), first = j->out->node_count;
	j->out->node_count += 2; /* children are a pair: nodes[first], nodes[first + 1] */
	build_node(j, first, begin, mid);
	build_node(j, first + 1, mid, end);
	n = &j->out->nodes[node];
	bvhlab_box_empty(n->lo, n->hi);
	for (int c = 0; c < 2; c++)
		bvhlab_box_grow(n->lo, n->hi, j->out->nodes[first + c].lo, j->out->nodes[first + c].hi);
	n->first = first;
	n->count = 0;
}

/* Sort on the host, then the hierarchy; ms[3] is this part. */
static int host_part(job *j, const uint32_t *codes)
{
	uint32_t n = j->in->prim_count;
	double t0 = now_ms();
	j->keys = malloc(sizeof(*j->keys) * n);
	if (!j->keys)
		return -ENOMEM;
	for (uint32_t i = 0; i < n; i++)
		j->keys[i] = (uint64_t)codes[i] << 32 | i;
	qsort(j->keys, n, sizeof(*j->keys), cmp_key);
	for (uint32_t i = 0; i < n; i++)
		j->out->prim_index[i] = (uint32_t)j->keys[i];
	j->out->node_count = 1;
	build_node(j, 0, 0, n);
	j->out->index_count = n;
	free(j->keys);
	j->ms[3] = now_ms() - t0;
	return 0;
}

static int read_options(const bvhlab_host *host, bvhlab_build_ctx *ctx, job *j,
                        const char **device)
{
	int64_t max_leaf;
	if (host->option_int(ctx, "max_leaf", &max_leaf) < 0 ||
	    host->option_string(ctx, "device", device) < 0) {
		host->set_error(ctx, "cannot read the options");
		return -EINVAL;
	}
	j->max_leaf = (uint32_t)max_leaf;
	return 0;
}

static int build(const bvhlab_host *host, bvhlab_build_ctx *ctx,
                 const bvhlab_build_input *input, bvhlab_build_output *output)
{
	static const char *const phases[] = {"upload", "device", "download", "host"};
	char err[BVHLAB_CL_ERROR_SIZE];
	const char *device;
	job j = {.in = input, .out = output};
	uint32_t n = input->prim_count;
	int rc = read_options(host, ctx, &j, &device);
	if (rc < 0)
		return rc;
	/* The host allocated 2N-1 nodes and N indices: enough here. */
	if (n == 0 || output->node_capacity < 2 * (uint64_t)n - 1 || output->index_capacity < n) {
		host->set_error(ctx, "need at least one primitive, 2N-1 nodes and N indices");
		return -EINVAL;
	}
	uint32_t *codes = malloc(sizeof(*codes) * n);
	if (!codes)
		return -ENOMEM;
	rc = open_device(host, ctx, device);
	if (rc == 0 && (rc = device_codes(&j, codes, err, sizeof(err))) < 0)
		host->set_error(ctx, "%s", err);
	else if (rc == 0 && (rc = host_part(&j, codes)) < 0)
		host->set_error(ctx, "out of memory");
	free(codes);
	for (int k = 0; rc == 0 && k < 4 && BVHLAB_HOST_HAS(host, phase); k++)
		host->phase(ctx, phases[k], j.ms[k]);
	return rc;
}

BVHLAB_PLUGIN(.name = "template_cl",
	.flags = BVHLAB_BUILDER_DETERMINISTIC | BVHLAB_BUILDER_DEVICE,
	.summary = "template OpenCL plugin: Morton codes on the device, LBVH split on the host",
	.option_count = sizeof(options) / sizeof(options[0]), .options = options, .build = build)
