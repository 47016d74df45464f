/*
 * The runs of a results document grouped by scene, its machines numbered,
 * and each scene x builder x machine's 1-thread median and most threads,
 * built in one pass. Reports are rendered after
 * every run of a sweep; looking runs up by scanning all of them for every
 * scene and every speedup made each rendering quadratic in the run count
 * (an 8-run sweep resumed over 8,000 kept runs took 50 s).
 */
#include <errno.h>
#include <math.h>
#include <stdint.h>
#include <stdlib.h>
#include <string.h>

#include "output/report.h"

/* One slot of the open-addressed table: a scene, or a scene x builder x
 * machine (a merged sweep's speedups compare runs of one machine only). */
struct report_slot {
	const char *scene, *builder; /* builder NULL in the scene table */
	long machine;                /* pair table: report_machine_number's */
	size_t start, count;         /* scene table: its runs in ix->order */
	double median;               /* pair table: the 1-thread median (NaN: none) */
	double max_threads;          /* pair table: the most threads it ran with */
};

static uint64_t hash(const char *s, uint64_t h)
{
	for (const unsigned char *p = (const unsigned char *)s; *p; p++)
		h = (h ^ *p) * 1099511628211ull;
	return h;
}

/* The slot of (scene, builder, machine) in a table of `cap` (a power of
 * two) slots; builder NULL and machine 0 in the one-key tables. */
static struct report_slot *slot(struct report_slot *table, size_t cap, const char *scene,
                                const char *builder, long machine)
{
	uint64_t h = hash(scene, 14695981039346656037ull);
	if (builder)
		h = hash(builder, h ^ 0xff) ^ (uint64_t)machine * 0x9e3779b97f4a7c15ull;
	for (size_t k = (size_t)h & (cap - 1);; k = (k + 1) & (cap - 1)) {
		struct report_slot *s = &table[k];
		if (!s->scene || (strcmp(s->scene, scene) == 0 && s->machine == machine &&
		                  (!builder || strcmp(s->builder, builder) == 0)))
			return s;
	}
}

/* Numbers the distinct machines of the runs in order of first appearance
 * (M1, M2, ... as report_machines.c lists them). */
static void number_machines(struct report_index *ix, const cJSON *runs)
{
	const cJSON *run;
	cJSON_ArrayForEach(run, runs) {
		const cJSON *m = report_machine(ix->doc, run);
		size_t k = 0;
		while (k < ix->machine_count && !report_same_machine(ix->machines[k], m))
			k++;
		if (k == ix->machine_count)
			ix->machines[ix->machine_count++] = m;
	}
}

long report_machine_number(const struct report_index *ix, const cJSON *run)
{
	const cJSON *m = report_machine(ix->doc, run);
	for (size_t k = 0; k < ix->machine_count; k++)
		if (report_same_machine(ix->machines[k], m))
			return (long)k;
	return 0;
}

static const char *scene_of(const cJSON *run)
{
	return report_str(run, "scene");
}

/* Counts runs per scene and records the 1-thread medians. */
static void first_pass(struct report_index *ix, const cJSON *runs)
{
	const cJSON *run;
	cJSON_ArrayForEach(run, runs) {
		struct report_slot *s = slot(ix->scenes, ix->cap, scene_of(run), NULL, 0);
		s->scene = scene_of(run);
		s->count++;
		long machine = report_machine_number(ix, run);
		struct report_slot *p = slot(ix->pairs, ix->cap, scene_of(run),
		                             report_str(run, "builder"), machine);
		double threads = report_num(run, "threads");
		if (!p->scene) {
			p->scene = scene_of(run);
			p->builder = report_str(run, "builder");
			p->machine = machine;
			p->median = NAN;
		}
		p->max_threads = threads > p->max_threads ? threads : p->max_threads;
		struct report_slot *b = slot(ix->names, ix->cap, report_str(run, "builder"), NULL, 0);
		if (!b->scene) { /* builders numbered in order of appearance: their colours */
			b->scene = report_str(run, "builder");
			b->start = ix->builder_count++;
		}
		if (threads == 1 && isnan(p->median)) /* the first 1-thread run counts */
			p->median = report_num(run, "build_ms.median");
	}
}

/* Places every run in its scene's range of ix->order, document order kept. */
static void second_pass(struct report_index *ix, const cJSON *runs)
{
	size_t next = 0;
	for (size_t k = 0; k < ix->cap; k++) {
		ix->scenes[k].start = next;
		next += ix->scenes[k].count;
		ix->scenes[k].count = 0;
	}
	const cJSON *run;
	cJSON_ArrayForEach(run, runs) {
		struct report_slot *s = slot(ix->scenes, ix->cap, scene_of(run), NULL, 0);
		ix->order[s->start + s->count++] = run;
	}
}

int report_index_init(struct report_index *ix, const cJSON *doc)
{
	const cJSON *runs = cJSON_GetObjectItemCaseSensitive(doc, "runs");
	size_t n = (size_t)cJSON_GetArraySize(runs);
	memset(ix, 0, sizeof(*ix));
	for (ix->cap = 16; ix->cap < 2 * n; ix->cap *= 2)
		;
	ix->scenes = calloc(ix->cap, sizeof(*ix->scenes));
	ix->pairs = calloc(ix->cap, sizeof(*ix->pairs));
	ix->names = calloc(ix->cap, sizeof(*ix->names));
	ix->order = calloc(n + 1, sizeof(*ix->order));
	ix->machines = calloc(n + 1, sizeof(*ix->machines));
	if (!ix->scenes || !ix->pairs || !ix->names || !ix->order || !ix->machines) {
		report_index_finish(ix);
		return -ENOMEM;
	}
	ix->doc = doc;
	number_machines(ix, runs);
	first_pass(ix, runs);
	second_pass(ix, runs);
	return 0;
}

void report_index_finish(struct report_index *ix)
{
	free(ix->scenes);
	free(ix->pairs);
	free(ix->names);
	free(ix->order);
	free(ix->machines);
	memset(ix, 0, sizeof(*ix));
}

const cJSON *const *report_scene_runs(const struct report_index *ix, const char *scene,
                                      size_t *count)
{
	const struct report_slot *s = ix->cap ? slot(ix->scenes, ix->cap, scene, NULL, 0) : NULL;
	*count = s && s->scene ? s->count : 0;
	if (!s || !s->scene)
		return ix->order;
	return ix->order + s->start;
}

double report_speedup(const struct report_index *ix, const cJSON *run)
{
	if (!ix->cap)
		return NAN;
	const struct report_slot *p = slot(ix->pairs, ix->cap, scene_of(run),
	                                   report_str(run, "builder"),
	                                   report_machine_number(ix, run));
	double t = report_num(run, "build_ms.median");
	/* A builder that ran on 1 thread only (no PARALLEL flag) has no speedup. */
	if (!p->scene || !(p->max_threads > 1))
		return NAN;
	return t > 0 ? p->median / t : NAN;
}

long report_builder_number(const struct report_index *ix, const char *builder)
{
	const struct report_slot *b = ix->cap ? slot(ix->names, ix->cap, builder, NULL, 0) : NULL;
	return b && b->scene ? (long)b->start : -1;
}
