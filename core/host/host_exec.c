/*
 * The executor in the host table (ABI 1.6): each entry is the core
 * executor's operation on the build's place (the CPU set and pin plan the
 * call into the plugin began with) at the build's thread count.
 */
#include <errno.h>

#include "host/build_ctx.h"

/* A plugin's task storage holds the executor's task record. */
_Static_assert(sizeof(struct exec_task) <= sizeof(bvhlab_task),
               "bvhlab_task is too small for struct exec_task");
_Static_assert(_Alignof(struct exec_task) <= _Alignof(bvhlab_task),
               "bvhlab_task is aligned less than struct exec_task");

int host_exec_run(bvhlab_build_ctx *ctx, uint32_t members,
                  void (*fn)(void *arg, uint32_t member), void *arg)
{
	return exec_run(&ctx->place, members, fn, arg);
}

int host_exec_for_each(bvhlab_build_ctx *ctx, uint32_t count, uint32_t grain,
                       void (*fn)(void *arg, uint32_t lo, uint32_t hi, uint32_t member),
                       void *arg)
{
	return exec_for_each(&ctx->place, ctx->threads, count, grain, fn, arg);
}

int host_exec_reduce(bvhlab_build_ctx *ctx, uint32_t count, void *acc, size_t size,
                     void (*fn)(void *arg, uint32_t lo, uint32_t hi, void *acc),
                     void (*join)(void *arg, void *acc, const void *part), void *arg)
{
	return exec_reduce(&ctx->place, ctx->threads, count, acc, size, fn, join, arg);
}

int host_exec_scan(bvhlab_build_ctx *ctx, const uint32_t *in, uint32_t *out, uint32_t count,
                   uint32_t *total)
{
	return exec_scan(&ctx->place, ctx->threads, in, out, count, total);
}

int host_exec_partition(bvhlab_build_ctx *ctx, const uint32_t *in, uint32_t *out,
                        uint32_t count, bool (*pred)(void *arg, uint32_t value), void *arg,
                        uint32_t *kept)
{
	return exec_partition(&ctx->place, ctx->threads, in, out, count, pred, arg, kept);
}

int host_exec_sort(bvhlab_build_ctx *ctx, uint64_t *keys, uint32_t *values, uint32_t count,
                   uint32_t key_bits)
{
	return exec_sort(&ctx->place, ctx->threads, keys, values, count, key_bits);
}

int host_exec_spawn(bvhlab_build_ctx *ctx, bvhlab_task *task, void (*fn)(void *arg),
                    void *arg)
{
	return exec_spawn(&ctx->place, (struct exec_task *)task, fn, arg);
}

void host_exec_join(bvhlab_build_ctx *ctx, bvhlab_task *task)
{
	(void)ctx;
	exec_join((struct exec_task *)task);
}
