/*
 * pin_probe: a test plugin that checks host->pin_thread from the inside.
 * Its workers pin themselves and look at where they landed; any surprise
 * fails the build with a message. The tree is one leaf of everything.
 *
 * Option expect (string): "pinned" (each worker bound to one CPU, distinct
 * CPUs for distinct cores) or "free" (pin_thread is a no-op); or
 * "executor": the host table's executor checked instead (exec_probe.c).
 */
#include <errno.h>
#include <pthread.h>
#include <sched.h>
#include <string.h>

#include <bvhlab/builder.h>

#include "exec_probe.h"

#define MAX_WORKERS 64

struct worker {
	const bvhlab_host *host;
	bvhlab_build_ctx *ctx;
	uint32_t id;
	int rc;
	int cpus_before, cpus_after; /* CPUs in the worker's mask */
	int bound_cpu;               /* the mask's only CPU when it has one */
	int running_on;              /* sched_getcpu() after pinning */
};

static int mask_cpus(int *first)
{
	cpu_set_t set;
	if (pthread_getaffinity_np(pthread_self(), sizeof(set), &set) != 0)
		return -1;
	*first = -1;
	for (int i = 0; i < CPU_SETSIZE && *first < 0; i++)
		if (CPU_ISSET(i, &set))
			*first = i;
	return CPU_COUNT(&set);
}

static void *work(void *arg)
{
	struct worker *w = arg;
	int first;
	w->cpus_before = mask_cpus(&first);
	w->rc = w->host->pin_thread(w->ctx, w->id);
	w->cpus_after = mask_cpus(&w->bound_cpu);
	w->running_on = sched_getcpu();
	return NULL;
}

static int check_pinned(const bvhlab_host *host, bvhlab_build_ctx *ctx, struct worker *w,
                        uint32_t n, uint32_t cores)
{
	for (uint32_t k = 0; k < n; k++) {
		if (w[k].rc != 0 || w[k].cpus_after != 1 || w[k].running_on != w[k].bound_cpu) {
			host->set_error(ctx, "worker %u: rc %d, %d CPUs in its mask, on CPU %d "
			                "(bound to %d)", k, w[k].rc, w[k].cpus_after,
			                w[k].running_on, w[k].bound_cpu);
			return -EIO;
		}
		for (uint32_t j = 0; j < k; j++)
			if (k < cores && w[j].bound_cpu == w[k].bound_cpu) {
				host->set_error(ctx, "workers %u and %u share CPU %d", j, k,
				                w[k].bound_cpu);
				return -EIO;
			}
	}
	return 0;
}

static int check_free(const bvhlab_host *host, bvhlab_build_ctx *ctx, struct worker *w,
                      uint32_t n)
{
	for (uint32_t k = 0; k < n; k++)
		if (w[k].rc != 0 || w[k].cpus_after != w[k].cpus_before) {
			host->set_error(ctx, "worker %u: pinning off, yet rc %d and %d -> %d CPUs",
			                k, w[k].rc, w[k].cpus_before, w[k].cpus_after);
			return -EIO;
		}
	return 0;
}

/* Worker 0 is the calling thread, as in most builders: the host must
 * restore its mask afterwards. */
static int run_workers(const bvhlab_host *host, bvhlab_build_ctx *ctx, struct worker *w,
                       uint32_t n)
{
	pthread_t tid[MAX_WORKERS];
	uint32_t started = 1;
	int rc = 0;
	for (uint32_t k = 0; k < n; k++)
		w[k] = (struct worker){.host = host, .ctx = ctx, .id = k};
	work(&w[0]);
	for (; started < n; started++)
		if (pthread_create(&tid[started], NULL, work, &w[started]) != 0) {
			host->set_error(ctx, "cannot start worker %u", started);
			rc = -EAGAIN;
			break;
		}
	for (uint32_t k = 1; k < started; k++)
		pthread_join(tid[k], NULL);
	return rc;
}

static void one_leaf(const bvhlab_build_input *in, bvhlab_build_output *out)
{
	bvhlab_node *root = &out->nodes[0];
	memcpy(root->lo, in->bounds.lo, sizeof(root->lo));
	memcpy(root->hi, in->bounds.hi, sizeof(root->hi));
	root->first = 0;
	root->count = in->prim_count;
	for (uint32_t i = 0; i < in->prim_count; i++)
		out->prim_index[i] = i;
	out->node_count = 1;
	out->index_count = in->prim_count;
}

static int build(const bvhlab_host *host, bvhlab_build_ctx *ctx,
                 const bvhlab_build_input *input, bvhlab_build_output *output)
{
	struct worker w[MAX_WORKERS];
	const char *expect;
	uint32_t n = input->threads < MAX_WORKERS ? input->threads : MAX_WORKERS;
	int rc;

	if (!BVHLAB_HOST_HAS(host, pin_thread)) {
		host->set_error(ctx, "host of ABI %u.%u has no pin_thread",
		                BVHLAB_ABI_VERSION_MAJOR(host->abi_version),
		                BVHLAB_ABI_VERSION_MINOR(host->abi_version));
		return -ENOTSUP;
	}
	if ((rc = host->option_string(ctx, "expect", &expect)) < 0)
		return rc;
	if (strcmp(expect, "executor") == 0)
		rc = exec_probe(host, ctx, input);
	else if ((rc = run_workers(host, ctx, w, n)) < 0)
		return rc;
	else
		rc = strcmp(expect, "pinned") == 0
		? check_pinned(host, ctx, w, n, host->hardware_threads(ctx))
		: check_free(host, ctx, w, n);
	if (rc == 0)
		one_leaf(input, output);
	return rc;
}

static const bvhlab_option_decl options[] = {
	{.name = "expect", .type = BVHLAB_OPTION_STRING, .help = "pinned, free or executor",
	 .def_string = "free", .choices = "pinned|free|executor"},
};

BVHLAB_PLUGIN(.name = "pin_probe", .flags = BVHLAB_BUILDER_PARALLEL,
	.summary = "test plugin: checks host->pin_thread from its workers",
	.option_count = 1, .options = options, .build = build)
