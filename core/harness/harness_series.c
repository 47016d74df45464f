/*
 * The harness's building blocks that the command's other subcommands
 * (build, render) share: loading a config scene and timing a build series.
 */
#include <errno.h>
#include <stdlib.h>
#include <string.h>

#include "harness/harness.h"
#include "util/util.h"

int harness_load_scene(const struct config_scene *cs, bvhlab_scene **out, bvhlab_error *err)
{
	int r = cs->path ? bvhlab_scene_load(cs->path, out, err)
	                 : bvhlab_scene_generate(cs->generator, &cs->gen, out, err);
	if (r < 0)
		return r;
	if (cs->subdivide > 0)
		r = bvhlab_scene_subdivide(*out, cs->subdivide, err);
	if (r == 0 && cs->name)
		r = bvhlab_scene_set_name(*out, cs->name);
	if (r < 0) {
		if (r == -ENOMEM && err && !err->message[0])
			error_set(err, "scene '%s': out of memory", cs->name);
		bvhlab_scene_destroy(*out);
		*out = NULL;
	}
	return r;
}

static int cmp_double(const void *a, const void *b)
{
	double x = *(const double *)a, y = *(const double *)b;
	return (x > y) - (x < y);
}

void harness_summarise(const double *samples, uint32_t n, double *median, double *min,
                       double *max)
{
	double sorted[n ? n : 1];
	memcpy(sorted, samples, n * sizeof(double));
	qsort(sorted, n, sizeof(double), cmp_double);
	*min = n ? sorted[0] : 0;
	*max = n ? sorted[n - 1] : 0;
	*median = n == 0 ? 0 : n % 2 ? sorted[n / 2] : 0.5 * (sorted[n / 2 - 1] + sorted[n / 2]);
}

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

