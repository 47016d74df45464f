/* bvhlab render: one image of a tree, shaded or as a heat map. */
#include <errno.h>
#include <getopt.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "cli.h"
#include "harness/harness_rays.h"
#include "output/image.h"

#define MAX_OPTIONS 64

static const char render_usage[] =
	"usage: bvhlab render PLUGIN SCENE -o FILE [options]\n"
	"\n"
	"Builds a tree with PLUGIN over SCENE (a mesh file or generator spec) and\n"
	"writes one image of it, framed automatically: the shaded scene, or with\n"
	"--heat the nodes visited per pixel (scale from its own minimum to maximum).\n"
	"The format follows FILE's extension (.png, .jpg, ...).\n"
	"\n"
	"options:\n"
	"  -o FILE          the image to write (required)\n"
	"  --heat           a heat map of nodes visited instead of the shaded render\n"
	"  --width W        image width (default 512)\n"
	"  --height H       image height (default 512)\n"
	"  --threads N      build threads (default 1; 0 = all cores)\n"
	"  -O KEY=VALUE     a builder option (repeatable)\n";

struct render_args {
	const char *out;
	bool heat;
	unsigned long width, height, threads;
	const char *options[MAX_OPTIONS];
	int option_count;
};

static int parse_render(int argc, char **argv, struct render_args *a)
{
	static const struct option longopts[] = {
		{"heat", no_argument, NULL, 'H'},        {"width", required_argument, NULL, 'w'},
		{"height", required_argument, NULL, 'e'}, {"threads", required_argument, NULL, 't'},
		{"help", no_argument, NULL, 'h'},         {NULL, 0, NULL, 0}};
	int c, r = 0;
	while (r == 0 && (c = getopt_long(argc, argv, "ho:O:", longopts, NULL)) != -1) {
		if (c == 'h')
			exit((fputs(render_usage, stdout), 0));
		else if (c == 'o')
			a->out = optarg;
		else if (c == 'H')
			a->heat = true;
		else if (c == 'w')
			r = cli_parse_uint("--width", optarg, 16384, &a->width);
		else if (c == 'e')
			r = cli_parse_uint("--height", optarg, 16384, &a->height);
		else if (c == 't')
			r = cli_parse_uint("--threads", optarg, 4096, &a->threads);
		else if (c == 'O' && a->option_count < MAX_OPTIONS)
			a->options[a->option_count++] = optarg;
		else
			r = -1;
	}
	if (r == 0 && (optind != argc - 2 || !a->out || !a->width || !a->height)) {
		fprintf(stderr, "bvhlab render: expected PLUGIN, SCENE and -o FILE\n\n%s",
		        render_usage);
		r = -1;
	}
	return r;
}

/* Pixels of the image the arguments ask for, into rgb. */
static int draw(const bvhlab_tree *tree, const bvhlab_scene *scene, const struct render_args *a,
                uint8_t *rgb)
{
	size_t n = a->width * a->height;
	uint32_t *nodes = a->heat ? malloc(n * sizeof(*nodes)) : NULL, lo = UINT32_MAX, hi = 0;
	struct ray_metrics m;
	struct ray_settings rs;
	bvhlab_camera cam;
	if (a->heat && !nodes)
		return -ENOMEM;
	harness_camera(NULL, scene, &cam);
	harness_ray_settings(NULL, &rs);
	rs.width = (uint32_t)a->width;
	rs.height = (uint32_t)a->height;
	int r = harness_trace_rays(tree, scene, &cam, &rs, &m, nodes, a->heat ? NULL : rgb);
	for (size_t i = 0; r == 0 && nodes && i < n; i++) {
		lo = nodes[i] < lo ? nodes[i] : lo;
		hi = nodes[i] > hi ? nodes[i] : hi;
	}
	if (r == 0 && nodes) {
		image_heat(nodes, n, lo, hi, rgb);
		printf("heat scale: %u to %u nodes per ray\n", lo, hi);
	}
	free(nodes);
	return r;
}

static int render(bvhlab_plugin *p, const bvhlab_options *opts, const bvhlab_scene *scene,
                  const struct render_args *a, bvhlab_error *err)
{
	bvhlab_prims prims = {0};
	bvhlab_tree tree = {0};
	uint8_t *rgb = malloc(a->width * a->height * 3);
	int r = rgb ? bvhlab_prims_init(&prims, scene, err) : -ENOMEM;
	if (r == 0)
		r = bvhlab_build(p, opts, &prims.input, (uint32_t)a->threads, &tree, err);
	if (r == 0 && (r = bvhlab_validate_tree(&tree, &prims.input, true, err)) == 0)
		r = draw(&tree, scene, a, rgb);
	if (r == 0)
		r = image_write_rgb8(a->out, (int)a->width, (int)a->height, rgb, err);
	bvhlab_tree_finish(&tree);
	bvhlab_prims_finish(&prims);
	free(rgb);
	return r;
}

int cmd_render(int argc, char **argv)
{
	struct render_args a = {.width = 512, .height = 512, .threads = 1};
	struct cli_target t;
	if (parse_render(argc, argv, &a) < 0 ||
	    cli_target_open(&t, argv[optind], argv[optind + 1], 0, a.options, a.option_count) < 0)
		return EXIT_USAGE;
	bvhlab_error err = {{0}};
	int status = 0;
	if (render(t.plugin, &t.opts, t.scene, &a, &err) < 0) {
		fprintf(stderr, "bvhlab: %s\n", err.message[0] ? err.message : "out of memory");
		status = EXIT_RUNS_FAILED;
	}
	cli_target_close(&t);
	return status;
}
