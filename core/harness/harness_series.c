/*
 * Timing a build series: warm-up builds, then timed ones into the same
 * tree (so room grown once stays allocated); `bvhlab build` and the sweep
 * share it.
 */
#include "harness/harness.h"
#include "util/util.h"

int harness_time_builds(const bvhlab_plugin *plugin, const bvhlab_options *opts,
                        const bvhlab_build_input *input, struct build_series *s,
                        bvhlab_error *err)
{
	for (uint32_t k = 0; k < s->warmup + s->repeat; k++) {
		double t0 = util_now();
		int r = bvhlab_build(plugin, opts, input, s->threads, &s->tree, err);
		double t1 = util_now();
		if (r < 0)
			return r;
		if (k >= s->warmup)
			s->samples_ms[k - s->warmup] = (t1 - t0) * 1e3;
	}
	return 0;
}

