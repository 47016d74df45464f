/*
 * standalone.h: what the three peer programs share (arguments, the scene,
 * the timing loop). Each program builds from its library's own input
 * format, made once before timing, and times only the library's build
 * call, after warm-up builds into the same BVH object, as the libraries'
 * own benchmarks do; compare.sh runs them beside the in-harness plugins.
 *
 *   PROGRAM SCENE [--subdivide K] [--threads N] [--repeat N] [--warmup N]
 *           [--variant NAME] [--callbacks tutorial|plugin] [--input once|each]
 *
 * prints one line: "LIB VARIANT [callbacks=C] threads=N wall_ms=MEDIAN
 * cpu_ms=MEDIAN min_ms=MIN repeats=N" (cpu_ms: the process's CPU time over
 * the call, all threads, which waiting for a CPU does not stretch).
 */
#ifndef BVHLAB_PEERS_STANDALONE_H
#define BVHLAB_PEERS_STANDALONE_H

#include <bvhlab/scene.h>

BVHLAB_BEGIN_DECLS

typedef struct sa_args {
	const char *scene;
	const char *variant; /* the library's builder, as the plugin's option names it */
	int which;           /* its index in the program's list of variants */
	const char *callbacks; /* embree only: "tutorial" (its kind, the default) or
	                        * "plugin" (the plugin's); NULL when not given */
	int input_each; /* tinybvh only. --input each (1): the library's input
	                 * remade, untimed, before every build (as the plugin makes
	                 * it in its build call, phase "input"); once (0): made
	                 * once; -1 when not given (once) */
	unsigned subdivide, threads, repeat, warmup;
} sa_args;

/* Parses argv into a (defaults: variant `def`, 1 thread, repeat 5,
 * warmup 1, callbacks NULL; `variants` is "a|b|c") and loads the scene as
 * the harness does (file, then subdivide) into *scene. 0, or the exit
 * status after a message on stderr: 2 for a bad command line (with the
 * usage), 1 when the scene cannot be loaded. */
int sa_start(int argc, char **argv, const char *variants, const char *def, sa_args *a,
             bvhlab_scene **scene);

/* One timed build: `prepare` (untimed, may be NULL) then `build`; both
 * return 0 or a negative errno. */
typedef int (*sa_step)(void *user);

/* Runs warmup + repeat builds, prints the result line for `lib`; 0 or the
 * first failing step's code. */
int sa_time(const char *lib, const sa_args *a, sa_step prepare, sa_step build, void *user);

BVHLAB_END_DECLS

#endif
