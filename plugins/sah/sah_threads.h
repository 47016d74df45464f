/*
 * What the SAH plugins share besides the split kernel: one build frame
 * around a scheduler (sah_seq's scheduler is sah_build_subtree on the calling
 * thread), and a subtree on a thread of its own. Threads come from the
 * thread layer (team.h), which pins them and gives them the stack the
 * kernel needs.
 *
 * The frame does the checks, resolves the options the plugin filled
 * (SAH_OPTIONS), ensures the output
 * capacity, sets the kernel up and tears it down, and hands the root job to
 * the scheduler, which
 * must have processed every job of the tree, with every thread it started
 * joined, when it returns. Joining is what makes the workers' writes
 * visible to the host: pthread_join synchronises with the thread's end.
 */
#ifndef BVHLAB_SAH_THREADS_H
#define BVHLAB_SAH_THREADS_H

#include <stdint.h>

#include <bvhlab/builder.h>

#include "sah_kernel.h"
#include "team.h"

/* Builds the tree below root with at most `threads` threads (>= 1), the
 * calling one included (worker 0), every thread started through th. 0
 * with every job done, or a negative errno after th->host->set_error
 * (called from the calling thread only). */
typedef int (*sah_scheduler_fn)(team_host *th, sah_builder *b, const sah_job *root,
                                uint32_t threads, void *arg);

/* The whole build() of a SAH plugin around `schedule`, with the options
 * as filled from SAH_OPTIONS and resolved (sah_options_resolve): 0, or a
 * negative errno after host->set_error. */
int sah_run_build(const bvhlab_host *host, bvhlab_build_ctx *ctx,
                  const bvhlab_build_input *input, bvhlab_build_output *output,
                  sah_options *opt, sah_scheduler_fn schedule, void *arg);

/*
 * build() and the entry point of a SAH plugin, at file scope after its
 * `options` (a plugin_option table holding SAH_OPTIONS or its groups) and
 * `schedule`: the options fill a `struct options_type`, whose first member
 * is `sah_options sah`, and the schedule gets that struct as its argument.
 */
/* Bytes per primitive a build adds at its peak (bvhlab_builder's
 * peak_bytes_per_prim), by method: measured (issue 44) 104-136 binned,
 * 172-232 with sweep's presorted arrays, on igea subdivided once and a
 * soup of 200,000. */
#define SAH_PEAK_BINNED 160
#define SAH_PEAK_SWEEP 256

#define SAH_PLUGIN(plugin_name, plugin_flags, plugin_summary, options_type)            \
	static int sah_check(const bvhlab_host *host, bvhlab_build_ctx *ctx, void *o)  \
	{                                                                              \
		return sah_options_resolve(host, ctx, &((options_type *)o)->sah);      \
	}                                                                              \
	PLUGIN_DECLS(options, options_type, sah_check)                                 \
	static int build(const bvhlab_host *host, bvhlab_build_ctx *ctx,               \
	                 const bvhlab_build_input *input, bvhlab_build_output *output) \
	{                                                                              \
		options_type o;                                                        \
		int rc = PLUGIN_OPTIONS_GET(host, ctx, input, &o);                     \
		return rc < 0 ? rc : sah_run_build(host, ctx, input, output, &o.sah,   \
		                                   schedule, &o);                      \
	}                                                                              \
	static uint32_t sah_peak_bytes(const void *o)                                  \
	{                                                                              \
		return ((const sah_options *)o)->method == SAH_BINNED ? SAH_PEAK_BINNED \
		                                                       : SAH_PEAK_SWEEP; \
	}                                                                              \
	PLUGIN_WITH_OPTIONS(options, .name = plugin_name, .flags = plugin_flags,       \
	                    .summary = plugin_summary, .build = build,                 \
	                    .peak_bytes_per_prim = SAH_PEAK_SWEEP,                     \
	                    .peak_bytes_for = sah_peak_bytes)

/* The option struct of a plugin with the shared options only. */
struct sah_plain_options {
	sah_options sah;
};

/* SAH_PLUGIN for a plugin with the shared options only (its schedule's
 * argument is then of no use to it). */
#define SAH_PLAIN_PLUGIN(plugin_name, plugin_flags, plugin_summary)                       \
	static const plugin_option options[] = { SAH_OPTIONS(struct sah_plain_options) }; \
	SAH_PLUGIN(plugin_name, plugin_flags, plugin_summary, struct sah_plain_options)

/* A job built whole by sah_build_subtree on a thread of its own. */
typedef struct sah_subtree_task {
	sah_builder *b;
	sah_job job;
	team_thread thread;
} sah_subtree_task;

/* Starts task on a new thread, or, when that fails, builds it right away on
 * the calling thread. Either way sah_subtree_join finishes it. */
void sah_subtree_spawn(team_host *th, sah_subtree_task *task);
void sah_subtree_join(sah_subtree_task *task);

static inline uint32_t sah_job_size(const sah_job *job)
{
	return job->end - job->begin;
}

/*
 * Threads worth starting for a root job: one per SAH_PRIMS_PER_THREAD
 * primitives at most. A thread costs its wake-up (the executor's pool),
 * and below this size the jobs are too few to keep more of them busy; a
 * config asking for 1024 threads on a small scene gets a few.
 */
#define SAH_PRIMS_PER_THREAD 4096u

static inline uint32_t sah_useful_threads(uint32_t threads, const sah_job *root)
{
	uint32_t useful = sah_job_size(root) / SAH_PRIMS_PER_THREAD + 1;
	return threads < useful ? threads : useful;
}

#endif /* BVHLAB_SAH_THREADS_H */
