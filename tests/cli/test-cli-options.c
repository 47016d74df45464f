/*
 * Every bundled plugin's every option, set wrong in a config (issue 40
 * item 5): a value of the wrong type, one out of its range (where it has
 * one), one that is not among its choices (where it has them; lbvh's bits
 * 31 too), and a malformed device for the device builders (their
 * fill_options check). Each is its own builder entry (a refine stage's
 * for a refine-only plugin); one `bvhlab run` per plugin must exit 2
 * before its output folder exists, refuse every entry, and say for each
 * the builder, the plugin, the option and what it allows.
 *
 * The plugins are those `bvhlab list` shows from the build's plugin folder
 * (the search path holds only it: no test fakes).
 */
#include <bvhlab/host.h>
#include <math.h>

#include "cliutil.h"

#define MAX_CASES 96

struct option_case {
	char name[16];     /* the builder entry's */
	const char *option;
	char value[48];    /* JSON */
	char expect[160];  /* what the message says is allowed */
};

static struct option_case cases[MAX_CASES];
static int case_count;

static struct option_case *add(const char *option, const char *expect)
{
	struct option_case *c = &cases[case_count];
	if (case_count == MAX_CASES)
		return NULL;
	snprintf(c->name, sizeof(c->name), "x%d", case_count++);
	c->option = option;
	snprintf(c->expect, sizeof(c->expect), "%s", expect);
	return c;
}

static const char *type_words(uint32_t type)
{
	switch (type) {
	case BVHLAB_OPTION_BOOL:
		return "must be true or false";
	case BVHLAB_OPTION_INT:
		return "must be an integer";
	case BVHLAB_OPTION_FLOAT:
		return "must be a finite number";
	default:
		return "must be a string";
	}
}

static bool is_choice(const char *choices, long long v)
{
	for (const char *p = choices; *p;) {
		char *end;
		if (strtoll(p, &end, 10) == v)
			return true;
		p = *end ? end + 1 : end;
	}
	return false;
}

/* A value just past the range: above it where there is room, else below. */
static void out_of_range(const bvhlab_option_decl *d, char *value, size_t size)
{
	if (d->type == BVHLAB_OPTION_INT)
		snprintf(value, size, "%.0f", d->max < 9e15 ? d->max + 1 : d->min - 1);
	else
		snprintf(value, size, "%.17g", d->max < 1e300 ? d->max + fabs(d->max) + 1
		                                               : d->min - fabs(d->min) - 1);
}

static void cases_of(const bvhlab_builder *b)
{
	struct option_case *c;
	char expect[160];
	for (uint32_t k = 0; k < b->option_count; k++) {
		const bvhlab_option_decl *d = &b->options[k];
		if ((c = add(d->name, type_words(d->type))))
			snprintf(c->value, sizeof(c->value), "%s",
			         d->type == BVHLAB_OPTION_STRING ? "7" : "\"seven\"");
		bool numeric = d->type == BVHLAB_OPTION_INT || d->type == BVHLAB_OPTION_FLOAT;
		snprintf(expect, sizeof(expect), "not in [%.15g, %.15g]", d->min, d->max);
		if (numeric && d->min <= d->max && (c = add(d->name, expect)))
			out_of_range(d, c->value, sizeof(c->value));
		snprintf(expect, sizeof(expect), "must be one of %s, not", d->choices);
		if (d->choices && d->type == BVHLAB_OPTION_STRING && (c = add(d->name, expect)))
			snprintf(c->value, sizeof(c->value), "\"no_such_choice\"");
		if (d->choices && d->type == BVHLAB_OPTION_INT && (c = add(d->name, expect))) {
			long long v = (long long)d->min;
			while (is_choice(d->choices, v))
				v++;
			snprintf(c->value, sizeof(c->value), "%lld", v);
		}
		if (!strcmp(d->name, "device") && (c = add(d->name, "allowed are auto, gpu, cpu")))
			snprintf(c->value, sizeof(c->value), "\"no_such_device\"");
	}
}

/* Each case a builder entry; a refine-only plugin's as a stage of sah_seq. */
static char *config_of(const bvhlab_builder *b, const char *out)
{
	static char text[1 << 14];
	size_t n = (size_t)snprintf(text, sizeof(text), "{ \"output\": \"%s\",\n"
	                            "  \"isolate\": false,\n"
	                            "  \"scenes\": [ { \"generator\": \"soup\", \"count\": 64 } ],\n"
	                            "  \"builders\": [\n", out);
	for (int k = 0; k < case_count && n < sizeof(text); k++) {
		const struct option_case *c = &cases[k];
		const char *sep = k + 1 < case_count ? "," : "";
		if (b->build)
			n += (size_t)snprintf(text + n, sizeof(text) - n,
			                      "    { \"name\": \"%s\", \"plugin\": \"%s\", "
			                      "\"options\": { \"%s\": %s } }%s\n",
			                      c->name, b->name, c->option, c->value, sep);
		else
			n += (size_t)snprintf(text + n, sizeof(text) - n,
			                      "    { \"name\": \"%s\", \"plugin\": \"sah_seq\", "
			                      "\"refine\": [ { \"plugin\": \"%s\", \"options\": "
			                      "{ \"%s\": %s } } ] }%s\n",
			                      c->name, b->name, c->option, c->value, sep);
	}
	if (n < sizeof(text))
		snprintf(text + n, sizeof(text) - n, "  ] }\n");
	return text;
}

/* The stderr line about builder entry `name`, copied into line. */
static bool line_of(const char *name, char *line, size_t size)
{
	char key[40];
	snprintf(key, sizeof(key), "builder '%.16s", name);
	for (const char *p = strstr(err_text, key); p; p = strstr(p + 1, key)) {
		char next = p[strlen(key)];
		if (next != '\'' && next != ',') /* x1 is not x12 */
			continue;
		const char *start = p, *end = strchr(p, '\n');
		while (start > err_text && start[-1] != '\n')
			start--;
		size_t len = end ? (size_t)(end - start) : strlen(start);
		snprintf(line, size, "%.*s", (int)(len < size ? len : size - 1), start);
		return true;
	}
	return false;
}

static void check_plugin(const bvhlab_builder *b)
{
	char out[64], plugin[80], option[80], line[1024], count[64];
	case_count = 0;
	cases_of(b);
	if (case_count == 0)
		return;
	CHECK(case_count < MAX_CASES);
	snprintf(out, sizeof(out), "out-%s", b->name);
	char *cfg = write_config("options.json", config_of(b, out));
	CHECK_INT(finish(start_in(tmpdir, 60, ARGS("run", "--quiet", cfg))), 2);
	CHECK(!cli_exists(cli_path_in(out)));
	snprintf(count, sizeof(count), ": %d builder%s cannot run as configured", case_count,
	         case_count == 1 ? "" : "s");
	CHECK_CONTAINS(err_text, count);
	snprintf(plugin, sizeof(plugin), "plugin '%s'", b->name);
	for (int k = 0; k < case_count; k++) {
		const struct option_case *c = &cases[k];
		snprintf(option, sizeof(option), "option '%s'", c->option);
		if (!line_of(c->name, line, sizeof(line))) {
			fprintf(stderr, "%s: no message for %s = %s\n", b->name, c->option, c->value);
			CHECK(false);
			continue;
		}
		CHECK_CONTAINS(line, plugin);
		CHECK_CONTAINS(line, option);
		CHECK_CONTAINS(line, c->expect);
	}
	printf("%s: %d wrong option values refused by name\n", b->name, case_count);
}

static void walk(void)
{
	const char *folder = BVHLAB_BUILD_PLUGIN_DIR "/";
	char **names = NULL;
	bvhlab_error err = {{0}};
	int plugins = 0;
	CHECK_INT(bvhlab_plugin_names(&names, &err), 0);
	for (size_t k = 0; names && names[k]; k++) {
		bvhlab_plugin *p = NULL;
		CHECK_INT(bvhlab_plugin_open(names[k], &p, &err), 0);
		if (p && strncmp(bvhlab_plugin_path(p), folder, strlen(folder)) == 0) {
			check_plugin(bvhlab_plugin_builder(p));
			plugins++;
		}
		bvhlab_plugin_close(p);
	}
	bvhlab_plugin_names_free(names);
	CHECK(plugins >= 13); /* the CPU builders and stages at least */
	printf("%d bundled plugins walked\n", plugins);
}

int main(int argc, char **argv)
{
	static const struct cli_mode modes[] = {{"all", walk}};
	return cli_main_modes(argc, argv, "test-cli-options", modes, 1);
}
