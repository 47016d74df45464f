/*
 * The SAH kernel's entry points: options, builder set-up and tear-down, the
 * dispatch of one job to its split search (sah_split.h) and the sequential
 * subtree builder. Node writing and the leaf rule are in sah_nodes.c.
 */
#include <errno.h>
#include <stdint.h>
#include <stdlib.h>
#include <string.h>

#include "big_alloc.h"
#include "sah_bins_avx2.h"
#include "sah_kernel.h"
#include "sah_split.h"

/* simd "auto" becomes avx2 where the CPU has it; "avx2" without it is refused
 * (the declaration cannot say what the CPU has). Run once, as the plugin's
 * fill_options check, when the config is read. */
int sah_options_resolve(const bvhlab_host *host, bvhlab_build_ctx *ctx, sah_options *opt)
{
	bool avx2 = sah_cpu_has_avx2();

	if (opt->simd_asked == SAH_ASK_AVX2 && !avx2) {
		host->set_error(ctx, "option 'simd' is 'avx2', but this CPU (or build) has no "
		                "AVX2: allowed here are auto and sse");
		return -EINVAL;
	}
	opt->simd = opt->simd_asked != SAH_ASK_SSE && avx2 ? SAH_SIMD_AVX2 : SAH_SIMD_SSE;
	return 0;
}

static bool input_ok(const sah_options *opt, const bvhlab_build_input *in,
                     const bvhlab_build_output *out)
{
	uint64_t n = in->prim_count;

	if (n == 0 || n > UINT32_MAX / 2 || !in->prim_bounds || !out->nodes || !out->prim_index)
		return false;
	if (opt->bins < 2 || opt->bins > SAH_MAX_BINS || opt->max_leaf < 1)
		return false;
	return out->node_capacity >= 2 * n - 1 && out->index_capacity >= n;
}

/*
 * The record arrays: 4 for sweep (prims[0..2], temp), 2 for binned
 * (prims[0], alt). Past the tree in the output when the host gave the room
 * (sah_scratch_nodes), which it keeps between builds: fresh mappings
 * would be paged in and zeroed by the kernel at every build (on igea
 * subdivided once, 128 MB for sweep). Else mapped for this build.
 */
static int alloc_records(sah_builder *b, const bvhlab_build_output *out, unsigned count,
                         sah_prim **dst[4])
{
	size_t bytes = ((size_t)b->prim_count * sizeof(sah_prim) + 63) & ~(size_t)63;
	uint64_t tree = 2 * (uint64_t)b->prim_count - 1;
	uint32_t spare = sah_scratch_nodes(b->opt.method, b->prim_count);
	char *room = NULL;

	if (spare && out->node_capacity >= tree + spare)
		room = (char *)(((uintptr_t)(out->nodes + tree) + 63) & ~(uintptr_t)63);
	b->in_output = room != NULL;
	for (unsigned k = 0; k < count; k++) {
		*dst[k] = room ? (sah_prim *)(void *)(room + k * bytes) : big_alloc(bytes);
		if (!*dst[k])
			return -ENOMEM;
	}
	return 0;
}

static int alloc_sweep(sah_builder *b, const bvhlab_build_input *input,
                       const bvhlab_build_output *out)
{
	sah_prim **dst[4] = { &b->prims[0], &b->prims[1], &b->prims[2], &b->temp };
	size_t n = b->prim_count;
	int rc = alloc_records(b, out, 4, dst);

	b->area = malloc(n * sizeof(float));
	b->side = malloc(n);
	if (rc < 0 || !b->area || !b->side)
		return -ENOMEM;
	sah_copy_prims(b, input, b->temp);
	return sah_presort(b);
}

uint32_t sah_scratch_nodes(int method, uint32_t n)
{
	return big_spare_nodes(n, (method == SAH_SWEEP ? 4 : 2) *
	                          (((size_t)n * sizeof(sah_prim) + 63) & ~(size_t)63));
}

int sah_builder_init(sah_builder *b, const sah_options *opt,
                     const bvhlab_build_input *input, bvhlab_build_output *output,
                     const team_host *th)
{
	int rc = -ENOMEM;

	memset(b, 0, sizeof(*b));
	if (!input_ok(opt, input, output))
		return -EINVAL;
	b->opt = *opt;
	b->th = th;
	b->prim_count = input->prim_count;
	b->root_box = input->bounds;
	b->nodes = output->nodes;
	b->ids = output->prim_index;
	atomic_init(&b->node_counter, 1);
	if (opt->method == SAH_SWEEP) {
		rc = alloc_sweep(b, input, output);
		if (rc < 0)
			goto fail;
	} else {
		sah_prim **dst[4] = { &b->prims[0], &b->alt };
		if (alloc_records(b, output, 2, dst) < 0)
			goto fail;
		sah_copy_prims(b, input, b->prims[0]);
	}
	return 0;
fail:
	sah_builder_free(b);
	return rc;
}

void sah_builder_free(sah_builder *b)
{
	for (int a = 0; a < 3; a++) {
		if (!b->in_output)
			big_free(b->prims[a]);
		b->prims[a] = NULL;
	}
	if (!b->in_output) {
		big_free(b->temp);
		big_free(b->alt);
	}
	b->alt = NULL;
	free(b->area);
	free(b->side);
	b->temp = NULL;
	b->area = NULL;
	b->side = NULL;
}

void sah_builder_root(const sah_builder *b, sah_job *root)
{
	root->node = 0;
	root->begin = 0;
	root->end = b->prim_count;
	root->depth = 0;
	root->alt = 0;
	root->box = b->root_box;
	root->cbox = b->root_cbox;
}

void sah_builder_finish(sah_builder *b, bvhlab_build_output *output)
{
	output->node_count = sah_node_count(b);
	output->index_count = b->prim_count;
}

unsigned sah_split_job(sah_builder *b, const sah_job *job, sah_job child[2])
{
	if (job->end - job->begin <= SAH_SMALL_MAX) {
		if (b->opt.quality == SAH_FAST)
			sah_small_fast_subtree(b, job);
		else
			sah_small_subtree(b, job);
		return 0;
	}
	if (b->opt.method == SAH_SWEEP)
		return sah_sweep_split(b, job, child);
	return sah_binned_split(b, job, child);
}

/* Larger-child-waits keeps the stack within log2(2^32) + 1 entries. */
#define STACK_SIZE 64

void sah_build_subtree(sah_builder *b, const sah_job *job)
{
	sah_job stack[STACK_SIZE];
	sah_job cur = *job, child[2];
	unsigned sp = 0;

	for (;;) {
		if (sah_split_job(b, &cur, child) == 2) {
			uint32_t n0 = child[0].end - child[0].begin;
			uint32_t n1 = child[1].end - child[1].begin;
			unsigned small = n0 <= n1 ? 0 : 1;

			stack[sp++] = child[1 - small];
			cur = child[small];
			continue;
		}
		if (sp == 0)
			break;
		cur = stack[--sp];
	}
}
