/*
 * Config checking helpers: located error messages, key checks with
 * did-you-mean suggestions, typed member getters and path resolution.
 */
#include <errno.h>
#include <math.h>
#include <stdarg.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "config/config_internal.h"
#include "config/json_locate.h"

#define MAX_KEY_FOR_DISTANCE 40
#define FULL_NAME_SIZE 160

int config_error(const struct config *cfg, const cJSON *item, bool at_key,
                 bvhlab_error *err, const char *fmt, ...)
{
	char message[sizeof(err->message)];
	va_list ap;
	va_start(ap, fmt);
	int n = vsnprintf(message, sizeof(message), fmt, ap);
	va_end(ap);
	if (n >= (int)sizeof(message)) /* the final error_set adds "..." too */
		memcpy(message + sizeof(message) - 4, "...", 4);
	const char *path = cfg->path ? cfg->path : "(config)";
	int line, col;
	bool found = item && at_key && json_locate_key(cfg->locations, item, &line, &col);
	if (!found && item)
		found = json_locate_value(cfg->locations, item, &line, &col);
	if (found)
		error_set(err, "%s:%d:%d: %s", path, line, col, message);
	else
		error_set(err, "%s: %s", path, message);
	return -EINVAL;
}

void config_locate_builder_error(const struct config *cfg, const struct config_builder *b,
                                 size_t stage, bvhlab_error *err)
{
	const char *path = cfg->path ? cfg->path : "(config)";
	size_t n = strlen(path);
	if (strncmp(err->message, path, n) == 0 && err->message[n] == ':')
		return;
	char message[sizeof(err->message)];
	memcpy(message, err->message, sizeof(message));
	bool in_stage = stage < b->refine_count;
	error_set(err, "%s:%d:%d: builder '%s': %s", path,
	          in_stage ? b->refine[stage].line : b->line,
	          in_stage ? b->refine[stage].column : b->column, b->name, message);
}

static const char *describe_number(const struct config *cfg, const cJSON *item, char *buf,
                                   size_t size)
{
	/* Echo what the user wrote: a double would turn 2.50 into 2.5. */
	const char *text = json_value_text(cfg->locations, item);
	size_t n = text ? strspn(text, "0123456789+-.eE") : 0;
	if (n == 0 || n >= size) {
		snprintf(buf, size, "%g", item->valuedouble);
		return buf;
	}
	memcpy(buf, text, n);
	buf[n] = '\0';
	return buf;
}

const char *config_describe(const struct config *cfg, const cJSON *item, char *buf,
                            size_t size)
{
	if (cJSON_IsNumber(item))
		return describe_number(cfg, item, buf, size);
	if (cJSON_IsString(item))
		return "a string";
	if (cJSON_IsTrue(item))
		return "true";
	if (cJSON_IsFalse(item))
		return "false";
	if (cJSON_IsArray(item))
		return "an array";
	if (cJSON_IsObject(item))
		return "an object";
	return "null";
}

/* ---- suggestions ------------------------------------------------------------ */

static int min3(int a, int b, int c)
{
	int m = a < b ? a : b;
	return m < c ? m : c;
}

/* Optimal string alignment distance: edits, with a swap of neighbours as one. */
static int distance(const char *a, const char *b)
{
	size_t n = strlen(a), m = strlen(b);
	if (n > MAX_KEY_FOR_DISTANCE || m > MAX_KEY_FOR_DISTANCE)
		return MAX_KEY_FOR_DISTANCE;
	int d[MAX_KEY_FOR_DISTANCE + 1][MAX_KEY_FOR_DISTANCE + 1];
	for (size_t i = 0; i <= n; i++)
		d[i][0] = (int)i;
	for (size_t j = 0; j <= m; j++)
		d[0][j] = (int)j;
	for (size_t i = 1; i <= n; i++) {
		for (size_t j = 1; j <= m; j++) {
			int cost = a[i - 1] != b[j - 1];
			d[i][j] = min3(d[i - 1][j] + 1, d[i][j - 1] + 1, d[i - 1][j - 1] + cost);
			if (i > 1 && j > 1 && a[i - 1] == b[j - 2] && a[i - 2] == b[j - 1])
				d[i][j] = d[i][j] < d[i - 2][j - 2] + 1 ? d[i][j] : d[i - 2][j - 2] + 1;
		}
	}
	return d[n][m];
}

void config_suggest_init(struct config_suggestion *s)
{
	s->best = NULL;
	s->distance = 3;
}

void config_suggest_consider(struct config_suggestion *s, const char *typed,
                             const char *candidate)
{
	int d = distance(typed, candidate);
	/* Two edits to a two-letter key could suggest anything. */
	if (d < s->distance && d < (int)strlen(typed)) {
		s->best = candidate;
		s->distance = d;
	}
}

/* ---- keys ------------------------------------------------------------------- */

const cJSON *config_member(const cJSON *obj, const char *key)
{
	return cJSON_GetObjectItemCaseSensitive(obj, key);
}

static bool is_known(const struct config_key *table, const char *key)
{
	for (; table->name; table++)
		if (strcmp(table->name, key) == 0)
			return true;
	return false;
}

static int unknown_key(const struct config *cfg, const cJSON *member,
                       const struct config_key *table, const char *where, bvhlab_error *err)
{
	char list[256] = "", hint[96] = "";
	size_t used = 0;
	struct config_suggestion s;
	config_suggest_init(&s);
	for (const struct config_key *k = table; k->name; k++) {
		config_suggest_consider(&s, member->string, k->name);
		if (used >= sizeof(list))
			continue;
		int n = snprintf(list + used, sizeof(list) - used, "%s%s", used ? ", " : "", k->name);
		used += (size_t)n;
		if (used >= sizeof(list)) /* not with the static key tables, but say so */
			memcpy(list + sizeof(list) - 4, "...", 4);
	}
	if (s.best)
		snprintf(hint, sizeof(hint), "; did you mean '%s'?", s.best);
	return config_error(cfg, member, true, err, "unknown key '%s' %s (known: %s)%s",
	                    member->string, where, list, hint);
}

int config_check_duplicates(const struct config *cfg, const cJSON *obj, const char *where,
                            bvhlab_error *err)
{
	for (const cJSON *m = obj->child; m; m = m->next) {
		for (const cJSON *p = obj->child; p != m; p = p->next) {
			if (strcmp(p->string, m->string) != 0)
				continue;
			int line = 0, col = 0;
			json_locate_key(cfg->locations, p, &line, &col);
			return config_error(cfg, m, true, err,
			                    "duplicate key '%s' %s (first at line %d, column %d)",
			                    m->string, where, line, col);
		}
	}
	return 0;
}

int config_check_keys(const struct config *cfg, const cJSON *obj,
                      const struct config_key *table, const char *where, bvhlab_error *err)
{
	for (const cJSON *m = obj->child; m; m = m->next)
		if (!is_known(table, m->string))
			return unknown_key(cfg, m, table, where, err);
	return config_check_duplicates(cfg, obj, where, err);
}

/* ---- typed members ---------------------------------------------------------- */

static const char *full_name(char *buf, size_t size, const char *prefix, const char *key)
{
	int n = snprintf(buf, size, "%s%s", prefix, key);
	if (n < 0 || (size_t)n >= size) /* only for absurd keys; show it was cut */
		memcpy(buf + size - 4, "...", 4);
	return buf;
}

/* The upper bound only matters, and is only shown, when the value is above it. */
static const char *integer_kind(uint64_t min, uint64_t max, bool too_large, char *buf,
                                size_t size)
{
	const char *base = min == 0 ? "a non-negative integer" :
	                   min == 1 ? "a positive integer" : "an integer";
	int n = snprintf(buf, size, "%s", base);
	if (min > 1)
		n += snprintf(buf + n, size - (size_t)n, " >= %llu", (unsigned long long)min);
	if (too_large && max != UINT64_MAX)
		snprintf(buf + n, size - (size_t)n, " up to %llu", (unsigned long long)max);
	return buf;
}

static int item_uint(const struct config *cfg, const cJSON *item, const char *name,
                     uint64_t min, uint64_t max, uint64_t *out, bvhlab_error *err)
{
	uint64_t v = 0;
	int rc = cJSON_IsNumber(item) ? json_get_uint64(cfg->locations, item, &v) : -EINVAL;
	if (rc || v < min || v > max) {
		char kind[96], got[48];
		bool too_large = (rc == -ERANGE && item->valuedouble > 0) || (!rc && v > max);
		return config_error(cfg, item, false, err, "'%s' must be %s, not %s", name,
		                    integer_kind(min, max, too_large, kind, sizeof(kind)),
		                    config_describe(cfg, item, got, sizeof(got)));
	}
	*out = v;
	return 0;
}

int config_get_uint(const struct config *cfg, const cJSON *obj, const char *key,
                    const char *prefix, uint64_t min, uint64_t max, uint64_t *out,
                    bvhlab_error *err)
{
	const cJSON *item = config_member(obj, key);
	char name[FULL_NAME_SIZE];
	if (!item)
		return 0;
	return item_uint(cfg, item, full_name(name, sizeof(name), prefix, key), min, max, out,
	                 err);
}

int config_get_u32(const struct config *cfg, const cJSON *obj, const char *key,
                   const char *prefix, uint32_t min, uint32_t max, uint32_t *out,
                   bvhlab_error *err)
{
	uint64_t v = *out;
	int rc = config_get_uint(cfg, obj, key, prefix, min, max, &v, err);
	if (!rc)
		*out = (uint32_t)v; /* within [min, max], checked */
	return rc;
}

int config_get_bool(const struct config *cfg, const cJSON *obj, const char *key,
                    const char *prefix, bool *out, bvhlab_error *err)
{
	const cJSON *item = config_member(obj, key);
	char name[FULL_NAME_SIZE], got[48];
	if (!item)
		return 0;
	if (!cJSON_IsBool(item))
		return config_error(cfg, item, false, err, "'%s' must be true or false, not %s",
		                    full_name(name, sizeof(name), prefix, key),
		                    config_describe(cfg, item, got, sizeof(got)));
	*out = cJSON_IsTrue(item);
	return 0;
}

int config_get_positive(const struct config *cfg, const cJSON *obj, const char *key,
                        const char *prefix, double *out, bvhlab_error *err)
{
	const cJSON *item = config_member(obj, key);
	char name[FULL_NAME_SIZE], got[48];
	if (!item)
		return 0;
	if (!cJSON_IsNumber(item) || !isfinite(item->valuedouble) || !(item->valuedouble > 0))
		return config_error(cfg, item, false, err, "'%s' must be a number > 0, not %s",
		                    full_name(name, sizeof(name), prefix, key),
		                    config_describe(cfg, item, got, sizeof(got)));
	*out = item->valuedouble;
	return 0;
}

int config_get_string(const struct config *cfg, const cJSON *obj, const char *key,
                      const char *prefix, char **out, bvhlab_error *err)
{
	const cJSON *item = config_member(obj, key);
	char name[FULL_NAME_SIZE], got[48];
	if (!item)
		return 0;
	full_name(name, sizeof(name), prefix, key);
	if (!cJSON_IsString(item))
		return config_error(cfg, item, false, err, "'%s' must be a string, not %s", name,
		                    config_describe(cfg, item, got, sizeof(got)));
	if (item->valuestring[0] == '\0')
		return config_error(cfg, item, false, err, "'%s' must not be empty", name);
	char *copy = strdup(item->valuestring);
	if (!copy) {
		error_set(err, "%s: out of memory", cfg->path);
		return -ENOMEM;
	}
	free(*out);
	*out = copy;
	return 0;
}

int config_get_dvec3(const struct config *cfg, const cJSON *obj, const char *key,
                     const char *prefix, double out[3], bvhlab_error *err)
{
	const cJSON *item = config_member(obj, key);
	char got[48];
	if (!item)
		return 0;
	if (cJSON_IsArray(item) && cJSON_GetArraySize(item) == 3) {
		double v[3];
		int k = 0;
		const cJSON *e;
		cJSON_ArrayForEach(e, item) {
			if (!cJSON_IsNumber(e) || !isfinite(e->valuedouble) ||
			    fabs(e->valuedouble) > 1e30)
				break;
			v[k++] = e->valuedouble;
		}
		if (k == 3) {
			memcpy(out, v, sizeof(v));
			return 0;
		}
	}
	return config_error(cfg, item, false, err,
	                    "'%s%s' must be an array of 3 finite numbers, not %s", prefix, key,
	                    config_describe(cfg, item, got, sizeof(got)));
}

int config_get_vec3(const struct config *cfg, const cJSON *obj, const char *key,
                    const char *prefix, float out[3], bvhlab_error *err)
{
	double v[3] = { out[0], out[1], out[2] };
	int rc = config_get_dvec3(cfg, obj, key, prefix, v, err);

	for (int k = 0; rc == 0 && k < 3; k++)
		out[k] = (float)v[k];
	return rc;
}

static int thread_entries(const struct config *cfg, const cJSON *array, const char *name,
                          uint32_t *threads, bvhlab_error *err)
{
	size_t i = 0;
	for (const cJSON *e = array->child; e; e = e->next, i++) {
		char element[FULL_NAME_SIZE + 24];
		uint64_t v;
		snprintf(element, sizeof(element), "%s[%zu]", name, i);
		int rc = item_uint(cfg, e, element, 0, CONFIG_MAX_THREADS, &v, err);
		if (rc)
			return rc;
		threads[i] = (uint32_t)v;
		for (size_t j = 0; j < i; j++)
			if (threads[j] == threads[i])
				return config_error(cfg, e, false, err,
				                    "'%s' repeats thread count %u of '%s[%zu]'",
				                    element, threads[i], name, j);
	}
	return 0;
}

int config_get_threads(const struct config *cfg, const cJSON *obj, const char *key,
                       const char *prefix, uint32_t **out, size_t *count,
                       bvhlab_error *err)
{
	const cJSON *item = config_member(obj, key);
	char name[FULL_NAME_SIZE], got[48];
	if (!item)
		return 0;
	full_name(name, sizeof(name), prefix, key);
	if (!cJSON_IsArray(item))
		return config_error(cfg, item, false, err,
		                    "'%s' must be an array of thread counts (0 = all cores), not %s",
		                    name, config_describe(cfg, item, got, sizeof(got)));
	size_t n = (size_t)cJSON_GetArraySize(item);
	if (n == 0)
		return config_error(cfg, item, false, err, "'%s' must not be empty", name);
	uint32_t *threads = calloc(n, sizeof(*threads));
	if (!threads) {
		error_set(err, "%s: out of memory", cfg->path);
		return -ENOMEM;
	}
	int rc = thread_entries(cfg, item, name, threads, err);
	if (rc) {
		free(threads);
		return rc;
	}
	free(*out);
	*out = threads;
	*count = n;
	return 0;
}

/* ---- paths ------------------------------------------------------------------ */

int config_resolve(const struct config *cfg, const char *path, char **out)
{
	/* Leave "x.obj" as is rather than "./x.obj" when the config is in the cwd. */
	if (path[0] == '/' || !cfg->dir || strcmp(cfg->dir, ".") == 0) {
		*out = strdup(path);
		return *out ? 0 : -ENOMEM;
	}
	size_t dir_len = strlen(cfg->dir), path_len = strlen(path);
	bool slash = dir_len > 0 && cfg->dir[dir_len - 1] != '/';
	char *joined = malloc(dir_len + slash + path_len + 1);
	if (!joined)
		return -ENOMEM;
	memcpy(joined, cfg->dir, dir_len);
	if (slash)
		joined[dir_len] = '/';
	memcpy(joined + dir_len + slash, path, path_len + 1);
	*out = joined;
	return 0;
}

char *config_stem(const char *path)
{
	const char *base = strrchr(path, '/');
	base = base ? base + 1 : path;
	if (*base == '\0')
		return strdup(path);
	const char *dot = strrchr(base, '.');
	return strndup(base, dot && dot != base ? (size_t)(dot - base) : strlen(base));
}
