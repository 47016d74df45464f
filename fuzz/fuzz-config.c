/*
 * libFuzzer target: the config parser (config*.c, json_locate.c), and
 * each builder's "options" applied to a descriptor that declares every
 * option type, with ranges and choices.
 */
#include <stdint.h>
#include <stdlib.h>
#include <string.h>

#include <bvhlab/host.h>

#include "config/config.h"

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size);

static const bvhlab_option_decl decls[] = {
	{ .name = "method", .type = BVHLAB_OPTION_STRING, .def_string = "sweep",
	  .choices = "sweep|binned" },
	{ .name = "bins", .type = BVHLAB_OPTION_INT, .def_int = 32, .min = 2, .max = 256 },
	{ .name = "c_trav", .type = BVHLAB_OPTION_FLOAT, .def_float = 1, .min = 0, .max = 1e6 },
	{ .name = "flag", .type = BVHLAB_OPTION_BOOL, .min = 1, .max = 0 },
	{ .name = "label", .type = BVHLAB_OPTION_STRING, .def_string = "x" },
};

static const bvhlab_builder desc = {
	.abi_version = BVHLAB_ABI_CURRENT,
	.struct_size = sizeof(bvhlab_builder),
	.name = "fuzz",
	.option_count = sizeof(decls) / sizeof(decls[0]),
	.options = decls,
};

static void apply_options(const struct config *cfg)
{
	for (size_t i = 0; i < cfg->builder_count; i++) {
		bvhlab_options opts;
		bvhlab_error err = { "" };

		if (bvhlab_options_init(&opts, &desc) != 0)
			abort();
		if (config_apply_options(cfg, &cfg->builders[i], &opts, &err) != 0 && !err.message[0])
			abort();
		bvhlab_options_finish(&opts);
	}
}

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size)
{
	char *text = malloc(size + 1);
	struct config cfg;
	bvhlab_error err = { "" };

	if (!text)
		return 0;
	memcpy(text, data, size);
	text[size] = '\0';
	if (config_parse(&cfg, "fuzz/config.json", text, &err) == 0) {
		if (cfg.scene_count == 0 || cfg.builder_count == 0 || cfg.repeat == 0)
			abort();
		apply_options(&cfg);
	} else if (!err.message[0]) {
		abort(); /* a rejected config must say why */
	}
	config_finish(&cfg);
	free(text);
	return 0;
}
