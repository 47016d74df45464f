/*
 * The single-ray benches' common part (rays_bench.h). A round traces the
 * whole batch PASSES times in a row per tracer, timed on the thread's CPU
 * clock (what the harness reports) and the wall clock; the core's passes
 * go through bvhlab_trace_measure, as the harness's do. A round's figure
 * is the median of its passes, so the first pass, cold after the other
 * tracers ran, is left out; the medians over rounds are printed. Both
 * clocks' figures come from the same passes: a burst of load from
 * elsewhere stretches the wall clock only. Ratios under load are still
 * not to be trusted: measure on a quiet machine.
 */
#include <errno.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <time.h>

#include "rays_bench.h"
#include "trace/trace_batch.h"
#include "trace/trace_wide8.h"
#include "util/util.h"

#define MAX_SAMPLES 4096
#define MIN_ROUNDS 5
#define PASSES 3
#define DIFFUSE_SEED 0xd1ff05eULL

/* The core's CPU traversals, in the order printed. */
static const int ours[] = {BVHLAB_TRAVERSAL_STACK, BVHLAB_TRAVERSAL_STACKLESS,
                           BVHLAB_TRAVERSAL_WIDE, BVHLAB_TRAVERSAL_WIDE4,
                           BVHLAB_TRAVERSAL_WIDE8};
#define OURS (sizeof(ours) / sizeof(ours[0]))
#define TRACERS (1 + OURS) /* the peer, then ours */

int rb_parse(int argc, char **argv, const char *prog, struct rb_args *a)
{
	*a = (struct rb_args){.builder = "sah_seq", .size = 512, .min_ms = 1000};
	for (int i = 1; i < argc; i++) {
		bool v = i + 1 < argc;
		if (strcmp(argv[i], "--subdivide") == 0 && v)
			a->subdivide = (unsigned)atoi(argv[++i]);
		else if (strcmp(argv[i], "--size") == 0 && v)
			a->size = (uint32_t)atoi(argv[++i]);
		else if (strcmp(argv[i], "--min-ms") == 0 && v)
			a->min_ms = atof(argv[++i]);
		else if (strcmp(argv[i], "--builder") == 0 && v)
			a->builder = argv[++i];
		else if (strcmp(argv[i], "--refine") == 0 && v)
			a->refine = argv[++i];
		else if (strcmp(argv[i], "--count") == 0)
			a->count = true;
		else if (argv[i][0] != '-' && !a->scene)
			a->scene = argv[i];
		else
			a->scene = NULL, i = argc;
	}
	if (a->scene && a->size > 0)
		return 0;
	fprintf(stderr, "usage: %s SCENE [--subdivide K] [--size N] [--min-ms MS] "
	                "[--builder PLUGIN] [--refine PLUGIN[:KEY=VALUE,...]] [--count]\n", prog);
	return -EINVAL;
}

/* "PLUGIN:k=v,k=v" into a plugin name (buf) and its options. */
static int stage_options(const char *spec, char *name, size_t size, const bvhlab_plugin **p,
                         bvhlab_plugin **open, bvhlab_options *opts, bvhlab_error *err)
{
	const char *colon = strchr(spec, ':');
	snprintf(name, size, "%.*s", colon ? (int)(colon - spec) : (int)strlen(spec), spec);
	int r = bvhlab_plugin_open(name, open, err);
	if (r == 0)
		r = bvhlab_options_init(opts, bvhlab_plugin_builder(*open));
	*p = *open;
	for (const char *item = colon ? colon + 1 : NULL; r == 0 && item && *item;) {
		char one[128];
		size_t n = strcspn(item, ",");
		snprintf(one, sizeof(one), "%.*s", (int)n, item);
		r = bvhlab_options_parse(opts, one, err);
		item += n + (item[n] == ',');
	}
	return r;
}

/* The builder's tree, then the refinement stage's, if any. */
static int make_tree(const struct rb_args *a, const bvhlab_scene *s, bvhlab_tree *tree,
                     bvhlab_error *err)
{
	char name[64];
	const bvhlab_plugin *p;
	bvhlab_plugin *open[2] = {NULL, NULL};
	bvhlab_options opts[2] = {{0}, {0}};
	bvhlab_prims prims = {0};
	int r = stage_options(a->builder, name, sizeof(name), &p, &open[0], &opts[0], err);
	if (r == 0)
		r = bvhlab_prims_init(&prims, s, err);
	if (r == 0)
		r = bvhlab_build(p, &opts[0], &prims.input, 1, tree, err);
	if (r == 0 && a->refine)
		r = stage_options(a->refine, name, sizeof(name), &p, &open[1], &opts[1], err);
	if (r == 0 && a->refine)
		r = bvhlab_refine(p, &opts[1], &prims.input, 1, tree, err);
	bvhlab_prims_finish(&prims);
	for (int i = 0; i < 2; i++) {
		if (opts[i].values)
			bvhlab_options_finish(&opts[i]);
		bvhlab_plugin_close(open[i]);
	}
	return r;
}

/* Primary rays, and one diffuse bounce per hit of the stack traversal's. */
static int make_rays(const struct rb_args *a, struct rb_setup *s)
{
	bvhlab_camera cam;
	bvhlab_camera_frame(&s->scene->bounds, &cam);
	s->count[0] = (size_t)a->size * a->size;
	int r = bvhlab_rays_primary(&cam, a->size, a->size, &s->rays[0]);
	bvhlab_hit *h = r == 0 ? malloc(s->count[0] * sizeof(*h)) : NULL;
	if (r == 0 && !h)
		r = -ENOMEM;
	if (r == 0)
		r = bvhlab_trace_batch(&s->tree, s->scene, s->rays[0], s->count[0], false, 1, h, NULL,
		                       NULL, NULL);
	if (r == 0)
		r = bvhlab_rays_diffuse(s->scene, s->rays[0], h, s->count[0], 1, DIFFUSE_SEED,
		                        &s->rays[1], &s->count[1]);
	free(h);
	return r;
}

int rb_setup_init(const struct rb_args *a, struct rb_setup *s, bvhlab_error *err)
{
	memset(s, 0, sizeof(*s));
	int r = bvhlab_scene_load(a->scene, &s->scene, err);
	if (r == 0 && a->subdivide)
		r = bvhlab_scene_subdivide(s->scene, a->subdivide, err);
	if (r == 0)
		r = make_tree(a, s->scene, &s->tree, err);
	if (r == 0 && (r = make_rays(a, s)) < 0)
		error_set(err, "rays: %s", strerror(-r));
	return r;
}

void rb_setup_finish(struct rb_setup *s)
{
	for (int k = 0; k < RB_KINDS; k++)
		free(s->rays[k]);
	bvhlab_tree_finish(&s->tree);
	bvhlab_scene_destroy(s->scene);
	memset(s, 0, sizeof(*s));
}

static int cmp_double(const void *a, const void *b)
{
	double x = *(const double *)a, y = *(const double *)b;
	return (x > y) - (x < y);
}

static double median(double *s, size_t n)
{
	qsort(s, n, sizeof(*s), cmp_double);
	return n % 2 ? s[n / 2] : 0.5 * (s[n / 2 - 1] + s[n / 2]);
}

static double cpu_now(void)
{
	struct timespec c;
	clock_gettime(CLOCK_THREAD_CPUTIME_ID, &c);
	return (double)c.tv_sec + 1e-9 * (double)c.tv_nsec;
}

/* One tracer on one kind of rays: a median per round, on each clock. */
struct tracer {
	double cpu[MAX_SAMPLES], wall[MAX_SAMPLES];
	double mrays[2]; /* medians over rounds: thread CPU time, wall clock */
	size_t hits;
	double nodes, tris; /* per ray, the core's traversals only: for the wide
	                     * ones the stack traversal's (bvhlab_trace_measure);
	                     * --count gives their own */
};

static double rate(size_t n, double seconds)
{
	return seconds > 0 ? (double)n / seconds * 1e-6 : 0;
}

static void peer_round(rb_pass_fn *pass, void *peer, const bvhlab_ray *rays, size_t n,
                       struct tracer *t, size_t round)
{
	double cpu[PASSES], wall[PASSES];
	for (int i = 0; i < PASSES; i++) {
		double w0 = util_now(), c0 = cpu_now();
		t->hits = pass(peer, rays, n);
		cpu[i] = rate(n, cpu_now() - c0);
		wall[i] = rate(n, util_now() - w0);
	}
	t->cpu[round] = median(cpu, PASSES);
	t->wall[round] = median(wall, PASSES);
}

static bool ours_round(const struct rb_setup *s, int kind, int k, bvhlab_hit *h,
                       struct tracer *t, size_t round)
{
	bvhlab_trace_options o = {.traversal = k, .threads = 1, .min_repeats = PASSES,
	                          .max_repeats = PASSES};
	bvhlab_trace_timing tm;
	size_t n = s->count[kind];
	if (bvhlab_trace_measure(&s->tree, s->scene, s->rays[kind], n, &o, h, NULL, &tm) < 0)
		return false;
	t->cpu[round] = tm.mrays_median;
	t->wall[round] = tm.wall_mrays_median;
	double rays = tm.stats.rays ? (double)tm.stats.rays : 1;
	t->nodes = (double)tm.stats.nodes_visited / rays;
	t->tris = (double)tm.stats.tris_tested / rays;
	t->hits = 0;
	for (size_t i = 0; i < n; i++)
		t->hits += h[i].prim != BVHLAB_NO_HIT;
	return true;
}

static void print_kind(const struct rb_args *a, const struct rb_setup *s, int kind, int clock,
                       const char *peer, const struct tracer *t)
{
	printf("scene %s (%u triangles), %zu %s rays, 1 thread, %s\n", s->scene->name,
	       s->scene->triangle_count, s->count[kind], kind ? "diffuse" : "primary",
	       clock ? "wall clock" : "thread CPU time");
	printf("  %s: %.2f Mrays/s (%zu hits)\n", peer, t[0].mrays[clock], t[0].hits);
	for (size_t k = 1; k < TRACERS; k++)
		printf("  bvhlab %s%s%s tree (width %u), %s traversal: %.2f Mrays/s (%zu hits, %.2f "
		       "nodes/ray, %.2f triangles/ray), ratio to %s %.2f\n", a->builder,
		       a->refine ? " + " : "", a->refine ? a->refine : "",
		       s->tree.width > 2 ? s->tree.width : 2, bvhlab_traversal_name(ours[k - 1]),
		       t[k].mrays[clock], t[k].hits, t[k].nodes, t[k].tris, peer,
		       t[0].mrays[clock] > 0 ? t[k].mrays[clock] / t[0].mrays[clock] : 0);
}

/* The wide copy's size, printed once per traversal. */
static void print_view(const struct trace_view *v)
{
	if (v->wide8)
		printf("    its copy: %u 8-lane nodes, %u triangle groups, depth %u, %.1f MB\n",
		       v->wide8->node_count, v->wide8->tri_groups, v->wide8->depth,
		       1e-6 * ((double)v->wide8->node_count * sizeof(struct wide8_node) +
		               (double)v->wide8->tri_groups * sizeof(struct wide8_tris)));
	else if (v->wide)
		printf("    its copy: %u 4-lane nodes, %u triangle groups, depth %u, %.1f MB\n",
		       v->wide->node_count, v->wide->tri_groups, v->wide->depth,
		       1e-6 * ((double)v->wide->node_count * sizeof(struct wide_node) +
		               (double)v->wide->tri_groups * sizeof(struct wide_tris)));
}

/* One untimed pass of core traversal k over its own tracing copies (the
 * batch tracer's, one thread): its hits and its own counters printed. */
static void count_pass(const struct rb_args *a, const struct rb_setup *s, int kind, int k)
{
	struct batch b = {.tree = &s->tree, .scene = s->scene, .rays = s->rays[kind],
	                  .count = s->count[kind], .traversal = k};
	struct worker w = {0};
	bvhlab_hit *h = malloc(b.count * sizeof(*h));
	uint32_t *parents = NULL;
	size_t hits = 0;
	atomic_init(&b.next, 0);
	int r = h ? trace_view_copy(b.tree, b.scene, &b.view) : -ENOMEM;
	if (r == 0 && k == BVHLAB_TRAVERSAL_STACKLESS)
		r = bvhlab_tree_parents(b.tree, &parents);
	b.view.parents = parents;
	if (r == 0 && trace_is_wide(k))
		r = trace_view_wide(b.tree, b.scene, k, &b.view);
	b.hits = h;
	if (r == 0)
		trace_run_workers(&b, &w, 1);
	for (size_t i = 0; r == 0 && i < b.count; i++)
		hits += h[i].prim != BVHLAB_NO_HIT;
	double rays = w.stats.rays ? (double)w.stats.rays : 1;
	printf("  bvhlab %s%s%s, %s traversal: %zu hits, %.2f nodes/ray, %.2f triangles/ray (its "
	       "own)\n", a->builder, a->refine ? " + " : "", a->refine ? a->refine : "",
	       bvhlab_traversal_name(k), hits, (double)w.stats.nodes_visited / rays,
	       (double)w.stats.tris_tested / rays);
	if (r == 0 && kind == 0)
		print_view(&b.view);
	trace_view_free(&b.view);
	free(parents);
	free(h);
}

static void rb_count(const struct rb_args *a, const struct rb_setup *s, const char *peer_name,
                     rb_pass_fn *pass, void *peer)
{
	for (int kind = 0; kind < RB_KINDS; kind++) {
		size_t n = s->count[kind];
		printf("scene %s (%u triangles), %zu %s rays, one untimed pass each\n",
		       s->scene->name, s->scene->triangle_count, n, kind ? "diffuse" : "primary");
		printf("  %s: %zu hits\n", peer_name, pass(peer, s->rays[kind], n));
		for (size_t k = 0; k < OURS; k++)
			count_pass(a, s, kind, ours[k]);
	}
}

void rb_run(const struct rb_args *a, const struct rb_setup *s, const char *peer_name,
            rb_pass_fn *pass, void *peer)
{
	if (a->count) {
		rb_count(a, s, peer_name, pass, peer);
		return;
	}
	struct tracer(*t)[TRACERS] = calloc(RB_KINDS, sizeof(*t));
	bvhlab_hit *h = malloc((s->count[0] > s->count[1] ? s->count[0] : s->count[1]) *
	                       sizeof(*h));
	double start = util_now();
	size_t r = 0;
	bool ok = t && h;
	while (ok && r < MAX_SAMPLES && (r < MIN_ROUNDS || util_now() - start < a->min_ms * 1e-3)) {
		for (int kind = 0; ok && kind < RB_KINDS; kind++) {
			peer_round(pass, peer, s->rays[kind], s->count[kind], &t[kind][0], r);
			for (size_t k = 0; ok && k < OURS; k++)
				ok = ours_round(s, kind, ours[k], h, &t[kind][1 + k], r);
		}
		r += ok;
	}
	for (int kind = 0; t && kind < RB_KINDS; kind++)
		for (size_t i = 0; i < TRACERS; i++) {
			t[kind][i].mrays[0] = r ? median(t[kind][i].cpu, r) : 0;
			t[kind][i].mrays[1] = r ? median(t[kind][i].wall, r) : 0;
		}
	for (int clock = 0; t && clock < 2; clock++)
		for (int kind = 0; kind < RB_KINDS; kind++)
			print_kind(a, s, kind, clock, peer_name, t[kind]);
	free(h);
	free(t);
}
