/* Argument helpers shared by the subcommands. */
#include <errno.h>
#include <stdbool.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>

#include "cli.h"
#include "config/config.h"
#include "harness/harness_scene.h"

int cli_parse_uint(const char *opt, const char *text, unsigned long max, unsigned long *out)
{
	char *end = NULL;
	errno = 0;
	unsigned long v = strtoul(text, &end, 10);
	if (!*text || *end || errno || v > max || text[0] == '-') {
		fprintf(stderr, "bvhlab: %s needs an integer in [0, %lu], not '%s'\n", opt, max, text);
		return -EINVAL;
	}
	*out = v;
	return 0;
}

int cli_parse_threads(const char *text, uint32_t *out, size_t max, size_t *count)
{
	*count = 0;
	for (const char *p = text; *p;) {
		char *end = NULL;
		errno = 0;
		unsigned long v = strtoul(p, &end, 10);
		if (end != p && !errno && *p != '-' && v > CONFIG_MAX_THREADS) {
			fprintf(stderr, "bvhlab: --threads: %.*s is more than the limit of %d threads\n",
			        (int)strcspn(p, ","), p, CONFIG_MAX_THREADS);
			return -EINVAL;
		}
		if (end == p || errno || (*end && *end != ',') || *count == max || *p < '0' ||
		    *p > '9') {
			fprintf(stderr, "bvhlab: --threads needs a list like 1,2,0 (0 = all "
			                "cores, at most %zu entries), not '%s'\n", max, text);
			return -EINVAL;
		}
		for (size_t k = 0; k < *count; k++)
			if (out[k] == v) {
				fprintf(stderr, "bvhlab: --threads: duplicate thread count %lu\n", v);
				return -EINVAL;
			}
		out[(*count)++] = (uint32_t)v;
		p = *end ? end + 1 : end;
	}
	if (*count == 0) {
		fprintf(stderr, "bvhlab: --threads needs at least one thread count\n");
		return -EINVAL;
	}
	return 0;
}

/* "width=X" (needles), the one generator parameter that is not an integer. */
static int gen_width(bvhlab_gen_params *g, const char *kv, bvhlab_error *err)
{
	char *end = NULL;
	double v = strtod(kv + 6, &end);
	if (end == kv + 6 || (*end && *end != ',') || !(v > 0.0)) {
		snprintf(err->message, sizeof(err->message),
		         "bad generator parameter '%.*s' (width needs a number > 0)",
		         (int)strcspn(kv, ","), kv);
		return -EINVAL;
	}
	g->width = v;
	return 0;
}

/* "key=value" of a generator spec into params. */
static int gen_param(bvhlab_gen_params *g, const char *kv, bvhlab_error *err)
{
	if (strncmp(kv, "width=", 6) == 0)
		return gen_width(g, kv, err);
	static const char *keys[] = {"frequency", "count", "size", "seed"};
	const char *eq = strchr(kv, '=');
	char *end = NULL;
	/* strtoull takes "-1" (as 2^64 - 1) and leading blanks: digits only. */
	bool digits = eq && eq[1] >= '0' && eq[1] <= '9';
	unsigned long long v = digits ? strtoull(eq + 1, &end, 10) : 0;
	for (int k = 0; eq && k < 4; k++) {
		if (strncmp(kv, keys[k], (size_t)(eq - kv)) || strlen(keys[k]) != (size_t)(eq - kv))
			continue;
		if (!digits || (end && *end && *end != ',') || (k < 3 && v > UINT32_MAX))
			break;
		uint32_t *fields[] = {&g->frequency, &g->count, &g->size};
		if (k < 3)
			*fields[k] = (uint32_t)v;
		else
			g->seed = v;
		return 0;
	}
	snprintf(err->message, sizeof(err->message),
	         "bad generator parameter '%.*s' (known: frequency, count, size, seed, width, as key=N)",
	         (int)strcspn(kv, ","), kv);
	return -EINVAL;
}

static bool is_generator_spec(const char *spec)
{
	struct stat st;
	if (stat(spec, &st) == 0 || strchr(spec, '/'))
		return false;
	return !strchr(spec, '.') || strchr(spec, ':');
}

/* "CONFIG.json:NAME": the scene NAME of an experiment config (composites too). */
static int load_config_scene(const char *spec, const char *colon, unsigned subdivide,
                             bvhlab_scene **out, bvhlab_error *err)
{
	struct config cfg;
	char *path = strndup(spec, (size_t)(colon - spec));
	int r = path ? config_load(&cfg, path, err) : -ENOMEM;
	free(path);
	if (r < 0)
		return r;
	r = -ENOENT;
	snprintf(err->message, sizeof(err->message), "%s: no scene named '%s'", cfg.path,
	         colon + 1);
	for (size_t i = 0; i < cfg.scene_count; i++) {
		struct config_scene cs = cfg.scenes[i];
		if (strcmp(cs.name, colon + 1) != 0)
			continue;
		cs.subdivide += subdivide;
		err->message[0] = '\0';
		r = harness_load_scene(&cs, out, err);
		break;
	}
	config_finish(&cfg);
	return r;
}

int cli_load_scene(const char *spec, unsigned subdivide, bvhlab_scene **out, bvhlab_error *err)
{
	struct config_scene cs = {.subdivide = subdivide};
	const char *json = strstr(spec, ".json:");
	char name[64];
	if (json)
		return load_config_scene(spec, json + 5, subdivide, out, err);
	bvhlab_gen_params_init(&cs.gen);
	if (!is_generator_spec(spec)) {
		cs.path = (char *)spec;
		return harness_load_scene(&cs, out, err);
	}
	size_t len = strcspn(spec, ":");
	snprintf(name, sizeof(name), "%.*s", (int)len, spec);
	for (const char *p = spec[len] ? spec + len + 1 : ""; *p;) {
		int r = gen_param(&cs.gen, p, err);
		if (r < 0)
			return r;
		p += strcspn(p, ",");
		p += *p == ',';
	}
	cs.generator = name;
	return harness_load_scene(&cs, out, err);
}

int cli_target_open(struct cli_target *t, const char *plugin, const char *scene,
                    unsigned subdivide, const char *const *options, int option_count)
{
	bvhlab_error err = {{0}};
	*t = (struct cli_target){0};
	if (bvhlab_plugin_open(plugin, &t->plugin, &err) < 0 ||
	    bvhlab_options_init(&t->opts, bvhlab_plugin_builder(t->plugin)) < 0)
		goto fail;
	for (int k = 0; k < option_count; k++)
		if (bvhlab_options_parse(&t->opts, options[k], &err) < 0)
			goto fail;
	if (bvhlab_options_check(&t->opts, &err) < 0)
		goto fail;
	if (cli_load_scene(scene, subdivide, &t->scene, &err) < 0)
		goto fail;
	return 0;
fail:
	fprintf(stderr, "bvhlab: %s\n", err.message[0] ? err.message : "out of memory");
	cli_target_close(t);
	return -1;
}

void cli_target_close(struct cli_target *t)
{
	bvhlab_scene_destroy(t->scene);
	if (t->opts.values)
		bvhlab_options_finish(&t->opts);
	bvhlab_plugin_close(t->plugin);
	*t = (struct cli_target){0};
}
