/*
 * The harness's progress on stderr: on a terminal one line rewritten in
 * place (run i of n, scene, builder, threads, elapsed, estimated time
 * left); otherwise one plain log line per finished run.
 */
#ifndef BVHLAB_CORE_PROGRESS_H
#define BVHLAB_CORE_PROGRESS_H

#include <stdbool.h>
#include <stdint.h>

#include "output/results.h"

struct progress {
	bool quiet;      /* print nothing */
	bool tty;        /* stderr is a terminal: rewrite the line in place */
	uint32_t index;  /* runs finished (or skipped) so far */
	uint32_t total;  /* runs in the sweep */
	double start;    /* util_now() at init */
};

void progress_init(struct progress *p, bool quiet);
/* On a terminal, the line of the run that starts now. */
void progress_start(const struct progress *p, const struct run_record *run);
/* A finished run: counts it and reports it. */
void progress_done(struct progress *p, const struct run_record *run);
/* Ends a rewritten line. */
void progress_finish(const struct progress *p);

#endif
