/*
 * plugin_options.h (plugins/common/options), as a plugin uses it: this
 * test is a plugin of its own (PLUGIN_WITH_OPTIONS) with a fake host.
 * The entry point returns the descriptor with the table's declarations,
 * in order, field for field (the field's type where an entry leaves it
 * out), to any thread (several ask at once, the first time), and its
 * fill_options (ABI 1.6); that fills a zeroed struct, every field type at
 * its offset with the value the host gives (a choice as its index, a
 * float rounded as a cast rounds), then runs the plugin's check; build()
 * copies the struct the host gives as input->options, or fills its own
 * from a host that gives none (an older one); an entry whose
 * field does not fit its declaration (a type that does not fit, a U32 for
 * a range past 32 bits, a CHOICE without choices) fails with -EINVAL and
 * a message naming the option.
 */
#include <errno.h>
#include <pthread.h>
#include <stdarg.h>
#include <stdbool.h>
#include <stdint.h>
#include <stddef.h>
#include <stdio.h>
#include <string.h>

#include <bvhlab/builder.h>

#include "plugin_options.h"
#include "testutil.h"

static int errors;
static char last_error[256];

static void set_error(bvhlab_build_ctx *ctx, const char *fmt, ...)
{
	va_list ap;

	(void)ctx;
	va_start(ap, fmt);
	vsnprintf(last_error, sizeof(last_error), fmt, ap);
	va_end(ap);
	errors++;
}

/* The values the fake host hands out, whatever the name's type. */
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

static int get_seven(bvhlab_build_ctx *ctx, const char *name, int64_t *out)
{
	(void)ctx;
	(void)name;
	*out = 7;
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
	int derived; /* set by the check */
};

static const plugin_option options[] = {
	PLUGIN_OPTION(struct opts, on, BOOL, .name = "on", .type = BVHLAB_OPTION_BOOL,
	              .help = "a bool, its type given", .def_bool = true),
	PLUGIN_OPTION(struct opts, count, U32, .name = "count", .def_int = 3, .min = 1, .max = 64),
	PLUGIN_OPTION(struct opts, big, I64, .name = "big", .min = 0, .max = 1e12),
	PLUGIN_OPTION(struct opts, cost_f, FLOAT, .name = "cost_f", .def_float = 0.5, .max = 10),
	PLUGIN_OPTION(struct opts, cost_d, DOUBLE, .name = "cost_d", .min = 0, .max = 10),
	PLUGIN_OPTION(struct opts, method, CHOICE, .name = "method", .def_string = "sweep",
	              .choices = "sweep|binned|grid"),
	PLUGIN_OPTION(struct opts, label, STRING, .name = "label", .help = "free text"),
};

/* The plugin's own rule: derives a field, refuses a count of 7. */
static int check(const bvhlab_host *h, bvhlab_build_ctx *ctx, void *opt)
{
	struct opts *o = opt;

	o->derived = o->method + 100;
	if (o->count != 7)
		return 0;
	h->set_error(ctx, "option 'count' must not be 7");
	return -EINVAL;
}
PLUGIN_DECLS(options, struct opts, check)

/* What the last build read. */
static struct opts filled;

static int build(const bvhlab_host *h, bvhlab_build_ctx *ctx, const bvhlab_build_input *in,
                 bvhlab_build_output *out)
{
	(void)out;
	filled = (struct opts){ .pad = 'x' };
	return PLUGIN_OPTIONS_GET(h, ctx, in, &filled);
}

PLUGIN_WITH_OPTIONS(options, .name = "options_probe", .summary = "plugin_options.h's test",
                    .build = build)

#define ASKERS 4

static void *ask(void *arg)
{
	*(const bvhlab_builder **)arg = bvhlab_plugin_entry(BVHLAB_ABI_MAJOR);
	return NULL;
}

/* All but the type, which the table leaves to the field. */
static bool same_decl(const bvhlab_option_decl *a, const bvhlab_option_decl *b)
{
	return a->name == b->name && a->help == b->help &&
	       a->def_bool == b->def_bool && a->def_int == b->def_int &&
	       a->def_float == b->def_float && a->def_string == b->def_string &&
	       a->min == b->min && a->max == b->max && a->choices == b->choices;
}

/* The first calls race: each must see the declarations filled. */
static void test_entry(void)
{
	static const uint32_t types[] = {
		BVHLAB_OPTION_BOOL, BVHLAB_OPTION_INT, BVHLAB_OPTION_INT, BVHLAB_OPTION_FLOAT,
		BVHLAB_OPTION_FLOAT, BVHLAB_OPTION_STRING, BVHLAB_OPTION_STRING,
	};
	pthread_t t[ASKERS];
	const bvhlab_builder *got[ASKERS] = { 0 };
	const bvhlab_builder *d;

	for (int k = 0; k < ASKERS; k++)
		CHECK_INT(pthread_create(&t[k], NULL, ask, &got[k]), 0);
	for (int k = 0; k < ASKERS; k++)
		pthread_join(t[k], NULL);
	d = got[0];
	CHECK(d != NULL);
	for (int k = 1; k < ASKERS; k++)
		CHECK(got[k] == d);
	if (!d)
		return;
	CHECK_INT(d->abi_version, BVHLAB_ABI_CURRENT);
	CHECK_INT(d->struct_size, sizeof(bvhlab_builder));
	CHECK(strcmp(d->name, "options_probe") == 0 && d->build == build);
	CHECK_INT(d->option_count, PLUGIN_OPTION_COUNT(options));
	for (uint32_t k = 0; k < d->option_count && k < PLUGIN_OPTION_COUNT(options); k++) {
		CHECK(same_decl(&d->options[k], &options[k].decl));
		CHECK_INT(d->options[k].type, types[k]);
	}
	CHECK(strcmp(d->options[5].choices, "sweep|binned|grid") == 0);
	CHECK(bvhlab_plugin_entry(BVHLAB_ABI_MAJOR + 1) == NULL);
	CHECK(d->fill_options != NULL);
	CHECK_INT(d->options_size, sizeof(struct opts));
}

static void check_filled(const struct opts *o, char pad)
{
	CHECK(o->pad == pad && o->on);
	CHECK_INT(o->count, 42);
	CHECK_INT(o->big, 5000000000LL);
	CHECK(o->cost_f == (float)0.1 && o->cost_d == 0.1);
	CHECK_INT(o->method, 2);
	CHECK(o->label && strcmp(o->label, "hello") == 0);
	CHECK_INT(o->derived, 102);
}

static void test_fill(void)
{
	const bvhlab_builder *d = bvhlab_plugin_entry(BVHLAB_ABI_MAJOR);
	struct opts once;
	bvhlab_build_input in = { .struct_size = sizeof(in) };

	/* fill_options: a zeroed struct, filled and checked */
	memset(&once, 'z', sizeof(once));
	errors = 0;
	CHECK_INT(d->fill_options(&host, NULL, &once), 0);
	CHECK_INT(errors, 0);
	check_filled(&once, 0);
	/* a build from a host that filled it: a copy, nothing asked */
	once.pad = 'c';
	in.options = &once;
	CHECK_INT(d->build(&host, NULL, &in, NULL), 0);
	check_filled(&filled, 'c');
	/* from a host that did not (no options, or an older input) */
	in.options = NULL;
	CHECK_INT(d->build(&host, NULL, &in, NULL), 0);
	check_filled(&filled, 0);
	in.options = &once;
	in.struct_size = offsetof(bvhlab_build_input, options);
	CHECK_INT(d->build(&host, NULL, &in, NULL), 0);
	check_filled(&filled, 0);
	CHECK_INT(errors, 0);
}

/* The check's refusal is fill_options's, with its message. */
static void test_check(void)
{
	static const bvhlab_host seven = {
		.abi_version = BVHLAB_ABI_CURRENT, .struct_size = sizeof(bvhlab_host),
		.set_error = set_error, .option_bool = get_bool, .option_int = get_seven,
		.option_float = get_float, .option_string = get_string,
	};
	struct opts o;

	errors = 0;
	CHECK_INT(bvhlab_plugin_entry(BVHLAB_ABI_MAJOR)->fill_options(&seven, NULL, &o), -EINVAL);
	CHECK_INT(errors, 1);
	CHECK_CONTAINS(last_error, "option 'count' must not be 7");
}

/* Each bad entry alone: -EINVAL, one message naming it, nothing else read. */
static void test_bad_entries(void)
{
	static const plugin_option bad[][1] = {
		{ PLUGIN_OPTION(struct opts, count, U32, .name = "as_float",
		                .type = BVHLAB_OPTION_FLOAT, .min = 1, .max = 2) },
		{ PLUGIN_OPTION(struct opts, on, BOOL, .name = "as_int", .type = BVHLAB_OPTION_INT) },
		{ PLUGIN_OPTION(struct opts, count, U32, .name = "wide", .type = BVHLAB_OPTION_INT,
		                .min = 0, .max = 1e12) },
		{ PLUGIN_OPTION(struct opts, method, CHOICE, .name = "no_choices",
		                .type = BVHLAB_OPTION_STRING) },
		{ PLUGIN_OPTION(struct opts, label, STRING, .name = "as_bool",
		                .type = BVHLAB_OPTION_BOOL) },
	};
	struct opts o = { 0 };

	for (size_t k = 0; k < sizeof(bad) / sizeof(bad[0]); k++) {
		errors = 0;
		last_error[0] = '\0';
		CHECK_INT(plugin_options_fill(&host, NULL, bad[k], 1, &o), -EINVAL);
		CHECK_INT(errors, 1);
		CHECK_CONTAINS(last_error, bad[k][0].decl.name);
		CHECK_CONTAINS(last_error, "does not fit its declaration");
	}
	CHECK(o.count == 0 && !o.on && o.method == 0 && !o.label);
}

int main(void)
{
	test_entry();
	test_fill();
	test_check();
	test_bad_entries();
	return test_finish();
}
