/* bvhlab info: what a scene is. */
#include <getopt.h>
#include <stdio.h>
#include <stdlib.h>

#include <cJSON.h>

#include "cli.h"

static const char usage[] =
	"usage: bvhlab info SCENE [--subdivide K] [--json]\n"
	"\n"
	"Loads a scene and prints its triangle and vertex counts, degenerate\n"
	"(zero-area) triangles and bounds. SCENE is an .obj or .ply file, or a\n"
	"generator with parameters: icosphere:frequency=300, soup:count=100000,seed=2,\n"
	"stadium:count=50000, terrain:size=512.\n"
	"\n"
	"options:\n"
	"  --subdivide K    split every triangle into 4, K times\n"
	"  --json           print one JSON object (key \"triangles\", ...)\n";

static void print_json(const bvhlab_scene *s)
{
	cJSON *o = cJSON_CreateObject();
	cJSON_AddStringToObject(o, "name", s->name ? s->name : "");
	cJSON_AddStringToObject(o, "source", s->source ? s->source : "");
	cJSON_AddNumberToObject(o, "triangles", s->triangle_count);
	cJSON_AddNumberToObject(o, "vertices", s->vertex_count);
	cJSON_AddNumberToObject(o, "degenerate", s->degenerate_count);
	cJSON_AddItemToObject(o, "lo", cJSON_CreateFloatArray(s->bounds.lo, 3));
	cJSON_AddItemToObject(o, "hi", cJSON_CreateFloatArray(s->bounds.hi, 3));
	char *text = cJSON_Print(o);
	if (text)
		puts(text);
	free(text);
	cJSON_Delete(o);
}

static void print_text(const bvhlab_scene *s)
{
	printf("scene:      %s\nsource:     %s\ntriangles:  %u\nvertices:   %u\n"
	       "degenerate: %u\nbounds:     (%g, %g, %g) - (%g, %g, %g)\n",
	       s->name ? s->name : "", s->source ? s->source : "", s->triangle_count,
	       s->vertex_count, s->degenerate_count, s->bounds.lo[0], s->bounds.lo[1],
	       s->bounds.lo[2], s->bounds.hi[0], s->bounds.hi[1], s->bounds.hi[2]);
}

int cmd_info(int argc, char **argv)
{
	static const struct option longopts[] = {{"subdivide", required_argument, NULL, 's'},
	                                         {"json", no_argument, NULL, 'j'},
	                                         {"help", no_argument, NULL, 'h'},
	                                         {NULL, 0, NULL, 0}};
	unsigned long subdivide = 0;
	bool json = false;
	int c;
	while ((c = getopt_long(argc, argv, "h", longopts, NULL)) != -1) {
		if (c == 'h')
			return fputs(usage, stdout), 0;
		if (c == 's' && cli_parse_uint("--subdivide", optarg, 8, &subdivide) == 0)
			continue;
		if (c == 'j') {
			json = true;
			continue;
		}
		return EXIT_USAGE;
	}
	if (optind != argc - 1) {
		fprintf(stderr, "bvhlab info: expected one scene\n\n%s", usage);
		return EXIT_USAGE;
	}
	bvhlab_scene *scene = NULL;
	bvhlab_error err = {{0}};
	if (cli_load_scene(argv[optind], (unsigned)subdivide, &scene, &err) < 0) {
		fprintf(stderr, "bvhlab: %s\n", err.message);
		return EXIT_USAGE;
	}
	if (json)
		print_json(scene);
	else
		print_text(scene);
	bvhlab_scene_destroy(scene);
	return 0;
}
