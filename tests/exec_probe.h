/* pin_probe's "executor" mode (exec_probe.c). */
#ifndef BVHLAB_TEST_EXEC_PROBE_H
#define BVHLAB_TEST_EXEC_PROBE_H

#include <bvhlab/builder.h>

/* 0, or -EIO after host->set_error naming the operation that differed. */
int exec_probe(const bvhlab_host *host, bvhlab_build_ctx *ctx, const bvhlab_build_input *in);

#endif
