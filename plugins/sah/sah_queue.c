/*
 * sah_queue: the thesis's node queue. `threads` workers (the calling
 * thread is one of them) take node jobs from one shared queue, split them
 * with the kernel and queue the children; below a cutoff the thread that
 * holds a job builds its subtree itself. Cutoff policies:
 *   "depth"    jobs deeper than `depth` are never queued: a job at depth
 *              `depth` is built whole by sah_build_subtree;
 *   "queue2t"  while the queue holds >= 2T jobs a worker recurses on its
 *              own, keeping pending children on a private deque; as soon
 *              as the queue drops below 2T it hands its largest pending
 *              child back to the queue ("push again when it drains");
 *   "auto"     depth below 500,000 primitives, queue2t from there (the
 *              thesis's rule).
 * Jobs under `min_job` primitives are never queued under any policy.
 *
 * Termination is exact: `outstanding` counts jobs queued and not yet
 * finished, under the queue's mutex. A job's children are queued before
 * the job itself is counted finished, so the count reaches 0 only once the
 * whole tree is built; then every worker is woken and leaves. Idle workers
 * sleep on the condition variable, never poll.
 */
#include <errno.h>
#include <stdatomic.h>
#include <stdlib.h>
#include <string.h>

#include <bvhlab/builder.h>

#include "sah_kernel.h"
#include "sah_threads.h"

#define AUTO_QUEUE_FROM 500000u

/* The choices of option policy, in order. */
enum policy { POLICY_QUEUE2T, POLICY_DEPTH, POLICY_AUTO };

/* The plugin's options ("auto" is decided by queue_init). */
struct queue_config {
	sah_options sah;
	int policy;
	uint32_t depth, min_job;
};

static const plugin_option options[] = {
	SAH_OPTIONS(struct queue_config),
	PLUGIN_OPTION(struct queue_config, policy, CHOICE, .name = "policy",
	              .help = "when to stop queueing: queue2t (queue below 2T jobs), depth, or "
	                      "auto (depth under 500K primitives, else queue2t)",
	              .def_string = "auto", .choices = "queue2t|depth|auto"),
	PLUGIN_OPTION(struct queue_config, depth, U32, .name = "depth",
	              .help = "policy depth: deepest queued node (root 0); deeper subtrees are "
	                      "built whole",
	              .def_int = 4, .min = 0, .max = 30),
	PLUGIN_OPTION(struct queue_config, min_job, U32, .name = "min_job",
	              .help = "jobs with fewer primitives are never queued, whatever the policy",
	              .def_int = 1024, .min = 1, .max = 1 << 30),
};

/* The shared queue: a max-heap by primitive count, so idle workers get
 * the biggest waiting job (the best bet for balance). */
struct queue {
	pthread_mutex_t lock;
	pthread_cond_t wake;
	sah_job *heap;
	uint32_t count, cap;
	uint32_t outstanding; /* queued or running jobs, under lock */
	atomic_uint waiting;  /* copy of count for queue2t's unlocked peeks */
	sah_builder *b;
	int policy;
	uint32_t depth, low_mark, min_job;
	team tm; /* the workers (its barrier goes unused) */
};

/* Private pending children of one queue2t worker. Entries shrink from lo
 * to hi (each lies inside the smaller sibling of the one below), so lo is
 * the largest and at most log2(N) + 1 entries exist: 64 is plenty. */
struct deque {
	sah_job job[64];
	unsigned lo, hi;
};

static int heap_push(struct queue *q, const sah_job *job)
{
	if (q->count == q->cap) {
		uint32_t cap = q->cap * 2;
		sah_job *heap = realloc(q->heap, cap * sizeof(*heap));
		if (!heap)
			return -ENOMEM;
		q->heap = heap;
		q->cap = cap;
	}
	uint32_t i = q->count++;
	for (; i > 0 && sah_job_size(&q->heap[(i - 1) / 2]) < sah_job_size(job); i = (i - 1) / 2)
		q->heap[i] = q->heap[(i - 1) / 2];
	q->heap[i] = *job;
	return 0;
}

static void heap_pop(struct queue *q, sah_job *out)
{
	sah_job last = q->heap[--q->count];
	uint32_t i = 0, c;

	*out = q->heap[0];
	while ((c = 2 * i + 1) < q->count) {
		if (c + 1 < q->count && sah_job_size(&q->heap[c + 1]) > sah_job_size(&q->heap[c]))
			c++;
		if (sah_job_size(&q->heap[c]) <= sah_job_size(&last))
			break;
		q->heap[i] = q->heap[c];
		i = c;
	}
	q->heap[i] = last;
}

/* Queues a job; false when the queue cannot grow (the caller keeps it). */
static bool queue_push(struct queue *q, const sah_job *job)
{
	pthread_mutex_lock(&q->lock);
	bool ok = heap_push(q, job) == 0;
	if (ok) {
		q->outstanding++;
		atomic_store_explicit(&q->waiting, q->count, memory_order_relaxed);
		pthread_cond_signal(&q->wake);
	}
	pthread_mutex_unlock(&q->lock);
	return ok;
}

/* Waits for a job; false once every job is finished. */
static bool queue_take(struct queue *q, sah_job *job)
{
	pthread_mutex_lock(&q->lock);
	while (q->count == 0 && q->outstanding > 0)
		pthread_cond_wait(&q->wake, &q->lock);
	bool got = q->count > 0;
	if (got) {
		heap_pop(q, job);
		atomic_store_explicit(&q->waiting, q->count, memory_order_relaxed);
	}
	pthread_mutex_unlock(&q->lock);
	return got;
}

static void queue_done(struct queue *q)
{
	pthread_mutex_lock(&q->lock);
	if (--q->outstanding == 0)
		pthread_cond_broadcast(&q->wake);
	pthread_mutex_unlock(&q->lock);
}

static void run_depth(struct queue *q, const sah_job *job)
{
	sah_job child[2];

	if (job->depth >= q->depth || sah_job_size(job) < q->min_job) {
		sah_build_subtree(q->b, job);
		return;
	}
	if (sah_split_job(q->b, job, child) == 0)
		return;
	for (int i = 0; i < 2; i++)
		if (sah_job_size(&child[i]) < q->min_job || !queue_push(q, &child[i]))
			sah_build_subtree(q->b, &child[i]);
}

/* Hands the largest pending children to the queue while it is short. A
 * stale count only shifts a hand-over by a split: it never affects the tree. */
static void donate(struct queue *q, struct deque *d)
{
	while (d->lo < d->hi && sah_job_size(&d->job[d->lo]) >= q->min_job &&
	       atomic_load_explicit(&q->waiting, memory_order_relaxed) < q->low_mark) {
		if (!queue_push(q, &d->job[d->lo]))
			break;
		d->lo++;
	}
	if (d->lo == d->hi)
		d->lo = d->hi = 0;
}

static void run_queue2t(struct queue *q, const sah_job *job)
{
	struct deque d = { .lo = 0, .hi = 0 };
	sah_job cur = *job, child[2];

	for (;;) {
		if (sah_job_size(&cur) < q->min_job) {
			sah_build_subtree(q->b, &cur);
		} else if (sah_split_job(q->b, &cur, child) == 2) {
			unsigned big = sah_job_size(&child[1]) > sah_job_size(&child[0]);
			d.job[d.hi++] = child[big];
			cur = child[1 - big];
			donate(q, &d);
			continue;
		}
		if (d.lo == d.hi)
			return;
		cur = d.job[--d.hi];
		if (d.lo == d.hi)
			d.lo = d.hi = 0;
	}
}

/* Every member of the team, the calling thread too (pinned by the layer). */
static void worker(void *arg, unsigned t)
{
	struct queue *q = arg;
	sah_job job;

	(void)t;
	while (queue_take(q, &job)) {
		if (q->policy == POLICY_DEPTH)
			run_depth(q, &job);
		else
			run_queue2t(q, &job);
		queue_done(q);
	}
}

static int queue_init(struct queue *q, sah_builder *b, uint32_t threads,
                      const struct queue_config *cfg)
{
	memset(q, 0, sizeof(*q));
	q->cap = 64;
	q->heap = malloc(q->cap * sizeof(*q->heap));
	if (!q->heap)
		return -ENOMEM;
	int rc = pthread_mutex_init(&q->lock, NULL);
	if (rc == 0 && (rc = pthread_cond_init(&q->wake, NULL)) != 0)
		pthread_mutex_destroy(&q->lock);
	if (rc != 0) {
		free(q->heap);
		return -rc;
	}
	atomic_init(&q->waiting, 0);
	q->b = b;
	q->policy = cfg->policy != POLICY_AUTO ? cfg->policy
	            : b->prim_count < AUTO_QUEUE_FROM ? POLICY_DEPTH : POLICY_QUEUE2T;
	q->depth = cfg->depth;
	q->min_job = cfg->min_job;
	q->low_mark = threads > UINT32_MAX / 2 ? UINT32_MAX : 2 * threads;
	return 0;
}

static void queue_destroy(struct queue *q)
{
	pthread_cond_destroy(&q->wake);
	pthread_mutex_destroy(&q->lock);
	free(q->heap);
}

/* The calling thread works too; a worker that fails to start only means
 * fewer hands on the same queue. */
static int schedule(team_host *th, sah_builder *b, const sah_job *root, uint32_t asked,
                    void *arg)
{
	/* no more OS threads than the scene has work for */
	uint32_t threads = sah_useful_threads(asked, root);
	struct queue q;
	int rc = queue_init(&q, b, threads, arg);

	if (rc < 0) {
		th->host->set_error(th->ctx, "cannot set up the job queue (%d)", rc);
		return rc;
	}
	/* The first push cannot fail: the heap starts with room. */
	queue_push(&q, root);
	rc = team_run_on(&q.tm, th, threads, worker, &q);
	/* Without a barrier no worker started: the calling thread does it all. */
	if (rc < 0)
		worker(&q, 0);
	queue_destroy(&q);
	return 0;
}

SAH_PLUGIN("sah_queue", BVHLAB_BUILDER_PARALLEL | BVHLAB_BUILDER_DETERMINISTIC,
	"parallel SAH, thesis node queue: workers share a job queue, exact termination",
	struct queue_config)
