/*
 * What every device builder's build() does around its own kernels
 * (cl_dev.h): the start (the primitive count, the output's room, the
 * device and program, the tree of a single primitive) and the report of
 * its phases.
 */
#include <errno.h>

#include "cl_dev.h"
#include "morton_front.h"

int cl_build_begin(const cl_builder *cb, cl_dev *d, const char *spec, const bvhlab_host *host,
                   bvhlab_build_ctx *ctx, const bvhlab_build_input *in,
                   bvhlab_build_output *out)
{
	uint32_t n = in->prim_count;
	int rc;

	if (n == 0 || n > cb->max_prims) {
		host->set_error(ctx, "cannot build over %u primitives", n);
		return -EINVAL;
	}
	if ((rc = big_ensure_output(host, ctx, n, 0, out)) < 0)
		return rc;
	rc = cl_dev_open(d, host, ctx, spec, cb->src, cb->len, cb->kernels, cb->kernel_count);
	if (rc < 0)
		return rc;
	if (n > 1)
		return 0;
	morton_single_leaf(in, out);
	return 1;
}

void cl_report_phases(const bvhlab_host *host, bvhlab_build_ctx *ctx,
                      const double ms[CL_PHASES])
{
	static const char *const names[CL_PHASES] = { "upload", "device", "download", "convert" };

	if (!BVHLAB_HOST_HAS(host, phase))
		return;
	for (int k = 0; k < CL_PHASES; k++)
		host->phase(ctx, names[k], ms[k]);
}

int cl_build_run(const cl_builder *cb, const cl_run_spec *rs, cl_dev *d, void *b,
                 const bvhlab_host *host, bvhlab_build_ctx *ctx, const bvhlab_build_input *in,
                 bvhlab_build_output *out)
{
	char err[BVHLAB_CL_ERROR_SIZE];
	const char *spec = *(const char **)(void *)((char *)b + rs->device_at);
	int rc = cl_build_begin(cb, d, spec, host, ctx, in, out);

	if (rc != 0)
		return rc < 0 ? rc : 0;
	if ((rc = rs->run(b, out, err, sizeof(err))) < 0) {
		host->set_error(ctx, "%s", err);
		return rc;
	}
	host->log(ctx, BVHLAB_LOG_DEBUG, "%u prims on %s", in->prim_count, d->cl.name);
	cl_report_phases(host, ctx, (const double *)(void *)((char *)b + rs->ms_at));
	return 0;
}
