/*
 * Marks that tell a reader not to trust a figure too far. Noise: a run
 * whose timed build repeats spread by more than NOISE (max - min over the
 * median), or whose tree is the very same as another run's on the scene
 * (same SAH cost, node count and nodes per ray) while its measured Mrays/s
 * differs from that run's by more than NOISE: the same tree should trace
 * at the same speed, so the difference is the machine's. Load: a run
 * during which other processes kept more CPUs busy on average
 * (load_other: the machine's busy time less the sweep's own) than the
 * cores the run left free, by more than OTHER_SLACK. Results written
 * before load_other existed fall back to the 1-minute load average
 * before or after, less the one thread the sweep itself keeps busy; that
 * average also counts the sweep's own previous runs, which is why it is
 * only the fallback.
 */
#include <math.h>
#include <stdio.h>
#include <string.h>

#include "output/report.h"

#define NOISE REPORT_NOISE
#define SWEEP_OWN_LOAD 1.0
/* A quarter of a CPU: kernel threads and /proc/stat's 10 ms ticks. */
#define OTHER_SLACK 0.25

static bool is_ok(const cJSON *run)
{
	return strcmp(report_str(run, "status"), "ok") == 0;
}

double report_build_spread(const cJSON *run)
{
	double med = report_num(run, "build_ms.median");
	double spread = (report_num(run, "build_ms.max") - report_num(run, "build_ms.min")) / med;
	return med > 0 && isfinite(spread) ? spread : NAN;
}

bool report_same_tree(const cJSON *a, const cJSON *b)
{
	static const char *const keys[] = {"tree.sah_cost", "tree.nodes",
	                                   "rays.primary.nodes_per_ray"};
	for (size_t k = 0; k < sizeof(keys) / sizeof(keys[0]); k++) {
		double x = report_num(a, keys[k]), y = report_num(b, keys[k]);
		if (!isfinite(x) || x != y)
			return false;
	}
	return true;
}

/* The largest relative Mrays/s difference to a run with the same tree on
 * the same machine (another machine traces at its own speed), and that
 * run. The SAH cost is compared first: it tells trees apart at once. */
static double same_tree_gap(const struct report_index *ix, const cJSON *run,
                            const cJSON **other)
{
	size_t n;
	const cJSON *const *runs = report_scene_runs(ix, report_str(run, "scene"), &n);
	double best = 0, mine = report_num(run, "rays.primary.mrays_per_s");
	double sah = report_num(run, "tree.sah_cost");
	*other = NULL;
	for (size_t k = 0; k < n && mine > 0 && isfinite(sah); k++) {
		if (runs[k] == run || report_num(runs[k], "tree.sah_cost") != sah ||
		    !is_ok(runs[k]) || !report_same_tree(run, runs[k]) ||
		    report_machine_number(ix, runs[k]) != report_machine_number(ix, run))
			continue;
		double theirs = report_num(runs[k], "rays.primary.mrays_per_s");
		double gap = theirs > 0 ? fabs(mine - theirs) / fmin(mine, theirs) : 0;
		if (gap > best) {
			best = gap;
			*other = runs[k];
		}
	}
	return best;
}

bool report_noise(const struct report_index *ix, const cJSON *run, char *buf, size_t size)
{
	const cJSON *other;
	double spread = report_build_spread(run), gap;
	int len = 0;
	buf[0] = '\0';
	if (!is_ok(run))
		return false;
	if (spread > NOISE)
		len = snprintf(buf, size, "build repeats spread %.1f %%", 100 * spread);
	if ((gap = same_tree_gap(ix, run, &other)) > NOISE && len >= 0 && (size_t)len < size)
		snprintf(buf + len, size - (size_t)len, "%ssame tree as %s x%.0f, Mrays/s %.0f %% apart",
		         len ? "; " : "", report_str(other, "builder"), report_num(other, "threads"),
		         100 * gap);
	return buf[0] != '\0';
}

/* The CPUs the run's machine offered. */
static double machine_cpus(const cJSON *doc, const cJSON *run)
{
	double c = report_num(run, "machine.threads_available");
	if (!(c > 0))
		c = report_num(doc, "machine.threads_available");
	if (!(c > 0))
		c = report_num(doc, "machine.cores");
	return c;
}

bool report_busy(const cJSON *doc, const cJSON *run, char *buf, size_t size)
{
	double before = report_num(run, "load_before"), after = report_num(run, "load_after");
	double free_cores = machine_cpus(doc, run) - report_num(run, "threads");
	double load = fmax(isfinite(before) ? before : -1, isfinite(after) ? after : -1);
	double other = report_num(run, "load_other");
	buf[0] = '\0';
	if (!(free_cores >= 0))
		return false;
	if (isfinite(other)) {
		if (!(other > free_cores + OTHER_SLACK))
			return false;
		snprintf(buf, size, "others kept %.2f CPUs busy during the run; %.0f core%s left free",
		         other, free_cores, free_cores == 1 ? "" : "s");
		return true;
	}
	if (!(load - SWEEP_OWN_LOAD > free_cores))
		return false;
	snprintf(buf, size, "load %.2f before, %.2f after; %.0f core%s left free", before, after,
	         free_cores, free_cores == 1 ? "" : "s");
	return true;
}

static const char load_rule[] =
	"during the run, other processes kept more CPUs busy on average than the "
	"cores the run left free (the machine's busy time less the sweep's own; for "
	"results without that figure, the 1-minute load average less the sweep's own "
	"thread), so other work may have shared its cores and its times are suspect";

void report_load_warning(struct strbuf *sb, const cJSON *doc, bool html)
{
	char why[160];
	int busy = 0, total = 0;
	const cJSON *run;
	cJSON_ArrayForEach(run, cJSON_GetObjectItem(doc, "runs")) {
		total += isfinite(report_num(run, "load_before"));
		busy += report_busy(doc, run, why, sizeof(why));
	}
	if (busy == 0)
		return;
	sb_printf(sb, html ? "<p class=\"warn\">⚠ Busy machine: %d of %d runs are marked "
	                     "“busy”: %s.</p>\n"
	                   : "\n**Busy machine:** %d of %d runs are marked “busy”: %s.\n",
	          busy, total, load_rule);
}
