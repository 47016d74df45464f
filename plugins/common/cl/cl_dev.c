/* The device builders' device, program and kernels (cl_dev.h). */
#include <errno.h>
#include <string.h>

#include "cl_dev.h"

void cl_dev_close(cl_dev *d)
{
	for (unsigned k = 0; k < d->kernel_count; k++)
		bvhlab_cl_release_kernel(&d->k[k]);
	memset(d, 0, sizeof(*d));
}

void cl_kept_free(cl_dev *d, cl_sort *s, cl_buf *b, unsigned count)
{
	cl_bufs_free(b, count);
	cl_bufs_free(s->b, SB_COUNT);
	cl_dev_close(d);
}

int cl_dev_open(cl_dev *d, const bvhlab_host *host, bvhlab_build_ctx *ctx, const char *spec,
                const char *src, size_t len, const char *const *names, unsigned count)
{
	char err[BVHLAB_CL_ERROR_SIZE];
	const bvhlab_cl *cl;
	cl_program prog;
	int rc = bvhlab_cl_host_program(host, ctx, spec, src, len, NULL, &cl, &prog);

	if (rc < 0 || prog == d->prog)
		return rc;
	cl_dev_close(d);
	if (count > CL_DEV_MAX_KERNELS) {
		host->set_error(ctx, "cl: more than %d kernels", CL_DEV_MAX_KERNELS);
		return -EINVAL;
	}
	d->cl = *cl;
	d->prog = prog;
	for (unsigned k = 0; k < count; k++) {
		if ((rc = bvhlab_cl_kernel(prog, names[k], &d->k[k], err, sizeof(err))) < 0) {
			host->set_error(ctx, "%s", err);
			cl_dev_close(d);
			return rc;
		}
		d->kernel_count = k + 1;
	}
	return 0;
}
