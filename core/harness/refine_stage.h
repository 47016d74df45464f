/*
 * A refinement stage as the harness runs it: a plugin with refine (ABI 1.2)
 * and its options, after every build of a series. Its own header because
 * both the series (harness_series.h) and the opened builders (harness_builders.h)
 * hold stages, and neither should include the other.
 */
#ifndef BVHLAB_CORE_HARNESS_REFINE_STAGE_H
#define BVHLAB_CORE_HARNESS_REFINE_STAGE_H

#include <bvhlab/host.h>

#include "config/config.h"

#define HARNESS_MAX_STAGES CONFIG_MAX_REFINE

/* A refinement stage run after every build of a series. */
struct refine_stage {
	const bvhlab_plugin *plugin; /* one whose descriptor has refine (ABI 1.2) */
	const bvhlab_options *opts;
};

#endif
