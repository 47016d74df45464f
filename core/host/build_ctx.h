/*
 * The context of one call into a plugin (build.c), and the executor's
 * entries of the host table (host_exec.c, ABI 1.6), which run on its place.
 */
#ifndef BVHLAB_CORE_HOST_BUILD_CTX_H
#define BVHLAB_CORE_HOST_BUILD_CTX_H

#include <bvhlab/builder.h>
#include <bvhlab/host.h>

#include "exec/exec.h"
#include "util/util.h"

struct bvhlab_build_ctx {
	const bvhlab_builder *builder;
	const bvhlab_options *opts;
	bvhlab_tree *tree;
	bvhlab_error *err;
	bool error_set;
	char bad_phase[192];     /* the first phase report refused and why, or "" */
	uint32_t threads;        /* input->threads: the executor's operations' width */
	struct exec_place place; /* the caller's CPU set and pin plan */
};

int host_exec_run(bvhlab_build_ctx *ctx, uint32_t members,
                  void (*fn)(void *arg, uint32_t member), void *arg);
int host_exec_for_each(bvhlab_build_ctx *ctx, uint32_t count, uint32_t grain,
                       void (*fn)(void *arg, uint32_t lo, uint32_t hi, uint32_t member),
                       void *arg);
int host_exec_reduce(bvhlab_build_ctx *ctx, uint32_t count, void *acc, size_t size,
                     void (*fn)(void *arg, uint32_t lo, uint32_t hi, void *acc),
                     void (*join)(void *arg, void *acc, const void *part), void *arg);
int host_exec_scan(bvhlab_build_ctx *ctx, const uint32_t *in, uint32_t *out, uint32_t count,
                   uint32_t *total);
int host_exec_partition(bvhlab_build_ctx *ctx, const uint32_t *in, uint32_t *out,
                        uint32_t count, bool (*pred)(void *arg, uint32_t value), void *arg,
                        uint32_t *kept);
int host_exec_sort(bvhlab_build_ctx *ctx, uint64_t *keys, uint32_t *values, uint32_t count,
                   uint32_t key_bits);
int host_exec_spawn(bvhlab_build_ctx *ctx, bvhlab_task *task, void (*fn)(void *arg),
                    void *arg);
void host_exec_join(bvhlab_build_ctx *ctx, bvhlab_task *task);

#endif
