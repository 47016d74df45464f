/* bvhlab build: one plugin on one scene, validated and measured. */
#include <getopt.h>
#include <stdio.h>
#include <stdlib.h>

#include "cli.h"
#include "harness/harness_measure.h"
#include "harness/isolate.h"
#include "harness/harness_series.h"
#include "util/util.h"

#define MAX_OPTIONS 64

static const char usage[] =
	"usage: bvhlab build PLUGIN SCENE [options]\n"
	"\n"
	"Builds one tree with PLUGIN (a name on the search path or a .so path) over\n"
	"SCENE (a mesh file or a generator spec, see `bvhlab info --help`), validates\n"
	"it (structure, and rays against brute force) and prints its metrics.\n"
	"\n"
	"options:\n"
	"  --threads N      threads for the builder (default 1; 0 = all cores)\n"
	"  -o KEY=VALUE     a builder option (repeatable; `bvhlab list` shows them)\n"
	"  --repeat N       timed builds (default 1, after one warm-up build, which\n"
	"                   is timed apart as the cold build)\n"
	"  --subdivide K    split every scene triangle into 4, K times\n"
	"  --rays N         rays for the brute-force check (default 256, 0 = none)\n"
	"  --refine PLUGIN  a refinement stage after each build (repeatable, applied\n"
	"                   in order; timed apart, SAH before and after printed)\n"
	"  -R KEY=VALUE     an option of the last --refine stage (repeatable)\n"
	"\n"
	"The plugin is loaded and run in a child process, as `bvhlab run` does: one\n"
	"that crashes, exits or throws (a C++ static constructor) is exit status 1.\n"
	"\n"
	"exit status: 0 valid tree, 1 build failed, crashed or tree invalid, 2 bad\n"
	"arguments.\n";

struct build_args {
	unsigned long threads, repeat, subdivide, rays;
	const char *options[MAX_OPTIONS];
	int option_count;
	const char *refine[HARNESS_MAX_STAGES];
	int refine_count;
	const char *refine_options[MAX_OPTIONS];
	int refine_option_stage[MAX_OPTIONS]; /* which stage each -R is for */
	int refine_option_count;
};

/* --refine and -R; -1 when there are too many or -R has no stage. */
static int parse_refine(int c, struct build_args *a)
{
	if (c == 'f' && a->refine_count < HARNESS_MAX_STAGES) {
		a->refine[a->refine_count++] = optarg;
		return 0;
	}
	if (c == 'R' && a->refine_count > 0 && a->refine_option_count < MAX_OPTIONS) {
		a->refine_option_stage[a->refine_option_count] = a->refine_count - 1;
		a->refine_options[a->refine_option_count++] = optarg;
		return 0;
	}
	fprintf(stderr, "bvhlab build: %s\n", c == 'f' ? "too many --refine stages"
	                                                : "-R needs a --refine before it");
	return -1;
}

static int parse(int argc, char **argv, struct build_args *a)
{
	static const struct option longopts[] = {
		{"threads", required_argument, NULL, 't'},   {"repeat", required_argument, NULL, 'r'},
		{"subdivide", required_argument, NULL, 's'}, {"rays", required_argument, NULL, 'y'},
		{"refine", required_argument, NULL, 'f'},
		{"help", no_argument, NULL, 'h'},            {NULL, 0, NULL, 0}};
	int c, r = 0;
	while (r == 0 && (c = getopt_long(argc, argv, "ho:R:", longopts, NULL)) != -1) {
		if (c == 'h')
			exit((fputs(usage, stdout), 0));
		else if (c == 't')
			r = cli_parse_uint("--threads", optarg, 4096, &a->threads);
		else if (c == 'r')
			r = cli_parse_uint("--repeat", optarg, 100000, &a->repeat);
		else if (c == 's')
			r = cli_parse_uint("--subdivide", optarg, 8, &a->subdivide);
		else if (c == 'y')
			r = cli_parse_uint("--rays", optarg, 1u << 20, &a->rays);
		else if (c == 'o' && a->option_count < MAX_OPTIONS)
			a->options[a->option_count++] = optarg;
		else if (c == 'f' || c == 'R')
			r = parse_refine(c, a);
		else
			r = -1;
	}
	if (r == 0 && optind != argc - 2) {
		fprintf(stderr, "bvhlab build: expected PLUGIN and SCENE\n\n%s", usage);
		r = -1;
	}
	return r;
}

static void print_stats(const bvhlab_tree_stats *st)
{
	printf("nodes:      %u (%u leaves)\nmax depth:  %u\navg leaf:   %.3f\nrefs:       %llu\n"
	       "SAH cost:   %.4f\nmemory:     %llu bytes\nleaf sizes:",
	       st->nodes, st->leaves, st->max_depth, st->avg_leaf_size,
	       (unsigned long long)st->refs, st->sah_cost,
	       (unsigned long long)st->memory_bytes);
	for (int k = 0; k < BVHLAB_LEAF_HISTOGRAM; k++)
		if (st->leaf_histogram[k])
			printf(" %s%d:%u", k == BVHLAB_LEAF_HISTOGRAM - 1 ? ">" : "",
			       k == BVHLAB_LEAF_HISTOGRAM - 1 ? k : k + 1, st->leaf_histogram[k]);
	printf("\n");
}

/* Measures the tree as a sweep's run does and prints; the exit status. */
static int check(const bvhlab_scene *scene, const bvhlab_prims *prims, const bvhlab_builder *b,
                 const bvhlab_tree *tree, unsigned long rays)
{
	bvhlab_error err = {{0}};
	struct tree_measure m;
	bool dup = b->flags & BVHLAB_BUILDER_SPATIAL_SPLITS;
	enum tree_verdict v = harness_measure_tree(tree, scene, &prims->input, dup, (uint32_t)rays,
	                                           &m, &err);
	if (v == TREE_FAILED) {
		fprintf(stderr, "bvhlab: %s\n", err.message);
		return EXIT_RUNS_FAILED;
	}
	if (!m.valid && !m.mismatches) {
		printf("valid:      NO: %s\n", err.message);
		return EXIT_RUNS_FAILED;
	}
	printf("valid:      %s (structure; %llu of %lu rays disagree with brute force)\n",
	       m.mismatches ? "NO" : "yes", (unsigned long long)m.mismatches, rays);
	print_stats(&m.stats);
	if (m.has_epo)
		printf("EPO:        %.4f\n", m.epo);
	return v == TREE_OK ? 0 : EXIT_RUNS_FAILED;
}

/* The refinement stages of --refine, with their -R options. */
struct stages {
	bvhlab_plugin *plugin[HARNESS_MAX_STAGES];
	bvhlab_options opts[HARNESS_MAX_STAGES];
	struct refine_stage stage[HARNESS_MAX_STAGES];
	struct stage_metrics out[HARNESS_MAX_STAGES];
	int count;
};

static void stages_close(struct stages *st)
{
	for (int k = 0; k < st->count; k++) {
		if (st->opts[k].values)
			bvhlab_options_finish(&st->opts[k]);
		bvhlab_plugin_close(st->plugin[k]);
	}
}

static int stages_open(struct stages *st, const struct build_args *a, bvhlab_error *err)
{
	for (int k = 0; k < a->refine_count; k++) {
		st->count = k + 1;
		if (bvhlab_plugin_open(a->refine[k], &st->plugin[k], err) < 0 ||
		    bvhlab_options_init(&st->opts[k], bvhlab_plugin_builder(st->plugin[k])) < 0)
			return -1;
		for (int j = 0; j < a->refine_option_count; j++)
			if (a->refine_option_stage[j] == k &&
			    bvhlab_options_parse(&st->opts[k], a->refine_options[j], err) < 0)
				return -1;
		if (bvhlab_options_check(&st->opts[k], err) < 0)
			return -1;
		st->stage[k] = (struct refine_stage){.plugin = st->plugin[k], .opts = &st->opts[k]};
	}
	return 0;
}

static void print_stages(const struct stages *st)
{
	for (int k = 0; k < st->count; k++)
		printf("refine:     %s %.3f ms median, SAH %.4f -> %.4f\n", st->out[k].plugin,
		       st->out[k].ms, st->out[k].sah_before, st->out[k].sah_after);
}

static void print_phases(const struct build_series *s)
{
	for (uint32_t k = 0; k < s->phase_count; k++)
		printf("phase:      %s %.3f ms median\n", s->phases[k].name, s->phases[k].ms);
}

static int build_and_check(bvhlab_plugin *p, const bvhlab_options *opts,
                           const bvhlab_scene *scene, const struct build_args *a)
{
	bvhlab_prims prims = {0};
	bvhlab_error err = {{0}};
	double samples[a->repeat];
	struct stages st = {0};
	struct build_series s = {.warmup = 1, .repeat = (uint32_t)a->repeat,
	                         .threads = (uint32_t)a->threads, .samples_ms = samples,
	                         .stages = st.stage, .stage_count = (uint32_t)a->refine_count,
	                         .stage_out = st.out};
	int status = EXIT_RUNS_FAILED;
	if (stages_open(&st, a, &err) < 0 || bvhlab_prims_init(&prims, scene, &err) < 0 ||
	    harness_time_builds(p, opts, &prims.input, &s, &err) < 0) {
		fprintf(stderr, "bvhlab: %s\n", err.message);
		goto out;
	}
	double med, mn, mx;
	util_summarise(samples, s.repeat, &med, &mn, &mx);
	printf("builder:    %s, %u thread(s)\nscene:      %s, %u triangles\n"
	       "build:      %.3f ms median (min %.3f, max %.3f, %u timed), %.2f Mtris/s\n"
	       "cold:       %.3f ms (the first build: fresh output and scratch)\n",
	       bvhlab_plugin_builder(p)->name, s.threads,
	       scene->name, scene->triangle_count, med, mn, mx, s.repeat,
	       scene->triangle_count / (med * 1e3), s.cold_ms);
	print_phases(&s);
	print_stages(&st);
	status = check(scene, &prims, bvhlab_plugin_builder(p), &s.tree, a->rays);
out:
	bvhlab_tree_finish(&s.tree);
	bvhlab_prims_finish(&prims);
	stages_close(&st);
	return status;
}

struct build_job {
	const struct build_args *a;
	const char *plugin, *scene;
};

/* Everything that touches the plugin, from loading it: in a child. */
static void build_work(void *arg, void *report, size_t size)
{
	const struct build_job *job = arg;
	struct cli_target t;
	int status = EXIT_USAGE;
	(void)size;
	if (cli_target_open(&t, job->plugin, job->scene, (unsigned)job->a->subdivide,
	                    job->a->options, job->a->option_count) == 0) {
		status = build_and_check(t.plugin, &t.opts, t.scene, job->a);
		cli_target_close(&t);
	}
	fflush(stdout); /* the child leaves without flushing */
	*(int *)report = status;
}

int cmd_build(int argc, char **argv)
{
	struct build_args a = {.threads = 1, .repeat = 1, .rays = 256};
	int r = parse(argc, argv, &a);
	if (r < 0 || a.repeat == 0)
		return EXIT_USAGE;
	/* Resolved once: the build and what is printed use this count. */
	a.threads = a.threads ? a.threads : bvhlab_hardware_threads();
	/* As a sweep's runs: a plugin that crashes (loading, say: a C++ static
	 * constructor that throws) or exits is an exit status of 1, not its own. */
	struct build_job job = {.a = &a, .plugin = argv[optind], .scene = argv[optind + 1]};
	struct isolate_limits none = {.timeout_s = 1e9};
	char why[512] = "";
	int status = EXIT_RUNS_FAILED;
	r = isolate_call(build_work, &job, &status, sizeof(status), &none, why, sizeof(why));
	if (r == ISOLATE_REPORTED && status >= 0 && status <= EXIT_USAGE)
		return status;
	fprintf(stderr, "bvhlab: plugin '%s' on %s: %s\n", job.plugin, job.scene,
	        r == ISOLATE_REPORTED ? "sent back a malformed status" : why);
	return EXIT_RUNS_FAILED;
}
