/* The Morton builders' shared front end (see morton_front.h). */
#include <errno.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <time.h>

#include "big_alloc.h"
#include "morton_front.h"
#include "plugin_options.h"

/* Below this many primitives per thread, more threads cost more than they
 * save (thread start and barriers are tens of microseconds). */
#define MIN_PRIMS_PER_THREAD 512

double morton_now_ms(void)
{
	struct timespec ts;

	clock_gettime(CLOCK_MONOTONIC, &ts);
	return ts.tv_sec * 1e3 + ts.tv_nsec / 1e6;
}

unsigned morton_team_size(const bvhlab_build_input *in)
{
	uint32_t most = in->prim_count / MIN_PRIMS_PER_THREAD;
	uint32_t want = in->threads < most ? in->threads : most;

	return want < 1 ? 1 : want > TEAM_MAX_THREADS ? TEAM_MAX_THREADS : want;
}

void morton_place_sort(morton_sort *s, char *at)
{
	size_t k8 = morton_align64(8 * (size_t)s->n);

	s->codes = (uint64_t *)(void *)at;
	s->keys[0] = (uint64_t *)(void *)(at + k8);
	s->keys[1] = (uint64_t *)(void *)(at + 2 * k8);
}

uint32_t *morton_scratch_alloc(morton_scratch *scratch, size_t region, morton_sort *sort,
                               unsigned threads, unsigned extra)
{
	size_t hist = (size_t)threads * MORTON_TOP_RADIX * sizeof(uint32_t) +
	              (MORTON_TOP_RADIX + 1) * sizeof(uint32_t);

	/* Zero-filled, which lbvh's arrival counters rely on when they live
	 * here; the threads touch it first, each its own chunk, sharing the
	 * faults. */
	scratch->region = region ? big_alloc(region) : NULL;
	scratch->small = malloc(hist + (size_t)threads * extra * sizeof(uint32_t));
	if ((region && !scratch->region) || !scratch->small)
		return NULL;
	sort->hist = scratch->small;
	sort->bucket = (uint32_t *)(void *)(sort->hist + threads);
	return sort->bucket + MORTON_TOP_RADIX + 1;
}

void morton_scratch_free(morton_scratch *scratch)
{
	big_free(scratch->region);
	free(scratch->small);
}

char *morton_scratch_place(morton_scratch *scratch, const bvhlab_build_output *out, uint32_t n,
                           size_t work, uint32_t spare, morton_sort *sort, unsigned threads,
                           unsigned extra, uint32_t **counts, bool *work_in_output)
{
	uint32_t nodes = 2 * n - 1;
	size_t sort_bytes = morton_sort_bytes(n);
	bool sort_out = (size_t)nodes * sizeof(bvhlab_node) >= sort_bytes;
	bool work_out = spare && out->node_capacity >= nodes + spare;
	uintptr_t past = (uintptr_t)(out->nodes + nodes);
	size_t region = (work_out ? 0 : work) + (sort_out ? 0 : sort_bytes);

	if (work_in_output)
		*work_in_output = work_out;
	if (!(*counts = morton_scratch_alloc(scratch, region, sort, threads, extra)))
		return NULL;
	morton_place_sort(sort, sort_out ? (char *)out->nodes
	                                 : (char *)scratch->region + (work_out ? 0 : work));
	return work_out ? (char *)((past + 63) & ~(uintptr_t)63) : (char *)scratch->region;
}

void morton_sort_team(morton_sort *s, team *tm, unsigned t,
                      void (*done)(void *arg, uint32_t first, uint32_t end), void *arg)
{
	/* Only member 0 sets the packing; the others read it after the
	 * barriers below. */
	if (t == 0)
		morton_sort_init(s);
	morton_codes(s, tm->threads, t);
	team_sync(tm);
	morton_scatter(s, tm->threads, t);
	team_sync(tm);
	morton_sort_buckets(s, done, arg);
	team_sync(tm);
}

void morton_single_leaf(const bvhlab_build_input *in, bvhlab_build_output *out)
{
	bvhlab_node *root = &out->nodes[0];

	for (int k = 0; k < 3; k++) {
		root->lo[k] = in->prim_bounds[0].lo[k];
		root->hi[k] = in->prim_bounds[0].hi[k];
	}
	root->first = 0;
	root->count = 1;
	out->prim_index[0] = 0;
	out->node_count = 1;
	out->index_count = 1;
}

/* The debug line: the phase times of j's team, started at `start` (ms). */
static void log_phases(const morton_job *j, const bvhlab_host *host, bvhlab_build_ctx *ctx,
                       uint32_t n, double start)
{
	char line[256];
	size_t at = 0;

	at += (size_t)snprintf(line, sizeof(line), "%u prims, %u threads", n, j->team->threads);
	if (j->count && at < sizeof(line))
		at += (size_t)snprintf(line + at, sizeof(line) - at, ", %u %s", *j->count,
		                       j->count_name);
	if (at < sizeof(line))
		at += (size_t)snprintf(line + at, sizeof(line) - at, ": setup %.2f, sort %.2f",
		                       j->ms[0] - start, j->ms[1] - j->ms[0]);
	for (size_t k = 0; j->phases[k].run && at < sizeof(line); k++)
		at += (size_t)snprintf(line + at, sizeof(line) - at, ", %s %.2f", j->phases[k].name,
		                       j->ms[k + 2] - j->ms[k + 1]);
	host->log(ctx, BVHLAB_LOG_DEBUG, "%s ms", line);
}

/* By every member t of the team: the sort and the job's phases, member 0
 * taking the times. */
static void run_phases(void *arg, unsigned t)
{
	const morton_job *j = arg;

	if (t == 0)
		j->ms[0] = morton_now_ms();
	morton_sort_team(j->sort, j->team, t, j->bucket_done, j->b);
	if (j->sorted)
		j->sorted(j->b, t);
	team_sync(j->team);
	if (t == 0)
		j->ms[1] = morton_now_ms();
	for (size_t k = 0; j->phases[k].run; k++) {
		j->phases[k].run(j->b, t);
		if (t == 0)
			j->ms[k + 2] = morton_now_ms();
	}
}

/* The team over the phases, with the sort's input and the scratch set. */
static int run_team(const morton_job *j, const bvhlab_host *host, bvhlab_build_ctx *ctx,
                    const bvhlab_build_input *in, bvhlab_build_output *out)
{
	morton_scratch s = { 0 };
	double start = morton_now_ms();
	team_host th;
	int rc;

	*j->threads = morton_team_size(in);
	j->sort->n = in->prim_count;
	j->sort->centroids = in->centroids;
	j->sort->centroid_bounds = in->centroid_bounds;
	team_host_init(&th, host, ctx);
	if (j->th)
		*j->th = &th;
	if ((rc = j->place(j->b, out, &s)) < 0) {
		host->set_error(ctx, "out of memory for the scratch of %u primitives",
		                in->prim_count);
		goto out;
	}
	if ((rc = team_run_on(j->team, &th, *j->threads, run_phases, (void *)j)) < 0) {
		host->set_error(ctx, "cannot set up the thread team");
		goto out;
	}
	if (j->finish && (rc = j->finish(j->b, host, ctx)) < 0)
		goto out;
	out->node_count = *j->node_count;
	out->index_count = in->prim_count;
	log_phases(j, host, ctx, in->prim_count, start);
out:
	if (j->cleanup)
		j->cleanup(j->b);
	morton_scratch_free(&s);
	return rc;
}

int morton_build(const morton_job *j, const bvhlab_host *host, bvhlab_build_ctx *ctx,
                 const bvhlab_build_input *in, bvhlab_build_output *out)
{
	uint32_t n = in->prim_count;
	int rc;

	if (n == 0 || n > j->max_prims) {
		host->set_error(ctx, "cannot build over %u primitives", n);
		return -EINVAL;
	}
	if ((rc = big_ensure_output(host, ctx, n, j->spare, out)) < 0)
		return rc;
	if (n == 1) {
		morton_single_leaf(in, out);
		return 0;
	}
	return run_team(j, host, ctx, in, out);
}
