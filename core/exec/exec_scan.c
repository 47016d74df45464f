/*
 * The executor's scans (see exec.h): prefix sums, stable partition and
 * the radix sort, each in two steps over fixed shares of the range: every
 * share counts, the caller turns the counts into offsets in share order,
 * every share writes from its offsets. Shares and offsets depend on the
 * range only, so the output is the same for every thread count.
 */
#include <errno.h>
#include <stdlib.h>
#include <string.h>

#include "exec/exec.h"

struct scan_job {
	const uint32_t *in;
	uint32_t *out;
	uint32_t count, shares;
	bool (*pred)(void *arg, uint32_t v);
	void *arg;
	uint32_t first[EXEC_MAX_MEMBERS]; /* per share: its count, then its offset */
	uint32_t other[EXEC_MAX_MEMBERS]; /* partition: where its rejects go */
	const uint64_t *keys;             /* sort: this pass's input ... */
	const uint32_t *values;
	uint64_t *keys_out;               /* ... and output */
	uint32_t *values_out;
	uint32_t shift;
	uint32_t *hist;                   /* sort: [shares][256] */
};

static void run_shares(const struct exec_place *p, struct scan_job *j,
                       void (*fn)(void *arg, uint32_t lo, uint32_t hi, uint32_t member))
{
	exec_for_each(p, j->shares, j->shares, 1, fn, j);
}

/* Turns per-share counts into exclusive offsets; returns the total. */
static uint32_t offsets(uint32_t *v, uint32_t n, uint32_t start)
{
	for (uint32_t k = 0; k < n; k++) {
		uint32_t c = v[k];
		v[k] = start;
		start += c;
	}
	return start;
}

/* ---- scan ---------------------------------------------------------------- */

static void sum_share(void *arg, uint32_t a, uint32_t b, uint32_t member)
{
	struct scan_job *j = arg;
	(void)member;
	for (uint32_t k = a; k < b; k++) {
		uint32_t lo, hi, sum = 0;
		exec_share(j->count, j->shares, k, &lo, &hi);
		for (uint32_t i = lo; i < hi; i++)
			sum += j->in[i];
		j->first[k] = sum;
	}
}

static void write_sums(void *arg, uint32_t a, uint32_t b, uint32_t member)
{
	struct scan_job *j = arg;
	(void)member;
	for (uint32_t k = a; k < b; k++) {
		uint32_t lo, hi, run = j->first[k];
		exec_share(j->count, j->shares, k, &lo, &hi);
		for (uint32_t i = lo; i < hi; i++) {
			uint32_t v = j->in[i]; /* read first: out may be in */
			j->out[i] = run;
			run += v;
		}
	}
}

int exec_scan(const struct exec_place *p, uint32_t threads, const uint32_t *in, uint32_t *out,
              uint32_t count, uint32_t *total)
{
	struct scan_job *j = malloc(sizeof(*j));
	if (!j)
		return -ENOMEM;
	*j = (struct scan_job){.in = in, .out = out, .count = count,
	                       .shares = exec_shares(threads, count)};
	run_shares(p, j, sum_share);
	uint32_t sum = offsets(j->first, j->shares, 0);
	run_shares(p, j, write_sums);
	if (total)
		*total = sum;
	free(j);
	return 0;
}

/* ---- partition ----------------------------------------------------------- */

static void count_kept(void *arg, uint32_t a, uint32_t b, uint32_t member)
{
	struct scan_job *j = arg;
	(void)member;
	for (uint32_t k = a; k < b; k++) {
		uint32_t lo, hi, kept = 0;
		exec_share(j->count, j->shares, k, &lo, &hi);
		for (uint32_t i = lo; i < hi; i++)
			kept += j->pred(j->arg, j->in[i]);
		j->first[k] = kept;
		j->other[k] = hi - lo - kept;
	}
}

static void scatter_kept(void *arg, uint32_t a, uint32_t b, uint32_t member)
{
	struct scan_job *j = arg;
	(void)member;
	for (uint32_t k = a; k < b; k++) {
		uint32_t lo, hi, yes = j->first[k], no = j->other[k];
		exec_share(j->count, j->shares, k, &lo, &hi);
		for (uint32_t i = lo; i < hi; i++)
			j->out[j->pred(j->arg, j->in[i]) ? yes++ : no++] = j->in[i];
	}
}

int exec_partition(const struct exec_place *p, uint32_t threads, const uint32_t *in,
                   uint32_t *out, uint32_t count, bool (*pred)(void *arg, uint32_t v),
                   void *arg, uint32_t *kept)
{
	if (count > 0 && (in == out || !pred))
		return -EINVAL;
	struct scan_job *j = malloc(sizeof(*j));
	if (!j)
		return -ENOMEM;
	*j = (struct scan_job){.in = in, .out = out, .count = count, .pred = pred, .arg = arg,
	                       .shares = exec_shares(threads, count)};
	run_shares(p, j, count_kept);
	uint32_t yes = offsets(j->first, j->shares, 0);
	offsets(j->other, j->shares, yes);
	run_shares(p, j, scatter_kept);
	if (kept)
		*kept = yes;
	free(j);
	return 0;
}

/* ---- sort: least significant digit first, 8 bits a pass ------------------ */

static void histogram(void *arg, uint32_t a, uint32_t b, uint32_t member)
{
	struct scan_job *j = arg;
	(void)member;
	for (uint32_t k = a; k < b; k++) {
		uint32_t lo, hi, *h = j->hist + (size_t)k * 256;
		exec_share(j->count, j->shares, k, &lo, &hi);
		memset(h, 0, 256 * sizeof(*h));
		for (uint32_t i = lo; i < hi; i++)
			h[(j->keys[i] >> j->shift) & 255]++;
	}
}

static void scatter_keys(void *arg, uint32_t a, uint32_t b, uint32_t member)
{
	struct scan_job *j = arg;
	(void)member;
	for (uint32_t k = a; k < b; k++) {
		uint32_t lo, hi, *h = j->hist + (size_t)k * 256;
		exec_share(j->count, j->shares, k, &lo, &hi);
		for (uint32_t i = lo; i < hi; i++) {
			uint32_t to = h[(j->keys[i] >> j->shift) & 255]++;
			j->keys_out[to] = j->keys[i];
			if (j->values)
				j->values_out[to] = j->values[i];
		}
	}
}

/* Offsets of every (digit, share) in digit-major order; false when one
 * digit holds every key (the pass would move nothing). */
static bool digit_offsets(struct scan_job *j)
{
	uint32_t run = 0;
	for (uint32_t d = 0; d < 256; d++) {
		uint32_t before = run;
		for (uint32_t k = 0; k < j->shares; k++) {
			uint32_t c = j->hist[(size_t)k * 256 + d];
			j->hist[(size_t)k * 256 + d] = run;
			run += c;
		}
		if (run - before == j->count)
			return false;
	}
	return true;
}

/* One pass from (keys, values) into the scratch or back; true when it moved. */
static bool sort_pass(const struct exec_place *p, struct scan_job *j)
{
	run_shares(p, j, histogram);
	if (!digit_offsets(j))
		return false;
	run_shares(p, j, scatter_keys);
	return true;
}

int exec_sort(const struct exec_place *p, uint32_t threads, uint64_t *keys, uint32_t *values,
              uint32_t count, uint32_t key_bits)
{
	if (key_bits < 1 || key_bits > 64)
		return -EINVAL;
	if (count < 2)
		return 0;
	struct scan_job *j = malloc(sizeof(*j));
	uint32_t shares = exec_shares(threads, count);
	void *scratch = malloc((size_t)count * (sizeof(uint64_t) + sizeof(uint32_t)) +
	                       (size_t)shares * 256 * sizeof(uint32_t));
	if (!j || !scratch) {
		free(j);
		free(scratch);
		return -ENOMEM;
	}
	uint64_t *keys2 = scratch;
	uint32_t *values2 = (uint32_t *)(keys2 + count);
	*j = (struct scan_job){.count = count, .shares = shares, .hist = values2 + count,
	                       .keys = keys, .values = values, .keys_out = keys2,
	                       .values_out = values ? values2 : NULL};
	for (j->shift = 0; j->shift < key_bits; j->shift += 8) {
		if (!sort_pass(p, j))
			continue;
		uint64_t *k = j->keys_out;
		uint32_t *v = j->values_out;
		j->keys_out = (uint64_t *)j->keys;
		j->values_out = (uint32_t *)j->values;
		j->keys = k;
		j->values = v;
	}
	if (j->keys != keys) {
		memcpy(keys, j->keys, (size_t)count * sizeof(*keys));
		if (values)
			memcpy(values, j->values, (size_t)count * sizeof(*values));
	}
	free(scratch);
	free(j);
	return 0;
}
