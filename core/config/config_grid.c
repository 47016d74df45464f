/*
 * Option grids: a builder option written {"grid": [v1, v2, ...]} stands for
 * one builder per value (several grids: one per combination), each named
 * after what varies, "sah_seq[bins=8,max_leaf=4]". The expanded builders
 * keep pointing at the grid's elements in the parsed document, so an
 * option check of a value reports the element's own line and column.
 */
#include <errno.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "config/config_internal.h"

/* More builders than this from one config is a typo, not a study. */
#define MAX_EXPANDED 100000
#define NAME_MAX_LEN 512

static int out_of_memory(const struct config *cfg, bvhlab_error *err)
{
	error_set(err, "%s: out of memory", cfg->path);
	return -ENOMEM;
}

static bool is_grid(const cJSON *value)
{
	return cJSON_IsObject(value) && config_member(value, "grid");
}

/* {"grid": [scalars...]} and nothing else; *size gets the element count. */
static int check_grid(const struct config *cfg, const cJSON *member, size_t index,
                      size_t *size, bvhlab_error *err)
{
	const cJSON *grid = config_member(member, "grid");
	char got[48];
	if (cJSON_GetArraySize(member) != 1)
		return config_error(cfg, member, true, err,
		                    "'builders[%zu].options.%s': a grid is {\"grid\": [values...]} "
		                    "with no other key", index, member->string);
	if (!cJSON_IsArray(grid) || cJSON_GetArraySize(grid) == 0)
		return config_error(cfg, grid, false, err,
		                    "'builders[%zu].options.%s.grid' must be a non-empty array, not %s",
		                    index, member->string,
		                    cJSON_IsArray(grid) ? "an empty array"
		                                        : config_describe(cfg, grid, got, sizeof(got)));
	size_t k = 0;
	for (const cJSON *v = grid->child; v; v = v->next, k++)
		if (cJSON_IsArray(v) || cJSON_IsObject(v) || cJSON_IsNull(v))
			return config_error(cfg, v, false, err,
			                    "'builders[%zu].options.%s.grid[%zu]' must be a number, string "
			                    "or boolean, not %s", index, member->string, k,
			                    config_describe(cfg, v, got, sizeof(got)));
	*size = k;
	return 0;
}

/* How many builders the entry becomes; *grids counts its grid options. */
static int entry_size(const struct config *cfg, const struct config_builder *b, size_t index,
                      size_t *builders, size_t *grids, bvhlab_error *err)
{
	*builders = 1;
	*grids = 0;
	for (const cJSON *m = b->options ? b->options->child : NULL; m; m = m->next) {
		size_t n = 1;
		if (!is_grid(m))
			continue;
		int rc = check_grid(cfg, m, index, &n, err);
		if (rc)
			return rc;
		if (*builders > MAX_EXPANDED / n)
			return config_error(cfg, m, true, err,
			                    "builders[%zu]: its grids make more than %d builders", index,
			                    MAX_EXPANDED);
		*builders *= n;
		(*grids)++;
	}
	return 0;
}

/* "key=value" of one pick, as the user wrote the value. */
static void append_pick(const struct config *cfg, struct strbuf *sb,
                        const struct config_grid_pick *p, bool first)
{
	char buf[48];
	const char *text = cJSON_IsString(p->value) ? p->value->valuestring
	                                            : config_describe(cfg, p->value, buf, sizeof(buf));
	sb_printf(sb, "%s%s=%s", first ? "" : ",", p->member->string, text);
}

/* Combination `combo` of the entry's grids: the last grid varies fastest. */
static void fill_picks(const struct config_builder *b, size_t combo, size_t grids,
                       struct config_grid_pick *picks)
{
	size_t g = 0;
	for (const cJSON *m = b->options->child; m; m = m->next)
		if (is_grid(m))
			picks[g++].member = m;
	for (size_t i = grids; i-- > 0;) {
		const cJSON *array = config_member(picks[i].member, "grid");
		size_t n = (size_t)cJSON_GetArraySize(array);
		picks[i].index = combo % n;
		picks[i].value = cJSON_GetArrayItem(array, (int)picks[i].index);
		combo /= n;
	}
}

/* One expanded builder: a deep copy of b with its picks and its name. */
static int make_builder(const struct config *cfg, const struct config_builder *b, size_t combo,
                        size_t grids, struct config_builder *out)
{
	struct strbuf sb = {0};
	*out = *b;
	out->plugin = strdup(b->plugin);
	out->top = b->top ? strdup(b->top) : NULL;
	out->picks = calloc(grids, sizeof(*out->picks));
	out->pick_count = grids;
	out->threads = NULL;
	out->name = NULL;
	if (b->threads && (out->threads = malloc(b->thread_count * sizeof(*b->threads))))
		memcpy(out->threads, b->threads, b->thread_count * sizeof(*b->threads));
	if (!out->plugin || !out->picks || (b->threads && !out->threads) || (b->top && !out->top))
		return -ENOMEM;
	fill_picks(b, combo, grids, out->picks);
	sb_printf(&sb, "%s[", b->name);
	for (size_t i = 0; i < grids; i++)
		append_pick(cfg, &sb, &out->picks[i], i == 0);
	sb_printf(&sb, "]");
	out->name = sb_take(&sb);
	return out->name ? 0 : -ENOMEM;
}

static void free_builder(struct config_builder *b)
{
	free(b->plugin);
	free(b->top);
	free(b->name);
	free(b->threads);
	free(b->picks);
}

/* Expanded names must stay apart, from each other and from plain builders. */
static int unique_expanded(const struct config *cfg, bvhlab_error *err)
{
	for (size_t i = 0; i < cfg->builder_count; i++)
		for (size_t j = 0; j < i; j++)
			if (strcmp(cfg->builders[i].name, cfg->builders[j].name) == 0)
				return config_error(cfg, cfg->builders[i].options, false, err,
				                    "duplicate builder name '%s' after expanding grids "
				                    "(set 'name' to tell them apart)", cfg->builders[i].name);
	return 0;
}

/* Expands entry b into out[0..n), deep copies; b stays the caller's to free. */
static int expand_entry(const struct config *cfg, const struct config_builder *b, size_t n,
                        size_t grids, struct config_builder *out, bvhlab_error *err)
{
	for (size_t c = 0; c < n; c++) {
		if (make_builder(cfg, b, c, grids, &out[c]) < 0) {
			for (size_t k = 0; k <= c; k++)
				free_builder(&out[k]);
			return out_of_memory(cfg, err);
		}
		if (strlen(out[c].name) > NAME_MAX_LEN) {
			for (size_t k = 0; k <= c; k++)
				free_builder(&out[k]);
			return config_error(cfg, b->options, false, err,
			                    "builder '%s': its grid names grow past %d characters",
			                    b->name, NAME_MAX_LEN);
		}
	}
	return 0;
}

/* Sizes of every entry's expansion; *total builders, *any grid at all. */
static int sizes_of(const struct config *cfg, const cJSON *array, size_t *sizes, size_t *grids,
                    size_t *total, bool *any, bvhlab_error *err)
{
	size_t index = 0;
	*total = 0;
	*any = false;
	for (const cJSON *e = array->child; e && index < cfg->builder_count; e = e->next, index++) {
		int rc = entry_size(cfg, &cfg->builders[index], index, &sizes[index], &grids[index], err);
		if (rc)
			return rc;
		*total += sizes[index];
		*any = *any || grids[index];
		if (*total > MAX_EXPANDED)
			return config_error(cfg, e, false, err, "the grids make more than %d builders",
			                    MAX_EXPANDED);
	}
	return 0;
}

int config_expand_grids(struct config *cfg, const cJSON *array, bvhlab_error *err)
{
	size_t total, sizes[cfg->builder_count], grids[cfg->builder_count];
	bool any;
	int rc = sizes_of(cfg, array, sizes, grids, &total, &any, err);
	if (rc || !any)
		return rc;
	struct config_builder *all = calloc(total, sizeof(*all));
	if (!all)
		return out_of_memory(cfg, err);
	for (size_t i = 0, at = 0; i < cfg->builder_count; at += sizes[i], i++) {
		if (!grids[i]) {
			all[at] = cfg->builders[i];
			cfg->builders[i] = (struct config_builder){0};
		} else if ((rc = expand_entry(cfg, &cfg->builders[i], sizes[i], grids[i], &all[at],
		                              err)) != 0) {
			for (size_t k = 0; k < at; k++)
				free_builder(&all[k]);
			free(all);
			return rc;
		}
	}
	for (size_t i = 0; i < cfg->builder_count; i++)
		free_builder(&cfg->builders[i]);
	free(cfg->builders);
	cfg->builders = all;
	cfg->builder_count = total;
	return unique_expanded(cfg, err);
}

const cJSON *config_grid_value(const struct config_builder *b, const cJSON *member,
                               size_t *index)
{
	*index = SIZE_MAX;
	for (size_t i = 0; i < b->pick_count; i++) {
		if (b->picks[i].member != member)
			continue;
		*index = b->picks[i].index;
		return b->picks[i].value;
	}
	return member;
}
