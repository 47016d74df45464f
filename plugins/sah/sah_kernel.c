/*
 * The SAH kernel's entry points: options, builder set-up and tear-down, the
 * dispatch of one job to its split search (sah_split.h) and the sequential
 * subtree builder. Node writing and the leaf rule are in sah_nodes.c.
 */
#include <errno.h>
#include <stdlib.h>
#include <string.h>

#include "big_alloc.h"
#include "sah_bins_avx2.h"
#include "sah_kernel.h"
#include "sah_split.h"

static int read_int(const bvhlab_host *host, bvhlab_build_ctx *ctx, const char *name,
                    int64_t lo, int64_t hi, uint32_t *out)
{
	int64_t v;
	int rc = host->option_int(ctx, name, &v);

	if (rc < 0) {
		host->set_error(ctx, "option \"%s\" is not available (%d)", name, rc);
		return rc;
	}
	if (v < lo || v > hi) {
		host->set_error(ctx, "option \"%s\" = %lld is outside %lld..%lld", name,
		                (long long)v, (long long)lo, (long long)hi);
		return -EINVAL;
	}
	*out = (uint32_t)v;
	return 0;
}

static int read_cost(const bvhlab_host *host, bvhlab_build_ctx *ctx, const char *name,
                     float *out)
{
	double v;
	int rc = host->option_float(ctx, name, &v);

	if (rc < 0) {
		host->set_error(ctx, "option \"%s\" is not available (%d)", name, rc);
		return rc;
	}
	/* Written as a negation so that NaN is rejected too. */
	if (!(v > 0 && v <= 1e30)) {
		host->set_error(ctx, "option \"%s\" = %g must be positive and finite", name, v);
		return -EINVAL;
	}
	*out = (float)v;
	return 0;
}

static int read_method(const bvhlab_host *host, bvhlab_build_ctx *ctx, int *out)
{
	const char *s;
	int rc = host->option_string(ctx, "method", &s);

	if (rc < 0) {
		host->set_error(ctx, "option \"method\" is not available (%d)", rc);
		return rc;
	}
	if (s && strcmp(s, "sweep") == 0) {
		*out = SAH_SWEEP;
	} else if (s && strcmp(s, "binned") == 0) {
		*out = SAH_BINNED;
	} else {
		host->set_error(ctx, "option \"method\" = \"%s\" is not sweep or binned",
		                s ? s : "(null)");
		return -EINVAL;
	}
	return 0;
}

static int read_simd(const bvhlab_host *host, bvhlab_build_ctx *ctx, int *out)
{
	const char *s;
	int rc = host->option_string(ctx, "simd", &s);
	bool avx2 = sah_cpu_has_avx2();

	if (rc < 0) {
		host->set_error(ctx, "option \"simd\" is not available (%d)", rc);
		return rc;
	}
	if (s && strcmp(s, "avx2") == 0 && !avx2) {
		host->set_error(ctx, "option \"simd\" = \"avx2\", but this CPU (or build) has no "
		                "AVX2; use auto or sse");
		return -ENOTSUP;
	}
	if (!s || (strcmp(s, "auto") && strcmp(s, "avx2") && strcmp(s, "sse"))) {
		host->set_error(ctx, "option \"simd\" = \"%s\" is not auto, avx2 or sse",
		                s ? s : "(null)");
		return -EINVAL;
	}
	*out = strcmp(s, "sse") && avx2 ? SAH_SIMD_AVX2 : SAH_SIMD_SSE;
	return 0;
}

static int read_quality(const bvhlab_host *host, bvhlab_build_ctx *ctx, int *out)
{
	const char *s;
	int rc = host->option_string(ctx, "quality", &s);

	if (rc < 0) {
		host->set_error(ctx, "option \"quality\" is not available (%d)", rc);
		return rc;
	}
	if (s && strcmp(s, "high") == 0) {
		*out = SAH_HIGH;
	} else if (s && strcmp(s, "fast") == 0) {
		*out = SAH_FAST;
	} else {
		host->set_error(ctx, "option \"quality\" = \"%s\" is not high or fast",
		                s ? s : "(null)");
		return -EINVAL;
	}
	return 0;
}

int sah_options_read(const bvhlab_host *host, bvhlab_build_ctx *ctx, sah_options *opt)
{
	int rc;

	if ((rc = read_method(host, ctx, &opt->method)) < 0 ||
	    (rc = read_int(host, ctx, "bins", 2, SAH_MAX_BINS, &opt->bins)) < 0 ||
	    (rc = read_int(host, ctx, "max_leaf", 1, 64, &opt->max_leaf)) < 0 ||
	    (rc = read_cost(host, ctx, "c_trav", &opt->c_trav)) < 0 ||
	    (rc = read_cost(host, ctx, "c_isect", &opt->c_isect)) < 0 ||
	    (rc = read_simd(host, ctx, &opt->simd)) < 0 ||
	    (rc = read_quality(host, ctx, &opt->quality)) < 0)
		return rc;
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

static int alloc_sweep(sah_builder *b, const bvhlab_build_input *input)
{
	size_t n = b->prim_count;

	for (int a = 0; a < 3; a++)
		b->prims[a] = big_alloc(n * sizeof(sah_prim));
	b->temp = big_alloc(n * sizeof(sah_prim));
	b->area = malloc(n * sizeof(float));
	b->side = malloc(n);
	if (!b->prims[0] || !b->prims[1] || !b->prims[2] || !b->temp || !b->area || !b->side)
		return -ENOMEM;
	sah_copy_prims(b, input, b->temp);
	return sah_presort(b);
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
		rc = alloc_sweep(b, input);
		if (rc < 0)
			goto fail;
	} else {
		b->prims[0] = big_alloc((size_t)b->prim_count * sizeof(sah_prim));
		b->alt = big_alloc((size_t)b->prim_count * sizeof(sah_prim));
		if (!b->prims[0] || !b->alt)
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
		big_free(b->prims[a]);
		b->prims[a] = NULL;
	}
	big_free(b->temp);
	big_free(b->alt);
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
