/* Option values checked against a builder's declarations. */
#include <errno.h>
#include <string.h>

#include <bvhlab/bvhlab.h>

#include "testutil.h"

static const bvhlab_option_decl decls[] = {
	{.name = "bins", .type = BVHLAB_OPTION_INT, .help = "bins", .def_int = 32, .min = 2,
	 .max = 256},
	{.name = "method", .type = BVHLAB_OPTION_STRING, .help = "m", .def_string = "sweep",
	 .choices = "sweep|binned"},
	{.name = "fast", .type = BVHLAB_OPTION_BOOL, .help = "f", .def_bool = true, .min = 1},
	{.name = "c_trav", .type = BVHLAB_OPTION_FLOAT, .help = "c", .def_float = 1.0,
	 .min = 0.001, .max = 1000},
	{.name = "label", .type = BVHLAB_OPTION_STRING, .help = "free text"},
};
static const bvhlab_builder builder = {
	.abi_version = BVHLAB_ABI_CURRENT, .struct_size = sizeof(bvhlab_builder),
	.name = "demo", .option_count = 5, .options = decls};

static void test_defaults(bvhlab_options *o)
{
	CHECK_INT(o->values[0].i, 32);
	CHECK(strcmp(o->values[1].s, "sweep") == 0);
	CHECK(o->values[2].b);
	CHECK(o->values[3].f == 1.0);
	CHECK(o->values[4].s == NULL);
	CHECK_INT(bvhlab_options_find(o, "method"), 1);
	CHECK_INT(bvhlab_options_find(o, "nope"), -1);
}

static void test_setters(bvhlab_options *o)
{
	bvhlab_error err = {{0}};
	CHECK_INT(bvhlab_options_set_int(o, "bins", 16, &err), 0);
	CHECK_INT(o->values[0].i, 16);
	CHECK_INT(bvhlab_options_set_int(o, "bins", 1, &err), -EINVAL);
	CHECK_CONTAINS(err.message, "option 'bins' of plugin 'demo' is out of range: 1 not in [2, 256]");
	CHECK_INT(bvhlab_options_set_int(o, "bims", 4, &err), -ENOENT);
	CHECK_CONTAINS(err.message, "unknown option 'bims' for plugin 'demo' (known: bins, method");
	CHECK_INT(bvhlab_options_set_string(o, "bins", "x", &err), -EINVAL);
	CHECK_CONTAINS(err.message, "option 'bins' of plugin 'demo' must be an integer");
	CHECK_INT(bvhlab_options_set_string(o, "method", "median", &err), -EINVAL);
	CHECK_CONTAINS(err.message, "must be one of sweep|binned, not 'median'");
	CHECK_INT(bvhlab_options_set_string(o, "method", "binned", &err), 0);
	CHECK(strcmp(o->values[1].s, "binned") == 0);
	CHECK_INT(bvhlab_options_set_float(o, "c_trav", 0.0, &err), -EINVAL);
	CHECK_INT(bvhlab_options_set_float(o, "c_trav", 1.0 / 0.0, &err), -EINVAL);
	CHECK_CONTAINS(err.message, "finite");
	CHECK_INT(bvhlab_options_set_bool(o, "fast", false, &err), 0);
	CHECK(!o->values[2].b);
	CHECK_INT(bvhlab_options_set_string(o, "label", "anything", &err), 0);
}

static void test_parse(bvhlab_options *o)
{
	bvhlab_error err = {{0}};
	CHECK_INT(bvhlab_options_parse(o, "bins=64", &err), 0);
	CHECK_INT(o->values[0].i, 64);
	CHECK_INT(bvhlab_options_parse(o, "bins=6.5", &err), -EINVAL);
	CHECK_CONTAINS(err.message, "must be an integer, not '6.5'");
	CHECK_INT(bvhlab_options_parse(o, "bins=", &err), -EINVAL);
	CHECK_INT(bvhlab_options_parse(o, "bins", &err), -EINVAL);
	CHECK_CONTAINS(err.message, "must be written key=value");
	CHECK_INT(bvhlab_options_parse(o, "fast=yes", &err), 0);
	CHECK(o->values[2].b);
	CHECK_INT(bvhlab_options_parse(o, "fast=maybe", &err), -EINVAL);
	CHECK_CONTAINS(err.message, "must be a boolean");
	CHECK_INT(bvhlab_options_parse(o, "c_trav=2.5", &err), 0);
	CHECK(o->values[3].f == 2.5);
	CHECK_INT(bvhlab_options_parse(o, "zzz=1", &err), -ENOENT);
	CHECK_CONTAINS(err.message, "unknown option 'zzz'");

	char buf[64];
	bvhlab_option_format(&o->values[0], buf, sizeof(buf));
	CHECK(strcmp(buf, "64") == 0);
	bvhlab_option_format(&o->values[1], buf, sizeof(buf));
	CHECK(strcmp(buf, "\"binned\"") == 0);
	bvhlab_option_format(&o->values[2], buf, sizeof(buf));
	CHECK(strcmp(buf, "true") == 0);
	bvhlab_option_format(&o->values[3], buf, sizeof(buf));
	CHECK(strcmp(buf, "2.5") == 0);
	/* Shortest form that reads back exactly: 0.05 as typed, and all 17
	 * digits where fewer would lose the value. */
	CHECK_INT(bvhlab_options_parse(o, "c_trav=0.05", &err), 0);
	bvhlab_option_format(&o->values[3], buf, sizeof(buf));
	CHECK(strcmp(buf, "0.05") == 0);
	o->values[3].f = 0.1 + 0.2;
	bvhlab_option_format(&o->values[3], buf, sizeof(buf));
	CHECK(strcmp(buf, "0.30000000000000004") == 0);
}

int main(void)
{
	bvhlab_options o;
	CHECK_INT(bvhlab_options_init(&o, &builder), 0);
	test_defaults(&o);
	test_setters(&o);
	test_parse(&o);
	bvhlab_options_finish(&o);
	return test_finish();
}
