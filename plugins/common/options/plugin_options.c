/* Options into a plugin's struct, by table (see plugin_options.h). */
#include <errno.h>
#include <stddef.h>
#include <stdbool.h>
#include <string.h>

#include "plugin_options.h"

/* The declared option type a field type is read from (and, where an
 * entry leaves it 0, declared as). */
static uint32_t source_type(int type)
{
	switch (type) {
	case PLUGIN_BOOL: return BVHLAB_OPTION_BOOL;
	case PLUGIN_I64:
	case PLUGIN_U32: return BVHLAB_OPTION_INT;
	case PLUGIN_DOUBLE:
	case PLUGIN_FLOAT: return BVHLAB_OPTION_FLOAT;
	case PLUGIN_CHOICE:
	case PLUGIN_STRING: return BVHLAB_OPTION_STRING;
	default: return 0;
	}
}

/* The index of s in "a|b|c", or -1. */
static int choice_index(const char *choices, const char *s)
{
	size_t len = strlen(s);
	int k = 0;

	for (const char *p = choices; p; k++) {
		const char *bar = strchr(p, '|');
		size_t n = bar ? (size_t)(bar - p) : strlen(p);
		if (n == len && strncmp(p, s, n) == 0)
			return k;
		p = bar ? bar + 1 : NULL;
	}
	return -1;
}

static int read_string(const bvhlab_host *host, bvhlab_build_ctx *ctx,
                       const plugin_option *o, char *dst)
{
	const char *s;
	int rc = host->option_string(ctx, o->decl.name, &s);
	int k;

	if (rc < 0)
		return rc;
	if (o->field == PLUGIN_STRING) {
		memcpy(dst, &s, sizeof(s));
		return 0;
	}
	if (!o->decl.choices || (k = choice_index(o->decl.choices, s)) < 0)
		return -EINVAL;
	memcpy(dst, &k, sizeof(k));
	return 0;
}

/* One field; memcpy, since the plugin's struct is not ours to alias. */
static int read_field(const bvhlab_host *host, bvhlab_build_ctx *ctx,
                      const plugin_option *o, char *dst)
{
	const bvhlab_option_decl *d = &o->decl;
	int64_t i;
	double x;
	int rc;

	switch (o->field) {
	case PLUGIN_BOOL: {
		bool b;
		if ((rc = host->option_bool(ctx, d->name, &b)) == 0)
			memcpy(dst, &b, sizeof(b));
		return rc;
	}
	case PLUGIN_I64:
	case PLUGIN_U32:
		if ((rc = host->option_int(ctx, d->name, &i)) < 0)
			return rc;
		if (o->field == PLUGIN_I64) {
			memcpy(dst, &i, sizeof(i));
			return 0;
		}
		if (!(d->min >= 0 && d->max <= UINT32_MAX && d->min <= d->max))
			return -EINVAL;
		memcpy(dst, &(uint32_t){ (uint32_t)i }, sizeof(uint32_t));
		return 0;
	case PLUGIN_DOUBLE:
	case PLUGIN_FLOAT:
		if ((rc = host->option_float(ctx, d->name, &x)) < 0)
			return rc;
		if (o->field == PLUGIN_DOUBLE)
			memcpy(dst, &x, sizeof(x));
		else
			memcpy(dst, &(float){ (float)x }, sizeof(float));
		return 0;
	default:
		return read_string(host, ctx, o, dst);
	}
}

void plugin_options_decls(const plugin_option *table, size_t count, bvhlab_option_decl *decls)
{
	for (size_t k = 0; k < count; k++) {
		decls[k] = table[k].decl;
		if (decls[k].type == 0)
			decls[k].type = source_type(table[k].field);
	}
}

int plugin_options_fill(const bvhlab_host *host, bvhlab_build_ctx *ctx,
                        const plugin_option *table, size_t count, void *out)
{
	for (size_t k = 0; k < count; k++) {
		const plugin_option *o = &table[k];
		uint32_t want = source_type(o->field);
		int rc = want && (o->decl.type == 0 || o->decl.type == want) ? 0 : -EINVAL;

		if (rc == 0)
			rc = read_field(host, ctx, o, (char *)out + o->offset);
		if (rc < 0) {
			host->set_error(ctx, "option \"%s\": the plugin's field does not fit "
			                "its declaration (%d)", o->decl.name, rc);
			return rc;
		}
	}
	return 0;
}

int plugin_options_read(const bvhlab_host *host, bvhlab_build_ctx *ctx,
                        const plugin_option *table, size_t count, plugin_check_fn check,
                        size_t size, void *out)
{
	int rc;

	memset(out, 0, size);
	rc = plugin_options_fill(host, ctx, table, count, out);
	return rc == 0 && check ? check(host, ctx, out) : rc;
}

int plugin_options_get(const bvhlab_host *host, bvhlab_build_ctx *ctx,
                       const bvhlab_build_input *input,
                       int (*fill)(const bvhlab_host *, bvhlab_build_ctx *, void *),
                       size_t size, void *out)
{
	size_t has = offsetof(bvhlab_build_input, options) + sizeof(input->options);

	if (input->struct_size >= has && input->options) {
		memcpy(out, input->options, size);
		return 0;
	}
	return fill(host, ctx, out);
}
