/*
 * The executor's operations (core/exec) against sequential references, at
 * 1, 2, 3 and 7 threads over empty, short, uneven and long ranges:
 * for_each covers every index once with members below the thread count;
 * reduce, scan, partition (stable) and sort (stable, 30- and 64-bit keys,
 * values carried) give exactly the sequential result; a team's members
 * all run at once (they meet at a barrier of their own); spawned tasks
 * nest (a recursive fork-join sum) and many run at once; the pool is
 * reused (it never holds more workers than were ever busy at once); and a
 * child forked after the pool started runs teams of its own (isolate.c's
 * case: the child has none of the parent's threads). Then the same
 * operations through the host table (ABI 1.6) from inside a build, at 1,
 * 2 and 3 threads (pin_probe's expect=executor, exec_probe.c).
 */
#include <errno.h>
#include <stdlib.h>
#include <string.h>
#include <sys/wait.h>
#include <unistd.h>

#include <bvhlab/bvhlab.h>

#include "exec/exec.h"
#include "peer_threads.h"
#include "testutil.h"

#define FIXTURE_SEED 46
#include "scene_fixture.h"

static const uint32_t sizes[] = {0, 1, 4095, 5000, 100003};
static const uint32_t thread_counts[] = {1, 2, 3, 7};
#define LONGEST 100003

static struct exec_place place;

static uint64_t next_random(uint64_t *s)
{
	uint64_t z = (*s += 0x9e3779b97f4a7c15u);
	z = (z ^ (z >> 30)) * 0xbf58476d1ce4e5b9u;
	z = (z ^ (z >> 27)) * 0x94d049bb133111ebu;
	return z ^ (z >> 31);
}

/* ---- for_each ------------------------------------------------------------- */

struct cover {
	uint8_t *hits;
	uint32_t threads, grain;
	atomic_uint bad; /* ranges too long, or members out of range */
};

static void cover_range(void *arg, uint32_t lo, uint32_t hi, uint32_t member)
{
	struct cover *c = arg;
	if (member >= c->threads || (c->grain && hi - lo > c->grain) || lo >= hi)
		atomic_fetch_add(&c->bad, 1);
	for (uint32_t i = lo; i < hi; i++)
		c->hits[i]++; /* each index in one range only: no other writer */
}

static void test_for_each(uint32_t n, uint32_t threads)
{
	for (uint32_t grain = 0; grain <= 1000; grain += 1000) {
		struct cover c = {.hits = calloc(n + 1, 1), .threads = threads, .grain = grain};
		atomic_init(&c.bad, 0);
		CHECK_INT(exec_for_each(&place, threads, n, grain, cover_range, &c), 0);
		for (uint32_t i = 0; i < n; i++)
			CHECK_INT(c.hits[i], 1);
		CHECK_INT(atomic_load(&c.bad), 0);
		free(c.hits);
	}
}

/* ---- reduce -------------------------------------------------------------- */

struct stats {
	uint64_t sum;
	uint32_t min, max;
};

static void stats_range(void *arg, uint32_t lo, uint32_t hi, void *acc)
{
	const uint32_t *v = arg;
	struct stats *s = acc;
	for (uint32_t i = lo; i < hi; i++) {
		s->sum += v[i];
		s->min = v[i] < s->min ? v[i] : s->min;
		s->max = v[i] > s->max ? v[i] : s->max;
	}
}

static void stats_join(void *arg, void *acc, const void *part)
{
	(void)arg;
	struct stats *s = acc;
	const struct stats *p = part;
	s->sum += p->sum;
	s->min = p->min < s->min ? p->min : s->min;
	s->max = p->max > s->max ? p->max : s->max;
}

static void test_reduce(const uint32_t *v, uint32_t n, uint32_t threads)
{
	struct stats want = {0, UINT32_MAX, 0}, got = want;
	stats_range((void *)v, 0, n, &want);
	CHECK_INT(exec_reduce(&place, threads, n, &got, sizeof(got), stats_range, stats_join,
	                      (void *)v), 0);
	CHECK(got.sum == want.sum && got.min == want.min && got.max == want.max);
}

/* ---- scan and partition --------------------------------------------------- */

static bool is_odd(void *arg, uint32_t v)
{
	(void)arg;
	return v & 1;
}

static void test_scan(const uint32_t *v, uint32_t n, uint32_t threads)
{
	uint32_t *want = malloc((n + 1) * sizeof(*want)), *got = malloc((n + 1) * sizeof(*got));
	uint32_t run = 0, total = 7, kept = 7, k = 0;
	for (uint32_t i = 0; i < n; i++) {
		want[i] = run;
		run += v[i];
	}
	CHECK_INT(exec_scan(&place, threads, v, got, n, &total), 0);
	CHECK(total == run && memcmp(got, want, n * sizeof(*got)) == 0);
	memcpy(got, v, n * sizeof(*got)); /* in place */
	CHECK_INT(exec_scan(&place, threads, got, got, n, NULL), 0);
	CHECK(memcmp(got, want, n * sizeof(*got)) == 0);
	for (int pass = 0; pass < 2; pass++)
		for (uint32_t i = 0; i < n; i++)
			if (is_odd(NULL, v[i]) == (pass == 0))
				want[k++] = v[i];
	CHECK_INT(exec_partition(&place, threads, v, got, n, is_odd, NULL, &kept), 0);
	CHECK(memcmp(got, want, n * sizeof(*got)) == 0);
	k = 0;
	for (uint32_t i = 0; i < n; i++)
		k += v[i] & 1;
	CHECK_INT(kept, k);
	CHECK_INT(exec_partition(&place, threads, got, got, n ? n : 1, is_odd, NULL, &kept),
	          -EINVAL);
	free(want);
	free(got);
}

/* ---- sort ------------------------------------------------------------------ */

struct pair {
	uint64_t key;
	uint32_t value;
};

/* Stable by the value, which is the original position. */
static int by_key(const void *a, const void *b)
{
	const struct pair *x = a, *y = b;
	if (x->key != y->key)
		return x->key < y->key ? -1 : 1;
	return (x->value > y->value) - (x->value < y->value);
}

static void test_sort(uint32_t n, uint32_t threads, uint32_t bits)
{
	uint64_t *keys = malloc((n + 1) * sizeof(*keys)), s = n * 31u + bits;
	uint32_t *values = malloc((n + 1) * sizeof(*values));
	struct pair *want = malloc((n + 1) * sizeof(*want));
	uint64_t mask = bits == 64 ? UINT64_MAX : (1ull << bits) - 1;
	for (uint32_t i = 0; i < n; i++) {
		/* Few distinct keys in the short case: ties test stability. */
		keys[i] = next_random(&s) & (n < 5000 ? 15 : mask);
		values[i] = i;
		want[i] = (struct pair){keys[i], i};
	}
	qsort(want, n, sizeof(*want), by_key);
	CHECK_INT(exec_sort(&place, threads, keys, values, n, bits), 0);
	bool same = true;
	for (uint32_t i = 0; i < n; i++)
		same &= keys[i] == want[i].key && values[i] == want[i].value;
	CHECK(same);
	CHECK_INT(exec_sort(&place, threads, keys, NULL, n, 0), -EINVAL);
	free(keys);
	free(values);
	free(want);
}

/* ---- teams and tasks --------------------------------------------------------- */

struct meeting {
	atomic_uint arrived;
	atomic_uint seen[EXEC_MAX_MEMBERS];
	uint32_t members;
};

/* Every member waits for all: a team short of threads would never meet. */
static void meet(void *arg, uint32_t t)
{
	struct meeting *m = arg;
	atomic_fetch_add(&m->seen[t], 1);
	atomic_fetch_add(&m->arrived, 1);
	while (atomic_load(&m->arrived) < m->members)
		sched_yield();
}

static void test_team(uint32_t members)
{
	struct meeting m = {.members = members};
	CHECK_INT(exec_run(&place, members, meet, &m), 0);
	for (uint32_t t = 0; t < members; t++)
		CHECK_INT(atomic_load(&m.seen[t]), 1);
}

struct sum_task {
	const uint32_t *v;
	uint32_t lo, hi;
	uint64_t sum;
};

/* Fork-join: halves below 1024 values are summed here; the other half is
 * spawned, nested as deep as the range allows. */
static void sum_spawned(void *arg)
{
	struct sum_task *s = arg;
	if (s->hi - s->lo <= 1024) {
		for (uint32_t i = s->lo; i < s->hi; i++)
			s->sum += s->v[i];
		return;
	}
	uint32_t mid = s->lo + (s->hi - s->lo) / 2;
	struct sum_task left = {s->v, s->lo, mid, 0}, right = {s->v, mid, s->hi, 0};
	struct exec_task t;
	if (exec_spawn(&place, &t, sum_spawned, &right) < 0)
		sum_spawned(&right);
	sum_spawned(&left);
	exec_join(&t);
	s->sum = left.sum + right.sum;
}

static void test_spawn(const uint32_t *v, uint32_t n)
{
	struct sum_task all = {v, 0, n, 0};
	uint64_t want = 0;
	for (uint32_t i = 0; i < n; i++)
		want += v[i];
	sum_spawned(&all);
	CHECK(all.sum == want);
}

/* A forked child has no workers: it must start its own, not wait for
 * the parent's. (Not under TSan, which refuses threads after a fork.) */
static void test_fork(void)
{
	if (UNDER_TSAN)
		return;
	fflush(stdout);
	pid_t pid = fork();
	if (pid == 0) {
		struct meeting m = {.members = 2};
		_exit(exec_run(&place, 2, meet, &m) == 0 && atomic_load(&m.seen[1]) == 1 ? 0 : 1);
	}
	int status = -1;
	CHECK(pid > 0 && waitpid(pid, &status, 0) == pid);
	CHECK(WIFEXITED(status) && WEXITSTATUS(status) == 0);
}

/* The host table's executor, checked by the probe plugin from inside. */
static void test_host_table(void)
{
	bvhlab_scene *scene = generate("soup", 20000, 0, 0);
	bvhlab_plugin *p = NULL;
	bvhlab_options opts;
	bvhlab_prims prims;
	bvhlab_error err = { { 0 } };
	CHECK_INT(bvhlab_plugin_open(BVHLAB_TEST_BUILDDIR "/pin_probe.so", &p, &err), 0);
	CHECK_INT(bvhlab_prims_init(&prims, scene, &err), 0);
	CHECK_INT(bvhlab_options_init(&opts, bvhlab_plugin_builder(p)), 0);
	CHECK_INT(bvhlab_options_parse(&opts, "expect=executor", &err), 0);
	for (uint32_t threads = 1; threads <= 3; threads++) {
		bvhlab_tree tree = { 0 };
		int rc = bvhlab_build(p, &opts, &prims.input, threads, &tree, &err);
		if (rc < 0)
			fprintf(stderr, "%u threads: %s\n", threads, err.message);
		CHECK_INT(rc, 0);
		bvhlab_tree_finish(&tree);
	}
	bvhlab_options_finish(&opts);
	bvhlab_prims_finish(&prims);
	bvhlab_plugin_close(p);
	bvhlab_scene_destroy(scene);
}

int main(void)
{
	uint32_t *v = malloc(LONGEST * sizeof(*v));
	uint64_t s = 5;
	for (uint32_t i = 0; i < LONGEST; i++)
		v[i] = (uint32_t)next_random(&s);
	CHECK_INT(exec_place_begin(&place), 0);
	for (size_t t = 0; t < sizeof(thread_counts) / sizeof(*thread_counts); t++) {
		uint32_t threads = thread_counts[t];
		for (size_t k = 0; k < sizeof(sizes) / sizeof(*sizes); k++) {
			test_for_each(sizes[k], threads);
			test_reduce(v, sizes[k], threads);
			test_scan(v, sizes[k], threads);
			test_sort(sizes[k], threads, 30);
			test_sort(sizes[k], threads, 64);
		}
		test_team(threads);
	}
	/* The most busy at once so far: 6 workers beside the caller. */
	CHECK(atomic_load(&peer_tid_count) <= 6);
	unsigned before = atomic_load(&peer_tid_count);
	test_team(7);
	CHECK_INT(atomic_load(&peer_tid_count), before);
	test_spawn(v, LONGEST);
	test_fork();
	exec_place_end(&place);
	test_host_table();
	free(v);
	printf("executor: %u workers started in all\n", atomic_load(&peer_tid_count));
	return test_finish();
}
