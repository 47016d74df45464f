/*
 * The experiment harness: every scene x builder x thread count of a config,
 * timed, validated and measured, with results written as runs finish.
 */
#ifndef BVHLAB_CORE_HARNESS_H
#define BVHLAB_CORE_HARNESS_H

#include <stdbool.h>
#include <stdint.h>

#include <bvhlab/bvhlab.h>
#include <bvhlab/trace.h>

#include "config/config.h"
#include "harness/refine_stage.h"
#include "output/results.h"

/* Loads or generates one config scene, subdivides it and names it. */
int harness_load_scene(const struct config_scene *cs, bvhlab_scene **out, bvhlab_error *err);

/*
 * Loads the scene once in a forked child first, under timeout_s and the
 * largest memory limit of the config's builders (none if one has none):
 * a scene that hangs the loader, eats the machine's memory or crashes it
 * costs that scene only. 0 when it loaded there; else a negative errno
 * and err saying why, naming the limit it ran into.
 */
int harness_probe_scene(const struct config *cfg, const struct config_scene *cs,
                        bvhlab_error *err);

/* What went wrong in a sweep, for its last line. */
struct harness_tally {
	size_t not_ok;   /* runs of this process that did not end ok */
	size_t untraced; /* ok runs without ray figures (their "rays": "error" says why) */
	size_t unsaved;  /* runs that finished but could not be written */
};

struct harness_options {
	bool quiet;  /* no progress lines on stderr */
	bool resume; /* keep the finished runs of the output's results.json, skip them */
	bool force;  /* without resume: move an earlier results.json aside, not refuse */
	bool retry_failed; /* with resume: runs kept that did not end ok run again */
	const bool *only;      /* [plan_run_count]: run just these ids; NULL: all */
	const char *plan_hash; /* run from a plan: recorded so merge can match parts */
	struct harness_tally *tally; /* filled when not NULL */
};

/*
 * Runs the whole config; each run's builds in a child process unless the
 * config says "isolate": false. Returns 0 when every run (kept ones
 * included) is ok and valid, 1 when some run is not (all are still
 * recorded), or a negative errno when nothing could be recorded (output
 * folder not writable, results.json to resume unreadable) with err set.
 */
int harness_run(const struct config *cfg, const struct harness_options *opts,
                bvhlab_error *err);

/* One timed build series of a plugin on prepared primitives. */
struct build_series {
	uint32_t warmup, repeat;
	uint32_t threads;      /* 0: all hardware threads */
	double *samples_ms;    /* [repeat], filled: the build and every stage */
	double cold_ms;        /* the first build (warm-up or not) with its refine stages: fresh output
	                        * and builder scratch, page faults included */
	const struct refine_stage *stages; /* [stage_count], applied in order */
	uint32_t stage_count;  /* at most HARNESS_MAX_STAGES */
	struct stage_metrics *stage_out; /* [stage_count], filled */
	/* The builder's own phases (ABI 1.3 host->phase): each one's median
	 * over the timed repeats (0 in a repeat that did not report it), in
	 * the order first reported; filled. */
	bvhlab_phase phases[BVHLAB_MAX_PHASES];
	uint32_t phase_count;
	bvhlab_tree tree;      /* the last build's tree, refined */
};

/* Runs warmup + repeat builds, each followed by the stages; stops at the
 * first failure (err set). */
int harness_time_builds(const bvhlab_plugin *plugin, const bvhlab_options *opts,
                        const bvhlab_build_input *input, struct build_series *s,
                        bvhlab_error *err);


/* ---- peak memory of the builds (harness_memory.c) ------------------------ */

struct build_memory; /* output/results.h */

/* Before the first build (warm-up included), and after the last one. */
void harness_memory_begin(struct build_memory *m);
void harness_memory_end(struct build_memory *m, const bvhlab_tree *tree);

/* ---- rays and images (harness_rays.c) ------------------------------------ */

struct ray_metrics; /* output/results.h */

/* Each tile keeps its best of at least this many passes (see
 * bvhlab_trace_timing): enough chances to run undisturbed. */
#define HARNESS_MIN_REPEATS 10
/* Diffuse rays: the same for every builder of a scene. */
#define HARNESS_DIFFUSE_SEED 0xd1ff05eULL

/* What rays a run is measured with: the config's "rays". */
struct ray_settings {
	uint32_t width, height; /* primary rays: one per pixel */
	uint32_t diffuse;       /* bounces per primary hit */
	uint32_t threads;       /* tracing threads; 0: all hardware threads */
	double min_ms;          /* each batch is repeated for at least this long */
	uint32_t min_repeats;   /* ... and at least this many passes */
	uint32_t rounds;        /* slices min_ms is spread over (harness_rounds.c) */
	unsigned traversals;    /* bit (1 << enum bvhlab_traversal) for each one measured */
	int main;               /* the traversal whose hits feed images and diffuse rays */
	const char *device;     /* the cl_ traversals' OpenCL device spec (NULL: auto) */
};

/* The config's settings (cfg NULL: one quick stack pass, all threads). */
void harness_ray_settings(const struct config *cfg, struct ray_settings *rs);

/* The config's camera, or the automatic framing of the scene. */
void harness_camera(const struct config *cfg, const bvhlab_scene *scene, bvhlab_camera *cam);

/*
 * Primary rays (width x height) and `diffuse` bounces per primary hit,
 * each batch timed (bvhlab_trace_measure) with every traversal of rs.
 * nodes ([width * height], may be NULL) gets nodes visited per pixel,
 * shade ([3 * width * height], may be NULL) the shaded render, both from
 * the main traversal. 0 or a negative errno, with m->error saying why (it
 * also names a traversal other than the main one that could not run: that
 * one is left out of m and the others are measured).
 */
int harness_trace_rays(const bvhlab_tree *tree, const bvhlab_scene *scene,
                       const bvhlab_camera *cam, const struct ray_settings *rs,
                       struct ray_metrics *m, uint32_t *nodes, uint8_t *shade);

#endif
