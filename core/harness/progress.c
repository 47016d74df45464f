/* Progress lines of a sweep on stderr (see progress.h). */
#include <stdio.h>
#include <string.h>
#include <unistd.h>

#include "harness/progress.h"
#include "util/util.h"

void progress_init(struct progress *p, bool quiet)
{
	*p = (struct progress){.quiet = quiet, .tty = isatty(STDERR_FILENO) == 1,
	                       .start = util_now()};
}

/* Seconds left, from the mean time of the runs so far; < 0 before the first. */
static double remaining(const struct progress *p, double elapsed)
{
	uint32_t done = p->index;
	return done ? elapsed / done * (p->total - done) : -1.0;
}

static void head(const struct progress *p, const struct run_record *run, uint32_t i)
{
	fprintf(stderr, "%s[%u/%u] %s / %s / %u thread%s: ", p->tty ? "\r\033[K" : "", i,
	        p->total, run->scene, run->builder, run->threads, run->threads == 1 ? "" : "s");
}

static void elapsed_and_left(const struct progress *p)
{
	double elapsed = util_now() - p->start, left = remaining(p, elapsed);
	fprintf(stderr, " [%.1fs elapsed", elapsed);
	if (left >= 0)
		fprintf(stderr, ", ~%.0fs left", left);
	fputc(']', stderr);
}

/* On a terminal, the line of the run in progress (rewritten when it ends). */
void progress_start(const struct progress *p, const struct run_record *run)
{
	if (p->quiet || !p->tty)
		return;
	head(p, run, p->index + 1);
	fputs("running...", stderr);
	elapsed_and_left(p);
	fflush(stderr);
}

/* A finished run: one log line, or on a terminal the line rewritten in
 * place (kept, with a newline, when the run is not ok). */
void progress_done(struct progress *p, const struct run_record *run)
{
	p->index++;
	if (p->quiet)
		return;
	head(p, run, p->index);
	fputs(run->status, stderr);
	if (run->sample_count && run->stats) {
		double med, mn, mx;
		util_summarise(run->samples_ms, run->sample_count, &med, &mn, &mx);
		fprintf(stderr, ", %.2f ms median, SAH %.3f", med, run->stats->sah_cost);
	}
	if (run->rays && run->rays->measured)
		fprintf(stderr, ", %.1f nodes/ray", run->rays->primary[run->rays->main].stats.rays
		        ? (double)run->rays->primary[run->rays->main].stats.nodes_visited /
		                  (double)run->rays->primary[run->rays->main].stats.rays
		        : 0);
	if (run->rays && run->rays->error[0]) /* a device that is not there, say */
		fprintf(stderr, ", rays: %s", run->rays->error);
	if (run->error)
		fprintf(stderr, " (%s)", run->error);
	elapsed_and_left(p);
	if (!p->tty || strcmp(run->status, "ok") != 0)
		fputc('\n', stderr);
	fflush(stderr);
}

void progress_finish(const struct progress *p)
{
	if (p->tty && !p->quiet && p->total)
		fputc('\n', stderr);
}
