/*
 * Running one piece of work in a forked child process, so that a plugin
 * that crashes, hangs, calls exit or eats memory costs one run and not the
 * sweep. The work fills a fixed-size report (plain bytes: no pointers)
 * that comes back through a pipe; nothing else of the child survives.
 */
#ifndef BVHLAB_CORE_ISOLATE_H
#define BVHLAB_CORE_ISOLATE_H

#include <stddef.h>
#include <stdint.h>

struct isolate_limits {
	double timeout_s;      /* > 0: the child is killed after this long */
	uint64_t memory_bytes; /* 0: none; else the child's RLIMIT_AS */
};

enum isolate_outcome {
	ISOLATE_REPORTED, /* the whole report came back */
	ISOLATE_CRASHED,  /* the child died or exited before reporting */
	ISOLATE_TIMEOUT,  /* it ran past timeout_s and was killed */
};

/* Runs in the child: fills report[0 .. size). Need not return cleanly. */
typedef void (*isolate_work)(void *arg, void *report, size_t size);

/*
 * Forks after flushing stdio; the child applies the limits, runs
 * work(arg, report, size) on its copy of report, sends it and _exits.
 * Returns an enum isolate_outcome with `why` describing a crash or a
 * timeout ("killed by SIGSEGV (Segmentation fault)", "exited with status 3
 * before reporting", ...), or a negative errno when no child could be
 * started (`why` says so). The caller must not have threads running.
 */
int isolate_call(isolate_work work, void *arg, void *report, size_t size,
                 const struct isolate_limits *limits, char *why, size_t why_size);

/* "SIGSEGV" for SIGSEGV, "signal 42" for a signal without a short name. */
const char *isolate_signal_name(int sig, char *buf, size_t size);

#endif
