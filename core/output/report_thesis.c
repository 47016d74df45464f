/*
 * The thesis's table shape in report.md: for each thread count above 1,
 * one row per scene with the sequential build time and, for every other
 * builder, its time, its gain (t_seq - t) / t_seq and its speedup
 * t_seq / t. The sequential time is the first ok 1-thread run of the
 * report's reference builder (report.reference, default sah_seq; no table
 * when the one asked for did not run). Only ok runs count; a missing one
 * shows as "—". When a thread count appears twice for a builder (threads
 * 0 resolving to a count also listed), the first ok run is used. A table
 * that would hold only dashes is left out: no sequential time, or no
 * builder at that count. Runs from several machines (a merged sweep) give
 * one row per scene and machine: a time is only set against the same
 * machine's sequential time. A reference that ran on more than 1 thread
 * (a parallel builder) gets no table.
 */
#include <stdlib.h>
#include <string.h>

#include <cJSON.h>

#include "output/report.h"
#include "util/util.h"

#define MAX_COLUMNS 32
#define MAX_THREAD_COUNTS 32
#define MISSING "—"

static const char *text(const cJSON *o, const char *key)
{
	const cJSON *v = cJSON_GetObjectItemCaseSensitive(o, key);
	return cJSON_IsString(v) ? v->valuestring : "";
}

static double number(const cJSON *o, const char *key, double fallback)
{
	const cJSON *v = cJSON_GetObjectItemCaseSensitive(o, key);
	return cJSON_IsNumber(v) ? v->valuedouble : fallback;
}

/* Median build time of the scene's first ok run of the builder on the
 * machine (-1: any) that matches, or a negative number. Only the scene's
 * runs are looked at (the index), so a table costs the run count times
 * its columns and thread counts. */
static double median_ms(const struct report_index *ix, const char *scene, long machine,
                        const char *builder, double threads)
{
	size_t n;
	const cJSON *const *runs = report_scene_runs(ix, scene, &n);

	for (size_t k = 0; k < n; k++) {
		const cJSON *run = runs[k];
		if (strcmp(text(run, "status"), "ok") != 0 || number(run, "threads", -1) != threads ||
		    strcmp(text(run, "builder"), builder) != 0 ||
		    (machine >= 0 && report_machine_number(ix, run) != machine))
			continue;
		double ms = number(cJSON_GetObjectItemCaseSensitive(run, "build_ms"), "median", -1);
		if (ms > 0)
			return ms;
	}
	return -1;
}

/* Labels of the builders compared with the reference, in order of appearance. */
static int columns(const cJSON *runs, const char *ref, const char **out)
{
	const cJSON *run;
	int n = 0;

	cJSON_ArrayForEach(run, runs) {
		const char *label = text(run, "builder");
		bool seen = strcmp(label, ref) == 0 || !*label;
		for (int i = 0; i < n && !seen; i++)
			seen = strcmp(out[i], label) == 0;
		if (!seen && n < MAX_COLUMNS)
			out[n++] = label;
	}
	return n;
}

static int by_value(const void *a, const void *b)
{
	double x = *(const double *)a, y = *(const double *)b;
	return (x > y) - (x < y);
}

/* Distinct thread counts above 1, ascending. */
static int thread_counts(const cJSON *runs, double *out)
{
	const cJSON *run;
	int n = 0;

	cJSON_ArrayForEach(run, runs) {
		double t = number(run, "threads", 0);
		bool seen = t <= 1;
		for (int i = 0; i < n && !seen; i++)
			seen = out[i] == t;
		if (!seen && n < MAX_THREAD_COUNTS)
			out[n++] = t;
	}
	qsort(out, (size_t)n, sizeof(*out), by_value);
	return n;
}

static void header(struct strbuf *sb, const char *ref, double threads, const char **cols,
                   int n)
{
	sb_printf(sb, "\n### %.0f threads\n\n| scene | ", threads);
	report_md_text(sb, ref);
	sb_printf(sb, " 1 thread ms |");
	for (int i = 0; i < n; i++) {
		sb_printf(sb, " ");
		report_md_text(sb, cols[i]);
		sb_printf(sb, " ms | gain | speedup |");
	}
	sb_printf(sb, "\n|---|---:|");
	for (int i = 0; i < n; i++)
		sb_printf(sb, "---:|---:|---:|");
	sb_printf(sb, "\n");
}

/* Whether the machine measured some run of the scene. */
static bool measured_on(const struct report_index *ix, const char *scene, long machine)
{
	size_t n;
	const cJSON *const *runs = report_scene_runs(ix, scene, &n);
	for (size_t k = 0; k < n; k++)
		if (report_machine_number(ix, runs[k]) == machine)
			return true;
	return false;
}

/* The scene's row of one machine; "scene (M2)" when there are several. */
static void row(struct strbuf *sb, const struct report_index *ix, const char *ref,
                const char *scene, long machine, double threads, const char **cols, int n)
{
	double seq = median_ms(ix, scene, machine, ref, 1);

	sb_printf(sb, "| ");
	report_md_text(sb, scene);
	if (ix->machine_count > 1)
		sb_printf(sb, " (M%ld)", machine + 1);
	sb_printf(sb, " |");
	if (seq > 0)
		sb_printf(sb, " %.2f |", seq);
	else
		sb_printf(sb, " " MISSING " |");
	for (int i = 0; i < n; i++) {
		double t = median_ms(ix, scene, machine, cols[i], threads);
		if (t <= 0)
			sb_printf(sb, " " MISSING " | " MISSING " | " MISSING " |");
		else if (seq <= 0)
			sb_printf(sb, " %.2f | " MISSING " | " MISSING " |", t);
		else
			sb_printf(sb, " %.2f | %.1f %% | %.2f |", t, 100 * (seq - t) / seq, seq / t);
	}
	sb_printf(sb, "\n");
}

/* Whether some scene has a time for the builder at threads. */
static bool any_time(const cJSON *doc, const struct report_index *ix, const char *builder,
                     double threads)
{
	const cJSON *scene;
	cJSON_ArrayForEach(scene, cJSON_GetObjectItemCaseSensitive(doc, "scenes"))
		if (median_ms(ix, text(scene, "name"), -1, builder, threads) > 0)
			return true;
	return false;
}

/* The columns with a time at this thread count: a column of dashes says
 * nothing (a builder that ran on 1 thread only, say). */
static int columns_at(const cJSON *doc, const struct report_index *ix, double threads,
                      const char **cols, int n, const char **out)
{
	int m = 0;
	for (int i = 0; i < n; i++)
		if (any_time(doc, ix, cols[i], threads))
			out[m++] = cols[i];
	return m;
}

/* The title and what the table holds. */
static void intro(struct strbuf *sb, const char *ref)
{
	sb_printf(sb, "\n## Parallel builders against ");
	report_md_text(sb, ref);
	sb_printf(sb, "\n\nThe thesis's table: median build times in ms; the sequential time "
	              "is ");
	report_md_text(sb, ref);
	sb_printf(sb, " on 1 thread; gain = (t_seq − t) / t_seq, speedup = t_seq / t. Only ok "
	              "runs count; " MISSING " marks a missing one.\n");
}

/* The rows of one thread count: per scene, one per machine that measured it. */
static void rows(struct strbuf *sb, const cJSON *doc, const struct report_index *ix,
                 const char *ref, double threads, const char **cols, int n)
{
	const cJSON *scene;
	cJSON_ArrayForEach(scene, cJSON_GetObjectItemCaseSensitive(doc, "scenes"))
		for (long m = 0; m < (long)ix->machine_count; m++)
			if (ix->machine_count == 1 || measured_on(ix, text(scene, "name"), m))
				row(sb, ix, ref, text(scene, "name"), m, threads, cols, n);
}

/* Whether the builder ran on more than 1 thread: a parallel reference's
 * 1-thread time is no sequential baseline, and gains over it would only
 * measure it against its own threads. */
static bool ran_parallel(const cJSON *runs, const char *builder)
{
	const cJSON *run;
	cJSON_ArrayForEach(run, runs)
		if (strcmp(text(run, "builder"), builder) == 0 && number(run, "threads", 1) > 1)
			return true;
	return false;
}

void report_thesis(struct strbuf *sb, const cJSON *doc, const struct report_index *ix)
{
	const cJSON *runs = cJSON_GetObjectItemCaseSensitive(doc, "runs");
	const char *cols[MAX_COLUMNS], *shown[MAX_COLUMNS], *asked;
	double counts[MAX_THREAD_COUNTS];
	bool titled = false, fallback;
	const char *ref = report_reference(doc, &asked, &fallback);
	if (!ref || fallback) /* the builder asked for did not run: no sequential time */
		return;
	if (ran_parallel(runs, ref)) /* its 1-thread run is no sequential baseline */
		return;
	int ncols = columns(runs, ref, cols), ncounts = thread_counts(runs, counts);

	/* Without a sequential time every gain and speedup would be a dash. */
	if (ncols == 0 || ncounts == 0 || !any_time(doc, ix, ref, 1))
		return;
	for (int k = 0; k < ncounts; k++) {
		int nshown = columns_at(doc, ix, counts[k], cols, ncols, shown);
		if (nshown == 0)
			continue;
		if (!titled)
			intro(sb, ref);
		titled = true;
		header(sb, ref, counts[k], shown, nshown);
		rows(sb, doc, ix, ref, counts[k], shown, nshown);
	}
}
