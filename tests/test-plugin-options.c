/*
 * plugin_options_fill (plugins/common/options), against a host table of
 * its own: every field type lands in its field at its offset with the
 * value the host gives (a choice as its index, a float rounded as a cast
 * rounds), and a table that does not match the declarations (an
 * undeclared name, a type that does not fit, a U32 field for a range past
 * 32 bits) fails with -EINVAL and says so through set_error.
 */
#include <errno.h>
#include <stdarg.h>
#include <stdbool.h>
#include <stdint.h>

#include <bvhlab/builder.h>

#include "plugin_options.h"
#include "testutil.h"

static const bvhlab_option_decl decls[] = {
	{ .name = "on", .type = BVHLAB_OPTION_BOOL },
	{ .name = "count", .type = BVHLAB_OPTION_INT, .min = 1, .max = 64 },
	{ .name = "big", .type = BVHLAB_OPTION_INT, .min = 0, .max = 1e12 },
	{ .name = "cost", .type = BVHLAB_OPTION_FLOAT, .min = 0, .max = 10 },
	{ .name = "method", .type = BVHLAB_OPTION_STRING, .choices = "sweep|binned|grid" },
	{ .name = "label", .type = BVHLAB_OPTION_STRING },
};
#define DECL_COUNT (sizeof(decls) / sizeof(decls[0]))

/* The values the fake host hands out, whatever the name's type. */
static int errors;

static void set_error(bvhlab_build_ctx *ctx, const char *fmt, ...)
{
	(void)ctx;
	(void)fmt;
	errors++;
}

static int get_bool(bvhlab_build_ctx *ctx, const char *name, bool *out)
{
	(void)ctx;
	(void)name;
	*out = true;
	return 0;
}

static int get_int(bvhlab_build_ctx *ctx, const char *name, int64_t *out)
{
	(void)ctx;
	*out = name[0] == 'b' ? 5000000000LL : 42;
	return 0;
}

static int get_float(bvhlab_build_ctx *ctx, const char *name, double *out)
{
	(void)ctx;
	(void)name;
	*out = 0.1;
	return 0;
}

static int get_string(bvhlab_build_ctx *ctx, const char *name, const char **out)
{
	(void)ctx;
	*out = name[0] == 'm' ? "grid" : "hello";
	return 0;
}

static const bvhlab_host host = {
	.abi_version = BVHLAB_ABI_CURRENT, .struct_size = sizeof(bvhlab_host),
	.set_error = set_error, .option_bool = get_bool, .option_int = get_int,
	.option_float = get_float, .option_string = get_string,
};

struct opts {
	char pad; /* the fields are not at offset 0 */
	bool on;
	uint32_t count;
	int64_t big;
	float cost_f;
	double cost_d;
	int method;
	const char *label;
};

static void test_fill(void)
{
	static const plugin_field fields[] = {
		PLUGIN_FIELD(struct opts, on, "on", BOOL),
		PLUGIN_FIELD(struct opts, count, "count", U32),
		PLUGIN_FIELD(struct opts, big, "big", I64),
		PLUGIN_FIELD(struct opts, cost_f, "cost", FLOAT),
		PLUGIN_FIELD(struct opts, cost_d, "cost", DOUBLE),
		PLUGIN_FIELD(struct opts, method, "method", CHOICE),
		PLUGIN_FIELD(struct opts, label, "label", STRING),
	};
	struct opts o = { .pad = 'x' };

	errors = 0;
	CHECK_INT(plugin_options_fill(&host, NULL, decls, DECL_COUNT, fields, 7, &o), 0);
	CHECK_INT(errors, 0);
	CHECK(o.pad == 'x' && o.on);
	CHECK_INT(o.count, 42);
	CHECK_INT(o.big, 5000000000LL);
	CHECK(o.cost_f == (float)0.1 && o.cost_d == 0.1);
	CHECK_INT(o.method, 2);
	CHECK(o.label && strcmp(o.label, "hello") == 0);
}

/* Each bad table alone: -EINVAL, one message, nothing else read. */
static void test_bad_tables(void)
{
	static const plugin_field bad[][1] = {
		{ PLUGIN_FIELD(struct opts, count, "no_such", U32) },
		{ PLUGIN_FIELD(struct opts, count, "cost", U32) },
		{ PLUGIN_FIELD(struct opts, on, "count", BOOL) },
		{ PLUGIN_FIELD(struct opts, count, "big", U32) },
		{ PLUGIN_FIELD(struct opts, method, "label", CHOICE) },
	};
	struct opts o = { 0 };

	for (size_t k = 0; k < sizeof(bad) / sizeof(bad[0]); k++) {
		errors = 0;
		CHECK_INT(plugin_options_fill(&host, NULL, decls, DECL_COUNT, bad[k], 1, &o),
		          -EINVAL);
		CHECK_INT(errors, 1);
	}
	CHECK(o.count == 0 && !o.on && o.method == 0);
}

int main(void)
{
	test_fill();
	test_bad_tables();
	return test_finish();
}
