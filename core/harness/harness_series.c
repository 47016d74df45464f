/*
 * Timing a build series: warm-up builds, then timed ones into the same
 * tree (so room grown once stays allocated), each followed by the
 * builder's refinement stages; `bvhlab build` and the sweep share it.
 */
#include <errno.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "harness/harness_series.h"
#include "util/util.h"

/* The stages after one build: their times into ms[stage * repeat + k]
 * when k is a timed repeat, the SAH around each when `last`. */
static int run_stages(struct build_series *s, const bvhlab_build_input *input, double *ms,
                      int64_t k, bool last, bvhlab_error *err)
{
	bvhlab_tree_stats st;
	for (uint32_t j = 0; j < s->stage_count; j++) {
		struct stage_metrics *out = &s->stage_out[j];
		if (last) {
			bvhlab_tree_stats_compute(&s->tree, &st);
			out->sah_before = st.sah_cost;
		}
		double t0 = util_now();
		int r = bvhlab_refine(s->stages[j].plugin, s->stages[j].opts, input, s->threads,
		                      &s->tree, err);
		double t1 = util_now();
		if (r < 0)
			return r;
		if (k >= 0)
			ms[j * s->repeat + (uint64_t)k] = (t1 - t0) * 1e3;
		if (last) {
			bvhlab_tree_stats_compute(&s->tree, &st);
			out->sah_after = st.sah_cost;
		}
	}
	return 0;
}

/* The phases the build just reported, into column k of ms[phase][repeat];
 * a name not seen in an earlier repeat gets the next row. */
static void take_phases(struct build_series *s, double *ms, uint32_t k)
{
	const bvhlab_tree *t = &s->tree;
	for (uint32_t j = 0; j < t->phase_count; j++) {
		uint32_t row = 0;
		while (row < s->phase_count && strcmp(s->phases[row].name, t->phases[j].name) != 0)
			row++;
		if (row == BVHLAB_MAX_PHASES)
			continue; /* more names over all repeats than one build may report */
		if (row == s->phase_count)
			s->phases[s->phase_count++] = t->phases[j];
		ms[row * s->repeat + k] = t->phases[j].ms;
	}
}

static void phase_medians(struct build_series *s, const double *ms)
{
	for (uint32_t j = 0; j < s->phase_count; j++) {
		double mn, mx;
		util_summarise(ms + (size_t)j * s->repeat, s->repeat, &s->phases[j].ms, &mn, &mx);
	}
}

static void stage_names(struct build_series *s, const double *ms)
{
	for (uint32_t j = 0; j < s->stage_count; j++) {
		struct stage_metrics *out = &s->stage_out[j];
		double mn, mx;
		snprintf(out->plugin, sizeof(out->plugin), "%s",
		         bvhlab_plugin_builder(s->stages[j].plugin)->name);
		util_summarise(ms + (size_t)j * s->repeat, s->repeat, &out->ms, &mn, &mx);
	}
}

int harness_time_builds(const bvhlab_plugin *plugin, const bvhlab_options *opts,
                        const bvhlab_build_input *input, struct build_series *s,
                        bvhlab_error *err)
{
	double *ms = calloc((size_t)s->stage_count * s->repeat + 1, sizeof(*ms));
	double *phase_ms = calloc((size_t)BVHLAB_MAX_PHASES * s->repeat, sizeof(*phase_ms));
	int r = ms && phase_ms ? 0 : -ENOMEM;
	if (r < 0)
		error_set(err, "out of memory for the stage times");
	s->phase_count = 0;
	for (uint32_t k = 0; r == 0 && k < s->warmup + s->repeat; k++) {
		double t0 = util_now();
		r = bvhlab_build(plugin, opts, input, s->threads, &s->tree, err);
		double t1 = util_now(), staged = 0;
		bool last = k + 1 == s->warmup + s->repeat;
		/* Before the stages: a refinement's call starts its own phases. */
		if (r == 0 && k >= s->warmup)
			take_phases(s, phase_ms, k - s->warmup);
		if (r == 0 && s->stage_count) {
			r = run_stages(s, input, ms, (int64_t)k - s->warmup, last, err);
			for (uint32_t j = 0; r == 0 && k >= s->warmup && j < s->stage_count; j++)
				staged += ms[j * s->repeat + (k - s->warmup)];
		}
		/* Like build_ms, the cold figure holds the refine stages too. */
		if (r == 0 && k == 0)
			s->cold_ms = (util_now() - t0) * 1e3;
		if (r == 0 && k >= s->warmup)
			s->samples_ms[k - s->warmup] = (t1 - t0) * 1e3 + staged;
	}
	if (r == 0) {
		stage_names(s, ms);
		phase_medians(s, phase_ms);
	}
	free(ms);
	free(phase_ms);
	return r;
}
