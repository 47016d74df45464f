/*
 * The builders of a sweep: each config builder's plugin opened once, with
 * its options checked. Opening runs foreign code (library constructors,
 * the entry point), so with isolation it is tried first in a forked probe:
 * a plugin that crashes or hangs while loading costs its own runs only.
 */
#ifndef BVHLAB_CORE_HARNESS_BUILDERS_H
#define BVHLAB_CORE_HARNESS_BUILDERS_H

#include <stdbool.h>

#include <bvhlab/bvhlab.h>

#include "config/config.h"
#include "harness/isolate.h"
#include "harness/refine_stage.h"

struct harness_builder {
	const struct config_builder *cb;
	bvhlab_plugin *plugin; /* NULL when it could not be loaded */
	bvhlab_options opts;
	bool opts_ok;          /* and every refine stage's plugin and options too */
	const char *status;    /* of its runs when unusable: "failed", "crashed", "timeout" */
	bool skipped;          /* optional ("optional": true) and its plugin could not be
	                        * loaded: it has no runs at all */
	char options_hash[17]; /* of the resolved options and stages, when opts_ok */
	char builder_hash[17]; /* of identity, when opts_ok */
	struct cJSON *identity; /* plugin, options, stages and animation as its runs are
	                         * made (docs/design.md, "Run identity"), when opts_ok */
	bool stage_failed;     /* the builder loaded but a refine stage's plugin did not */
	bool bad_config;       /* its plugin (or a stage's) is not there or not a
	                        * bvhlab plugin, or an option is wrong: the config
	                        * is refused before anything runs */
	bvhlab_error error;
	struct harness_stage {
		bvhlab_plugin *plugin;
		bvhlab_options opts;
	} stages[HARNESS_MAX_STAGES];
	/* "animation": its update plugin (its default options) and stages,
	 * opened to check them before the sweep (open when opts_ok) */
	struct harness_stage update, anim_stages[HARNESS_MAX_STAGES];
	struct refine_stage refine[HARNESS_MAX_STAGES]; /* views of stages[] */
	/* A two-level builder's "top" (its default options; plugin NULL for a
	 * one-level builder): it builds over boxes, checked before the sweep. */
	struct harness_stage top;
};

/* The resource limits of a builder's children (its own or the config's). */
struct isolate_limits harness_run_limits(const struct config *cfg,
                                         const struct config_builder *cb);

/*
 * Opens `plugin` in a forked child killed after timeout_s (> 0): 0 when it
 * loaded there. Else *status is "failed" and -EINVAL (err: why it was
 * refused: not there, not a bvhlab plugin), or "crashed"/"timeout" (or
 * "failed" when no child started) and -ECHILD (err: it died or hung while
 * loading, naming the plugin). Nothing of the plugin stays in this process.
 */
int harness_probe_plugin(const char *plugin, double timeout_s, const char **status,
                         bvhlab_error *err);

/*
 * Opens every builder of cfg into *out ([cfg->builder_count]), each plugin
 * (the builder's and every refine stage's) first in a forked probe when
 * `probed`; a builder that cannot be used keeps its status and message,
 * and the others go on.
 * Messages go to stderr, each once (a grid's builders share theirs), as
 * FILE:LINE:COLUMN: builder 'NAME': ...; *bad_configs counts the builders
 * whose config is wrong (bad_config). A plugin that crashes or hangs while
 * loading is not a config error: its runs are recorded as such. 0, or
 * -ENOMEM.
 */
int harness_open_builders(const struct config *cfg, bool probed,
                          struct harness_builder **out, size_t *bad_configs);
/* A sweep's builders (probed when the config isolates runs): a config that
 * cannot run as written is refused whole (-EINVAL, every error printed,
 * err counting the builders) before the output folder is touched. */
int harness_open_sweep_builders(const struct config *cfg, struct harness_builder **out,
                                bvhlab_error *err);
void harness_close_builders(const struct config *cfg, struct harness_builder *builders);

#endif
