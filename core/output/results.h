/*
 * results.json (docs/design.md, "results.json"), results.csv and report.md of one output
 * folder. The document lives in memory as cJSON and every file is rewritten
 * through a temporary file and rename after each run, so an interrupted
 * sweep always leaves complete files with every finished run.
 */
#ifndef BVHLAB_CORE_RESULTS_H
#define BVHLAB_CORE_RESULTS_H

#include <stdbool.h>
#include <stdint.h>

#include <bvhlab/bvhlab.h>

#include "config/config.h"
#include "machine/machine.h"

struct cJSON;

struct results {
	struct cJSON *doc;
	struct cJSON *scenes;
	struct cJSON *runs;
	char *dir;
	struct cJSON **stale; /* [stale_count] runs of runs[] to be made again: not
	                       * found as done, replaced by their new record */
	size_t stale_count;
	bool locked;  /* lock_fd holds the folder's lock (results_dir.c) */
	int lock_fd;
};

/* A configured thread count not known (a record written before it was kept). */
#define RUN_THREADS_UNKNOWN UINT32_MAX

/*
 * Who a run is: made once, in the run list (plan/plan.h), and the one key
 * results, --resume, ray and image updates, plan.json and merge find a run
 * by (run_identity.c). Its slot is scene x builder x thread count; its
 * identity hash covers everything that shapes its figures (docs/design.md,
 * "Run identity"), so a kept run whose hash differs is made again.
 */
struct run_identity {
	uint32_t id;              /* position in the run list */
	const char *scene;
	const char *builder;      /* the config's label for the builder */
	uint32_t threads;         /* resolved thread count, >= 1 (0: not known, a plan's) */
	uint32_t threads_configured; /* as configured, 0 = all cores (RUN_THREADS_UNKNOWN) */
	const char *options_hash; /* of its options and refine stages, or NULL */
	/* 16 hex digits each, or NULL (not known: a record of an older bvhlab) */
	const char *scene_hash;   /* the scene's description and its files' contents */
	const char *builder_hash; /* plugin, options, refine stages, animation ("": the
	                           * builder's plugin could not be opened) */
	const char *measure_hash; /* repeat, warmup, validation, rays, pin, rays_per_frame */
	const char *hash;         /* of the three: the run's identity */
	/* The config fragments that produced it, recorded with the run as
	 * "config": {"scene", "builder", "measure"} (NULL: not recorded). */
	const struct cJSON *scene_config, *builder_config, *measure_config;
};

/* How a recorded run stands to a key (run_identity_compare). */
enum run_match {
	RUN_OTHER,   /* another slot: scene, builder or thread count differ */
	RUN_SAME,    /* the same run, made the same way */
	RUN_CHANGED  /* the same slot made another way: to be made again */
};

/* Adds "threads_configured", "identity": {"hash", "scene", "builder",
 * "measure"} and "config" of key to the record o (nothing for what key
 * does not know). 0, or -1 when out of memory. */
int run_identity_add(struct cJSON *o, const struct run_identity *key);
/* A record's identity (a results.json or plan.json run); its strings point
 * into run. Members missing are NULL, 0 or RUN_THREADS_UNKNOWN. */
void run_identity_read(const struct cJSON *run, struct run_identity *out);
/* The one comparison: RUN_OTHER, RUN_SAME (also when want has no hash), or
 * RUN_CHANGED with *changed (if not NULL) naming the first part that
 * differs: "scene", "builder", "measure", or "record" (have has no hash). */
enum run_match run_identity_compare(const struct run_identity *want,
                                    const struct run_identity *have, const char **changed);

/* Traversal counters and timings of one run's primary and diffuse rays,
 * by traversal (harness/harness_rays.c measures them). */
struct ray_metrics {
	bool measured;
	uint32_t threads;      /* the threads that traced them */
	unsigned traversals;   /* bit (1 << enum bvhlab_traversal) for each one measured */
	int main;              /* the traversal "primary"/"diffuse" report */
	uint32_t rounds;       /* interleaved rounds the timings are spread over
	                        * (harness_rounds.c); 1: one stretch in the run's child */
	bool provisional;      /* one slice, timed in the run's child while the rounds
	                        * that replace it are still to come ("provisional":
	                        * true; a resumed sweep runs such a run again) */
	/* by enum bvhlab_traversal */
	bvhlab_trace_timing primary[BVHLAB_TRAVERSAL_COUNT], diffuse[BVHLAB_TRAVERSAL_COUNT];
	/* the any-hit kinds, by enum bvhlab_traversal, measured when kinds says */
	bvhlab_trace_timing shadow[BVHLAB_TRAVERSAL_COUNT], ao[BVHLAB_TRAVERSAL_COUNT];
	unsigned kinds;         /* bit (1 << enum ray_kind) per kind asked for
	                         * (config.h); 0 is read as primary and diffuse */
	uint64_t disagreements; /* rays whose hits differ from the main traversal's
	                         * (for the any-hit kinds: whether anything is hit) */
	char device[96];        /* the OpenCL device of the cl_ traversals ("" if none ran) */
	char error[512];        /* why the rays, or one traversal, could not be traced ("") */
};

/* m's timings of one kind of rays, by enum bvhlab_traversal. */
static inline bvhlab_trace_timing *ray_metrics_kind(struct ray_metrics *m, int kind)
{
	bvhlab_trace_timing *t[RAY_KINDS] = {m->primary, m->diffuse, m->shadow, m->ao};
	return t[kind];
}

/* Peak memory of one run's builds (harness/harness_memory.c measures it). */
struct build_memory {
	bool measured;            /* /proc/self/status was readable */
	bool reset;               /* the high-water mark was reset before the builds */
	uint64_t start_rss_bytes; /* resident set before the first build */
	uint64_t peak_rss_bytes;  /* the process's peak resident set over the builds */
	uint64_t peak_bytes;      /* peak_rss - start_rss: what the builds added at peak
	                           * (0 when the mark could not be reset) */
	uint64_t output_bytes;    /* the output buffers the host allocated, capacity */
	uint64_t scene_bytes;     /* the scene's own arrays (harness_memory_scene_bytes):
	                           * resident before the builds, part of start_rss */
	uint64_t run_peak_rss_bytes; /* the peak over the builds, validation and tracing
	                              * (0: not read) */
};

/* A run's peak memory as estimated before it started
 * (harness/harness_estimate.c). */
struct memory_estimate {
	bool known;             /* a limit was known (the config's, or MemAvailable) */
	bool declared;          /* the builder and its stages declared their bytes */
	bool limit_from_config; /* memory_limit_mb, not the memory available */
	uint64_t bytes;         /* scene_bytes + the larger of bytes_per_prim and
	                         * after_bytes_per_prim x primitives */
	uint64_t scene_bytes;   /* the scene's arrays (harness_memory_scene_bytes) */
	uint64_t bytes_per_prim; /* the builder's and its stages' declarations, summed */
	uint64_t after_bytes_per_prim; /* the tree, validation and tracing after the builds
	                                * (harness_estimate.c) */
	uint64_t limit_bytes;   /* what it was held against */
	/* A two-level run's (harness_estimate_two_level): its instances and the
	 * bytes each adds (top build, input, tracing); bytes_per_prim and
	 * after_bytes_per_prim are then per unique triangle. 0: one-level. */
	uint64_t instances;
	uint64_t top_bytes_per_instance;
};

/* The device a device builder's run built on (BVHLAB_BUILDER_DEVICE) and
 * what the OpenCL runtime took (harness/harness_memory.c measures it). */
struct run_device {
	struct machine_cl_device cl; /* as its "device" option chose it */
	bool runtime_measured;
	uint64_t runtime_bytes; /* resident memory the runtime and a context on the
	                         * device added before the first build, measured once
	                         * per process: part of memory.start_rss_bytes, not of
	                         * memory.peak_bytes (the build's own) */
};

/* What a build series measured of one refinement stage. */
struct stage_metrics {
	char plugin[64];       /* the descriptor's name */
	double ms;             /* median over the timed repeats */
	double sah_before, sah_after; /* SAH cost of the last repeat's tree */
};

/* One frame of an animated scene as a run's strategy handled it
 * (harness/harness_frames.c; results_frames.c writes it). */
struct frame_metrics {
	uint32_t frame;
	bool rebuilt;          /* built anew, not updated */
	bool valid;            /* structure (and brute-force rays where checked) */
	bool rays_checked;     /* brute-force rays checked: first, middle, last frame */
	double update_ms;      /* the rebuild or update and its stages */
	double sah;            /* SAH cost of the frame's tree */
	double nodes_per_ray;  /* primary rays of the frame's camera */
	double mrays_per_s;
	double cost_ms;        /* update_ms + rays_per_frame / rays per second */
	bool traced;           /* the rays were traced: nodes_per_ray, mrays_per_s measured */
	bool costed;           /* cost_ms known: traced, or no rays per frame to pay for */
};

/* One level of a two-level run (docs/instances.md): its plugin, build
 * time (the bottom's: the sum over meshes of each mesh's median) and tree
 * (the bottom's: summed over the meshes' trees; sah the mean of theirs,
 * each mesh counted once). */
struct results_level {
	char plugin[64];
	double build_ms;
	uint32_t trees, nodes, leaves;
	double sah;
	uint64_t memory_bytes;
};

/* A two-level run's levels apart, and the whole tree's two-level SAH:
 * SAH(top) + sum over instances i of SA(world box i) / SA(top root) *
 * SAH(bottom tree of i's mesh). */
struct results_two_level {
	struct results_level bottom, top;
	double sah;
};

/* Everything known about one run; fields beyond status are optional. */
struct run_record {
	uint32_t id;           /* position in the config's run order (plan.h) */
	const char *scene;
	const char *builder;   /* the config's label for the builder */
	const char *plugin;    /* the descriptor's name */
	uint32_t threads;      /* resolved thread count */
	const bvhlab_options *opts; /* resolved options, or NULL */
	const char *options_hash; /* of opts and the refine stages' (part of the
	                           * run's identity), or NULL */
	const struct run_identity *key; /* the run's identity (its hashes and config
	                                 * fragment are recorded), or NULL */
	const char *status;    /* "ok", "invalid", "failed", ... */
	const char *error;     /* message when status is not "ok", or NULL */
	const double *samples_ms;
	uint32_t sample_count; /* 0: no timing */
	double cold_ms;        /* the first build, before any warm-up repeat */
	uint32_t triangles;
	const bvhlab_tree_stats *stats; /* or NULL */
	uint32_t width;        /* with stats: the tree's branching factor, 2 to 8 */
	const double *epo;     /* end-point overlap (bvhlab_tree_epo), or NULL */
	const struct build_memory *memory; /* peak memory of the builds, or NULL */
	const struct memory_estimate *estimate; /* the peak estimated beforehand, or NULL */
	const struct run_device *device; /* a device builder's device, or NULL */
	bool validated;
	bool valid;
	uint64_t rays_checked, mismatches;
	const struct ray_metrics *rays; /* or NULL: not traced */
	const struct stage_metrics *stages; /* [stage_count] refinement stages */
	uint32_t stage_count;
	const bvhlab_phase *phases; /* [phase_count] the builder's phase medians */
	uint32_t phase_count;
	const struct frame_metrics *frames; /* [frame_count] an animated scene's frames */
	uint32_t frame_count;
	const struct results_two_level *two_level; /* a two-level build's levels, or NULL */
	/* The machine's 1-minute load average just before and after the run's
	 * series (-1: unreadable), so a report can tell a busy machine;
	 * recorded when load_read. */
	bool load_read;
	double load_before, load_after;
	/* CPUs others kept busy during the series, on average
	 * (machine_other_load), or -1: not measurable. */
	double load_other;
};


/* mkdir -p: creates every missing folder of `path`; err names the one that failed. */
int results_make_dirs(const char *path, bvhlab_error *err);

/* The document for folder dir; results_write creates the folder. */
int results_init(struct results *res, const struct config *cfg, const char *dir,
                 bvhlab_error *err);
void results_finish(struct results *res);

int results_add_scene(struct results *res, const char *name, const char *source,
                      uint32_t triangles, const char *error);
/* A two-level scene's counts, added to scene `name` (added before) as
 * "instances": {meshes, instances, unique_triangles, instanced_triangles}. */
struct results_instances {
	uint32_t meshes, instances;
	uint64_t unique_triangles, instanced_triangles;
};
int results_scene_instances(struct results *res, const char *name,
                            const struct results_instances *in);
int results_add_run(struct results *res, const struct run_record *run);
/* The run's record as results_add_run adds it (results_run.c); NULL when
 * out of memory. */
struct cJSON *results_run_json(const struct run_record *run);
/*
 * "not_applicable": [{"builder", "threads": [...], "reason"}]: thread counts
 * of the config that a builder was not run at (one without the PARALLEL
 * flag runs once per scene); replaces the builder's earlier entry.
 */
int results_set_not_applicable(struct results *res, const char *builder,
                               const uint32_t *threads, size_t count, const char *reason);

/* A device builder's run: "device": {"name", "kind", "compute_units",
 * "platform", "index": "P:D", "global_mem_bytes"} into run object o, and
 * "runtime_bytes" into its "memory" (results_device.c). */
void results_device_add(struct cJSON *o, const struct run_device *d);

/* "rays": {"primary": {...}, "diffuse": {...}, "threads": n} of docs/design.md. */
struct cJSON *results_rays_json(const struct ray_metrics *m);

/* "build_phases": {"upload": ms, "device": ms, ...} (results_stages.c). */
struct cJSON *results_phases_json(const bvhlab_phase *phases, uint32_t count);

/* A run's build time of record ("own_ms" in results.json; fronts and
 * dominance verdicts compare it): build_ms.median less the medians of the
 * phases "input" and "convert", which a builder reports for translating
 * bvhlab's input into its own format and its tree into the standard
 * layout (the peer libraries; the device builders' conversion). NAN when
 * the run has no build_ms. */
double results_own_ms(const struct cJSON *run);

/* "stages": [{"plugin", "ms", "sah_before", "sah_after"}, ...] (results_stages.c). */
struct cJSON *results_stages_json(const struct stage_metrics *stages, uint32_t count);

/* "frames": [{frame, update_ms, sah, valid, nodes_per_ray, mrays_per_s,
 * cost_ms, rebuilt}, ...] (results_frames.c). */
struct cJSON *results_frames_json(const struct frame_metrics *frames, uint32_t count);
/* frames.csv in dir, one line per run and frame, when some run of the
 * document has frames (results_frames.c). */
int results_frames_csv(const struct cJSON *doc, const char *dir, bvhlab_error *err);

/* The scene's "images": {"<kind>": name}; a legend also sets "heat_min"/"heat_max". */
int results_set_scene_image(struct results *res, const char *scene, const char *kind,
                            const char *name, uint32_t lo, uint32_t hi);
/* The run's "heat_image": name. */
int results_set_run_image(struct results *res, const struct run_identity *key,
                          const char *name);

/* Replaces the run's "rays" (the interleaved rounds' timings come after
 * the run was recorded). -ENOENT when there is no such run. */
int results_set_run_rays(struct results *res, const struct run_identity *key,
                         const struct ray_metrics *m);

/*
 * Takes over the finished runs (any status of docs/design.md's list) and the
 * scenes of dir/results.json, for `bvhlab run --resume`. *kept counts the
 * runs, *not_ok those whose status is not "ok". -ENOENT when there is no
 * file; another negative errno, with err naming the file, when it cannot be
 * read, is not a results document or fails results_check_runs.
 */
int results_resume(struct results *res, const struct run_identity *keys, size_t key_count,
                   size_t *kept, size_t *not_ok, bvhlab_error *err);

/*
 * The runs of a results.json to resume, against the sweep's run list
 * (keys[key_count]): each an object with a known status, a whole thread
 * count up to CONFIG_MAX_THREADS, its optional members of the right types,
 * and an identity (scene, builder, resolved thread count) that one run of
 * the list has and no other run repeats. 0, or -EINVAL with err naming the
 * file and the first bad run.
 */
int results_check_runs(const struct cJSON *runs, const struct run_identity *keys,
                       size_t key_count, const char *path, bvhlab_error *err);
/*
 * Marks the runs of `builder` that were made with other options (their
 * "options_hash" is not options_hash; runs without one, or options_hash
 * NULL, stay) and, when not_ok, those whose status is not "ok", to be made
 * again: results_has_run no longer finds them, and each stays in the
 * document until results_add_run replaces it (a kill in between loses
 * nothing). How many were marked.
 */
size_t results_forget_runs(struct results *res, const char *builder, const char *options_hash,
                           bool not_ok);
/* Marks a run of the document to be made again: it stays (and in the file)
 * until its new record replaces it. 1 when it was not marked yet, else 0. */
size_t results_mark_stale(struct results *res, struct cJSON *run);
/* Whether run is marked to be made again. */
bool results_is_stale(const struct results *res, const struct cJSON *run);
/* Removes the kept runs in no slot of keys[] (of a scene and builder the
 * sweep has, at a thread count it no longer makes: results_check_runs
 * accepts only those); how many. They are gone from the file at the next
 * write. */
size_t results_drop_gone(struct results *res, const struct run_identity *keys, size_t count);
/*
 * Marks every kept run whose identity differs from the run of keys[] in
 * its slot to be made again (run_identity_compare: RUN_CHANGED), calling
 * changed(ctx, key, what) for each; every kept run takes its slot's id in
 * keys[] (the list's ids move when builders or scenes are added). How many
 * were marked (results_check.c).
 */
size_t results_forget_changed(struct results *res, const struct run_identity *keys,
                              size_t count,
                              void (*changed)(void *ctx, const struct run_identity *key,
                                              const char *what),
                              void *ctx);
/* Marks the runs whose rays are provisional (their sweep was killed before
 * the rounds replaced them) to be made again, as results_forget_runs does. */
size_t results_forget_provisional(struct results *res);
/* Whether every run of the document is "ok" (those to be made again aside). */
bool results_all_ok(const struct results *res);
/* "options": {name: value, ...} of resolved options (NULL: {}). */
struct cJSON *results_options_json(const bvhlab_options *opts);

/* A number member of an object the writers build: each writes its figures
 * as one table through results_add_numbers, in the table's order (the
 * order results.json shows them in). */
struct results_number {
	const char *name;
	double value;
};
#define RESULTS_NUMBERS(table) (sizeof(table) / sizeof((table)[0]))
/* Adds the n numbers of f to o, in order; o NULL adds nothing. */
void results_add_numbers(struct cJSON *o, const struct results_number *f, size_t n);

/* Whether the document holds the run (found by scene, builder and threads). */
bool results_has_run(const struct results *res, const struct run_identity *key);

/* ---- the output folder (results_dir.c) ---------------------------------- */

/*
 * Rewrites results.json, results.csv, report.md and report.html, each
 * atomically; a folder that does not exist yet is made with all four in it
 * at once (a hidden temporary sibling, .bvhlab-new-XXXXXX, renamed into
 * place), parents as needed. The folder's lock is taken first if res does
 * not hold it (a new folder comes with it held): -EBUSY, err naming the
 * holder's pid, when another process writes there.
 */
int results_write(struct results *res, bvhlab_error *err);
/* The four files into res->dir as it is (results_write's second half). */
int results_write_renderings(const struct results *res, bvhlab_error *err);

/*
 * One writer per output folder: takes res->dir's advisory lock
 * (.bvhlab.lock, flock) for as long as res lives, and writes this pid
 * into it. 0 (also when the folder does not exist yet: results_write takes
 * it when it makes the folder), or -EBUSY with err naming the folder and
 * the pid of the process that holds it.
 */
int results_lock(struct results *res, bvhlab_error *err);
void results_unlock(struct results *res);

/* Removes the temporary folders (.bvhlab-new-*) in parent that no living
 * process is making (their lock is free). */
void results_sweep_temps(const char *parent);

/* "out/", "out/." and "out//" become "out", in place. */
void results_normalise_dir(char *dir);

/* Writes `text` to dir/name through dir/.name.tmp and rename. */
int results_write_file(const char *dir, const char *name, const char *text, bvhlab_error *err);

/* How `bvhlab report` sees a saved sweep (results_view.c): its reference
 * and the scenes and thread counts kept (none listed: all). */
struct results_view {
	const char *reference;   /* a builder label or plugin, or NULL: the config's */
	const char *const *scenes;
	size_t scene_count;
	const double *threads;
	size_t threads_count;
};
/* Applies the view to a results document in memory: runs and scenes not
 * kept removed (a "report_note" says so), config.report.reference set.
 * 0, or -EINVAL with err naming the file and the scene, thread count or
 * reference it lacks (the reference must have an ok run among those kept). */
int results_view_apply(struct cJSON *doc, const struct results_view *view, const char *path,
                       bvhlab_error *err);

/* Regenerates results.csv, report.md and report.html in dir from a saved
 * results.json (bvhlab report), seen through view (NULL: as saved); the
 * file itself is only read. */
int results_render_saved(const char *json_path, const char *dir,
                         const struct results_view *view, bvhlab_error *err);

#endif
