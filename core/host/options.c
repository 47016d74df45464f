/*
 * Builder options: values checked against the plugin's declarations.
 * The plugin only ever sees declared names with values of the declared
 * type, in range, so its getters cannot fail on a valid config.
 */
#include <errno.h>
#include <inttypes.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include <bvhlab/host.h>

#include "host/options_fill.h"
#include "util/util.h"

static const char *type_name(uint32_t type)
{
	switch (type) {
	case BVHLAB_OPTION_BOOL:
		return "a boolean";
	case BVHLAB_OPTION_INT:
		return "an integer";
	case BVHLAB_OPTION_FLOAT:
		return "a number";
	case BVHLAB_OPTION_STRING:
		return "a string";
	}
	return "of an unknown type";
}

int bvhlab_options_init(bvhlab_options *opts, const bvhlab_builder *builder)
{
	opts->builder = builder;
	opts->filled = NULL;
	opts->values = calloc(builder->option_count ? builder->option_count : 1,
	                      sizeof(*opts->values));
	if (!opts->values)
		return -ENOMEM;
	for (uint32_t k = 0; k < builder->option_count; k++) {
		const bvhlab_option_decl *d = &builder->options[k];
		bvhlab_option_value *v = &opts->values[k];
		v->type = d->type;
		v->b = d->def_bool;
		v->i = d->def_int;
		v->f = d->type == BVHLAB_OPTION_INT ? (double)d->def_int : d->def_float;
		if (d->type == BVHLAB_OPTION_STRING && d->def_string) {
			v->s = strdup(d->def_string);
			if (!v->s) {
				bvhlab_options_finish(opts);
				return -ENOMEM;
			}
		}
	}
	return 0;
}

/* A set value makes the plugin's struct stale: bvhlab_options_check fills it anew. */
static void drop_filled(bvhlab_options *opts)
{
	free(opts->filled);
	opts->filled = NULL;
}

void bvhlab_options_finish(bvhlab_options *opts)
{
	drop_filled(opts);
	if (!opts->values)
		return;
	for (uint32_t k = 0; k < opts->builder->option_count; k++)
		free(opts->values[k].s);
	free(opts->values);
	opts->values = NULL;
}

int bvhlab_options_find(const bvhlab_options *opts, const char *name)
{
	for (uint32_t k = 0; k < opts->builder->option_count; k++)
		if (strcmp(opts->builder->options[k].name, name) == 0)
			return (int)k;
	return -1;
}

/* Finds `key` declared with `type`, or explains why not. */
static int lookup(const bvhlab_options *opts, const char *key, uint32_t type,
                  bvhlab_error *err)
{
	const bvhlab_builder *b = opts->builder;
	int k = bvhlab_options_find(opts, key);
	if (k < 0) {
		char known[256] = "";
		size_t used = 0;
		for (uint32_t i = 0; i < b->option_count && used < sizeof(known); i++)
			used += (size_t)snprintf(known + used, sizeof(known) - used, "%s%s",
			                         i ? ", " : "", b->options[i].name);
		error_set(err, "unknown option '%s' for plugin '%s' (known: %s)", key,
		                 b->name, b->option_count ? known : "none");
		return -ENOENT;
	}
	if (b->options[k].type != type) {
		error_set(err, "option '%s' of plugin '%s' must be %s", key, b->name,
		                 type_name(b->options[k].type));
		return -EINVAL;
	}
	return k;
}

static bool has_range(const bvhlab_option_decl *d)
{
	return d->min <= d->max;
}

static int check_range(const bvhlab_options *opts, int k, double v, bvhlab_error *err)
{
	const bvhlab_option_decl *d = &opts->builder->options[k];
	if (!has_range(d) || (v >= d->min && v <= d->max))
		return 0;
	error_set(err, "option '%s' of plugin '%s' is out of range: %.15g not in [%.15g, %.15g]",
	                 d->name, opts->builder->name, v, d->min, d->max);
	return -EINVAL;
}

/* Whether `v` is one of the '|'-separated `choices`. */
static bool is_choice(const char *choices, const char *v)
{
	size_t n = strlen(v);
	for (const char *p = choices; *p;) {
		const char *bar = strchr(p, '|');
		size_t len = bar ? (size_t)(bar - p) : strlen(p);
		if (len == n && strncmp(p, v, n) == 0)
			return true;
		if (!bar)
			break;
		p = bar + 1;
	}
	return false;
}

/* An INT option's choices (ABI 1.6): the value must be one of them. */
static int check_int_choice(const bvhlab_options *opts, int k, int64_t v, bvhlab_error *err)
{
	const bvhlab_option_decl *d = &opts->builder->options[k];
	char text[24];
	if (!d->choices || !bvhlab_builder_int_choices(opts->builder))
		return 0;
	snprintf(text, sizeof(text), "%" PRId64, v);
	if (is_choice(d->choices, text))
		return 0;
	error_set(err, "option '%s' of plugin '%s' must be one of %s, not %s", d->name,
	          opts->builder->name, d->choices, text);
	return -EINVAL;
}

int bvhlab_options_set_bool(bvhlab_options *opts, const char *key, bool v, bvhlab_error *err)
{
	int k = lookup(opts, key, BVHLAB_OPTION_BOOL, err);
	if (k < 0)
		return k;
	drop_filled(opts);
	opts->values[k].b = v;
	return 0;
}

int bvhlab_options_set_int(bvhlab_options *opts, const char *key, int64_t v, bvhlab_error *err)
{
	int k = lookup(opts, key, BVHLAB_OPTION_INT, err);
	if (k < 0)
		return k;
	drop_filled(opts);
	int r = check_range(opts, k, (double)v, err);
	if (r == 0)
		r = check_int_choice(opts, k, v, err);
	if (r < 0)
		return r;
	opts->values[k].i = v;
	opts->values[k].f = (double)v;
	return 0;
}

int bvhlab_options_set_float(bvhlab_options *opts, const char *key, double v, bvhlab_error *err)
{
	int k = lookup(opts, key, BVHLAB_OPTION_FLOAT, err);
	if (k < 0)
		return k;
	drop_filled(opts);
	if (!isfinite(v)) {
		error_set(err, "option '%s' of plugin '%s' must be a finite number", key,
		                 opts->builder->name);
		return -EINVAL;
	}
	int r = check_range(opts, k, v, err);
	if (r < 0)
		return r;
	opts->values[k].f = v;
	return 0;
}

int bvhlab_options_set_string(bvhlab_options *opts, const char *key, const char *v,
                              bvhlab_error *err)
{
	int k = lookup(opts, key, BVHLAB_OPTION_STRING, err);
	if (k < 0)
		return k;
	drop_filled(opts);
	const bvhlab_option_decl *d = &opts->builder->options[k];
	if (d->choices && !is_choice(d->choices, v)) {
		error_set(err, "option '%s' of plugin '%s' must be one of %s, not '%s'", key,
		                 opts->builder->name, d->choices, v);
		return -EINVAL;
	}
	/* An option with a default means something by it: empty is no value. */
	if (!*v && d->def_string && *d->def_string) {
		error_set(err, "option '%s' of plugin '%s' must not be empty (default '%s')", key,
		          opts->builder->name, d->def_string);
		return -EINVAL;
	}
	char *copy = strdup(v);
	if (!copy)
		return -ENOMEM;
	free(opts->values[k].s);
	opts->values[k].s = copy;
	return 0;
}

static int parse_bool(const char *text, bool *out)
{
	if (!strcmp(text, "true") || !strcmp(text, "1") || !strcmp(text, "yes") ||
	    !strcmp(text, "on"))
		*out = true;
	else if (!strcmp(text, "false") || !strcmp(text, "0") || !strcmp(text, "no") ||
	         !strcmp(text, "off"))
		*out = false;
	else
		return -EINVAL;
	return 0;
}

/* Parses text as the declared type of option k and sets it. */
static int set_from_text(bvhlab_options *opts, const char *key, int k, const char *text,
                         bvhlab_error *err)
{
	const bvhlab_option_decl *d = &opts->builder->options[k];
	char *end = NULL;
	errno = 0;
	switch (d->type) {
	case BVHLAB_OPTION_BOOL: {
		bool b;
		if (parse_bool(text, &b) == 0)
			return bvhlab_options_set_bool(opts, key, b, err);
		break;
	}
	case BVHLAB_OPTION_INT: {
		long long v = strtoll(text, &end, 10);
		if (*text && !*end && errno == 0)
			return bvhlab_options_set_int(opts, key, v, err);
		break;
	}
	case BVHLAB_OPTION_FLOAT: {
		double v = strtod(text, &end);
		if (*text && !*end && errno == 0)
			return bvhlab_options_set_float(opts, key, v, err);
		break;
	}
	case BVHLAB_OPTION_STRING:
		return bvhlab_options_set_string(opts, key, text, err);
	}
	error_set(err, "option '%s' of plugin '%s' must be %s, not '%s'", key,
	                 opts->builder->name, type_name(d->type), text);
	return -EINVAL;
}

int bvhlab_options_parse(bvhlab_options *opts, const char *assignment, bvhlab_error *err)
{
	const char *eq = strchr(assignment, '=');
	if (!eq || eq == assignment) {
		error_set(err, "option '%s' must be written key=value", assignment);
		return -EINVAL;
	}
	char key[128];
	size_t len = (size_t)(eq - assignment);
	if (len >= sizeof(key)) {
		error_set(err, "option name too long in '%s'", assignment);
		return -EINVAL;
	}
	memcpy(key, assignment, len);
	key[len] = '\0';
	int k = bvhlab_options_find(opts, key);
	if (k < 0)
		return lookup(opts, key, 0, err);
	return set_from_text(opts, key, k, eq + 1, err);
}

/* The shortest %g form that reads back as the same double: 0.05, not
 * 0.050000000000000003 (what %.17g prints), and nothing lost. */
static void format_double(double f, char *buf, size_t size)
{
	for (int digits = 15; digits <= 17; digits++) {
		snprintf(buf, size, "%.*g", digits, f);
		if (strtod(buf, NULL) == f)
			return;
	}
}

void bvhlab_option_format(const bvhlab_option_value *v, char *buf, size_t size)
{
	switch (v->type) {
	case BVHLAB_OPTION_BOOL:
		snprintf(buf, size, "%s", v->b ? "true" : "false");
		break;
	case BVHLAB_OPTION_INT:
		snprintf(buf, size, "%" PRId64, v->i);
		break;
	case BVHLAB_OPTION_FLOAT:
		format_double(v->f, buf, size);
		break;
	case BVHLAB_OPTION_STRING:
		snprintf(buf, size, "\"%s\"", v->s ? v->s : "");
		break;
	default:
		snprintf(buf, size, "null");
	}
}

/* An INT or FLOAT option's value as a double; false for other types. */
static bool numeric(const bvhlab_options *opts, int k, double *v)
{
	uint32_t type = opts->builder->options[k].type;
	*v = type == BVHLAB_OPTION_INT ? (double)opts->values[k].i : opts->values[k].f;
	return type == BVHLAB_OPTION_INT || type == BVHLAB_OPTION_FLOAT;
}

/* The min_NAME <= max_NAME pairs. */
static int check_pairs(const bvhlab_options *opts, bvhlab_error *err)
{
	const bvhlab_builder *b = opts->builder;
	for (uint32_t k = 0; k < b->option_count; k++) {
		const char *name = b->options[k].name;
		char max[128];
		double lo, hi;
		if (strncmp(name, "min_", 4) != 0 ||
		    (size_t)snprintf(max, sizeof(max), "max_%s", name + 4) >= sizeof(max))
			continue;
		int j = bvhlab_options_find(opts, max);
		if (j >= 0 && numeric(opts, (int)k, &lo) && numeric(opts, j, &hi) && lo > hi) {
			error_set(err, "option '%s' of plugin '%s' is %.15g, more than '%s' (%.15g)",
			          name, b->name, lo, max, hi);
			return -EINVAL;
		}
	}
	return 0;
}

int bvhlab_options_check(bvhlab_options *opts, bvhlab_error *err)
{
	int r = check_pairs(opts, err);
	return r < 0 ? r : options_fill(opts, err);
}
