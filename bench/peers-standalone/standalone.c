/*
 * The peer programs' shared part (standalone.h): arguments, the scene, and
 * the timing loop, the same for every library so that only the build call
 * differs between them.
 */
#include "standalone.h"

#include <errno.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <time.h>

#include "util/util.h"

#define MAX_REPEAT 1000

static int usage(const char *prog, const char *variants)
{
	fprintf(stderr, "usage: %s SCENE [--subdivide K] [--threads N] [--repeat N] "
	        "[--warmup N] [--variant %s] [--callbacks tutorial|plugin] [--input once|each]\n", prog, variants);
	return -1;
}

/* The index of `v` among the '|'-separated names in `list`, or -1. */
static int index_in(const char *v, const char *list)
{
	size_t n = strlen(v);
	int k = 0;
	for (const char *p = list; p; p = strchr(p, '|'), p = p ? p + 1 : NULL, k++)
		if (strncmp(p, v, n) == 0 && (p[n] == '|' || p[n] == '\0'))
			return k;
	return -1;
}

static int number(const char *s, unsigned lo, unsigned hi, unsigned *out)
{
	char *end;
	unsigned long v = strtoul(s, &end, 10);
	if (*s == '\0' || *end != '\0' || v < lo || v > hi)
		return -1;
	*out = (unsigned)v;
	return 0;
}

static int parse(int argc, char **argv, const char *variants, const char *def, sa_args *a)
{
	*a = (sa_args){.variant = def, .callbacks = NULL, .input_each = -1, .threads = 1, .repeat = 5,
	               .warmup = 1};
	for (int i = 1; i < argc; i++) {
		const char *k = argv[i], *v = i + 1 < argc ? argv[i + 1] : NULL;
		int bad = 0;
		if (k[0] != '-' && !a->scene) {
			a->scene = k;
			continue;
		}
		if (k[0] != '-' || !v)
			return usage(argv[0], variants);
		i++;
		if (strcmp(k, "--subdivide") == 0)
			bad = number(v, 0, 8, &a->subdivide);
		else if (strcmp(k, "--threads") == 0)
			bad = number(v, 1, 1024, &a->threads);
		else if (strcmp(k, "--repeat") == 0)
			bad = number(v, 1, MAX_REPEAT, &a->repeat);
		else if (strcmp(k, "--warmup") == 0)
			bad = number(v, 0, MAX_REPEAT, &a->warmup);
		else if (strcmp(k, "--variant") == 0)
			bad = index_in(v, variants) < 0, a->variant = v;
		else if (strcmp(k, "--callbacks") == 0)
			bad = index_in(v, "tutorial|plugin") < 0, a->callbacks = v;
		else if (strcmp(k, "--input") == 0)
			a->input_each = index_in(v, "once|each"), bad = a->input_each < 0;
		else
			bad = 1;
		if (bad)
			return usage(argv[0], variants);
	}
	a->which = index_in(a->variant, variants);
	return a->scene ? 0 : usage(argv[0], variants);
}

int sa_start(int argc, char **argv, const char *variants, const char *def, sa_args *a,
             bvhlab_scene **scene)
{
	bvhlab_error err;
	*scene = NULL;
	if (parse(argc, argv, variants, def, a) < 0)
		return 2;
	int rc = bvhlab_scene_load(a->scene, scene, &err);
	if (rc == 0 && a->subdivide)
		rc = bvhlab_scene_subdivide(*scene, a->subdivide, &err);
	if (rc == 0)
		return 0;
	fprintf(stderr, "%s\n", err.message);
	bvhlab_scene_destroy(*scene);
	*scene = NULL;
	return 1;
}

static double cpu_ms(void)
{
	struct timespec ts;
	clock_gettime(CLOCK_PROCESS_CPUTIME_ID, &ts);
	return ts.tv_sec * 1e3 + ts.tv_nsec * 1e-6;
}

int sa_time(const char *lib, const sa_args *a, sa_step prepare, sa_step build, void *user)
{
	double wall[MAX_REPEAT], cpu[MAX_REPEAT];
	for (unsigned i = 0; i < a->warmup + a->repeat; i++) {
		int rc = prepare ? prepare(user) : 0;
		double w0 = util_now_ms(), c0 = cpu_ms();
		if (rc == 0)
			rc = build(user);
		double w1 = util_now_ms(), c1 = cpu_ms();
		if (rc < 0) {
			fprintf(stderr, "%s %s: build failed (%s)\n", lib, a->variant, strerror(-rc));
			return rc;
		}
		if (i >= a->warmup)
			wall[i - a->warmup] = w1 - w0, cpu[i - a->warmup] = c1 - c0;
	}
	double wmed, wmin, wmax, cmed, cmin, cmax;
	util_summarise(wall, a->repeat, &wmed, &wmin, &wmax);
	util_summarise(cpu, a->repeat, &cmed, &cmin, &cmax);
	printf("%s %s%s%s threads=%u wall_ms=%.3f cpu_ms=%.3f min_ms=%.3f repeats=%u\n", lib,
	       a->variant, a->callbacks ? " callbacks=" : "", a->callbacks ? a->callbacks : "",
	       a->threads, wmed, cmed, wmin, a->repeat);
	return 0;
}
