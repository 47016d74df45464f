/* bvhlab info: what a scene is, or what the machine is. */
#include <errno.h>
#include <getopt.h>
#include <stdio.h>
#include <stdlib.h>

#include <cJSON.h>

#include "cli.h"
#include "machine/machine.h"

static const char usage[] =
	"usage: bvhlab info SCENE [--subdivide K] [--json]\n"
	"       bvhlab info --machine [--json]\n"
	"\n"
	"Loads a scene and prints its triangle and vertex counts, degenerate\n"
	"(zero-area) triangles and bounds. SCENE is an .obj or .ply file, or a\n"
	"generator with parameters: icosphere:frequency=300, soup:count=100000,seed=2,\n"
	"stadium:count=50000, terrain:size=512, needles:count=1000,width=0.001, room,\n"
	"or a scene of an experiment config, CONFIG.json:NAME (composite scenes\n"
	"print their part count).\n"
	"\n"
	"With --machine, prints the CPU topology this process may use (hwloc,\n"
	"narrowed by its affinity mask and cgroup cpuset): packages, physical\n"
	"cores (what threads 0 means), logical CPUs and L1d/L2/L3 caches; then\n"
	"the OpenCL devices (name, kind, compute units, global memory, version)\n"
	"by the P:D a device option or rays.device names them by, or why there\n"
	"are none (OpenCL not built, no platform).\n"
	"\n"
	"options:\n"
	"  --subdivide K    split every triangle into 4, K times\n"
	"  --machine        describe the machine instead of a scene\n"
	"  --json           print one JSON object (key \"triangles\", ...)\n";

static void print_json(const bvhlab_scene *s)
{
	cJSON *o = cJSON_CreateObject();
	cJSON_AddStringToObject(o, "name", s->name ? s->name : "");
	cJSON_AddStringToObject(o, "source", s->source ? s->source : "");
	cJSON_AddNumberToObject(o, "triangles", s->triangle_count);
	cJSON_AddNumberToObject(o, "vertices", s->vertex_count);
	cJSON_AddNumberToObject(o, "degenerate", s->degenerate_count);
	cJSON_AddNumberToObject(o, "parts", s->part_count);
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
	printf("scene:      %s\nsource:     %s\nparts:      %u\ntriangles:  %u\n"
	       "vertices:   %u\ndegenerate: %u\nbounds:     (%g, %g, %g) - (%g, %g, %g)\n",
	       s->name ? s->name : "", s->source ? s->source : "", s->part_count,
	       s->triangle_count, s->vertex_count, s->degenerate_count, s->bounds.lo[0], s->bounds.lo[1],
	       s->bounds.lo[2], s->bounds.hi[0], s->bounds.hi[1], s->bounds.hi[2]);
}

/* "opencl": {"icd": how the driver was found, "devices": [...]} or {"error":
 * why there are none}. */
static void add_opencl_json(cJSON *o)
{
	struct machine_cl_device *d;
	size_t n;
	char why[512];
	cJSON *cl = cJSON_AddObjectToObject(o, "opencl");
	int r = machine_cl_devices(&d, &n, why, sizeof(why));
	cJSON_AddBoolToObject(cl, "built", r != -ENOTSUP);
	cJSON_AddStringToObject(cl, "icd", machine_icd_how());
	if (r < 0) {
		cJSON_AddStringToObject(cl, "error", why);
		return;
	}
	cJSON *list = cJSON_AddArrayToObject(cl, "devices");
	for (size_t k = 0; list && k < n; k++) {
		cJSON *e = cJSON_CreateObject();
		char spec[32];
		snprintf(spec, sizeof(spec), "%u:%u", d[k].platform_index, d[k].device_index);
		cJSON_AddStringToObject(e, "device", spec);
		cJSON_AddStringToObject(e, "platform", d[k].platform);
		cJSON_AddStringToObject(e, "name", d[k].name);
		cJSON_AddStringToObject(e, "kind", d[k].kind);
		cJSON_AddNumberToObject(e, "compute_units", d[k].compute_units);
		cJSON_AddNumberToObject(e, "global_mem_bytes", (double)d[k].global_mem);
		cJSON_AddStringToObject(e, "version", d[k].version);
		cJSON_AddItemToArray(list, e);
	}
	free(d);
}

static void print_machine_json(const struct machine_info *m)
{
	cJSON *o = cJSON_CreateObject();
	cJSON_AddStringToObject(o, "cpu", m->cpu);
	cJSON_AddNumberToObject(o, "packages", m->topo.packages);
	cJSON_AddNumberToObject(o, "physical_cores", m->topo.physical_cores);
	cJSON_AddNumberToObject(o, "logical_cpus", m->topo.logical_cpus);
	cJSON_AddNumberToObject(o, "threads_available", m->threads_available);
	cJSON_AddBoolToObject(o, "hwloc", m->topo.from_hwloc);
	cJSON *caches = cJSON_AddObjectToObject(o, "caches");
	for (int k = 0; caches && k < MACHINE_CACHE_LEVELS; k++) {
		if (m->topo.caches[k].size == 0)
			continue;
		cJSON *c = cJSON_AddObjectToObject(caches, machine_cache_name(k));
		cJSON_AddNumberToObject(c, "bytes", (double)m->topo.caches[k].size);
		cJSON_AddNumberToObject(c, "instances", m->topo.caches[k].instances);
	}
	add_opencl_json(o);
	char *text = cJSON_Print(o);
	if (text)
		puts(text);
	free(text);
	cJSON_Delete(o);
}

/* 49152 -> "48 KiB", 33554432 -> "32 MiB". */
static const char *size_text(uint64_t bytes, char *buf, size_t size)
{
	if (bytes >= (1u << 20) && bytes % (1u << 20) == 0)
		snprintf(buf, size, "%llu MiB", (unsigned long long)(bytes >> 20));
	else
		snprintf(buf, size, "%llu KiB", (unsigned long long)(bytes >> 10));
	return buf;
}

/* One line per OpenCL device, by the "P:D" a device spec names it by. */
static void print_opencl_text(void)
{
	struct machine_cl_device *d;
	size_t n;
	char why[512];
	int r = machine_cl_devices(&d, &n, why, sizeof(why));
	printf("OpenCL ICD: %s\n", machine_icd_how());
	if (r < 0) {
		printf("OpenCL:     %s\n", why);
		return;
	}
	if (n == 0)
		printf("OpenCL:     platforms but no device\n");
	for (size_t k = 0; k < n; k++)
		printf("%s %u:%u %s \"%s\" (%s), %u compute units, %.1f GiB, %s\n",
		       k ? "           " : "OpenCL:    ", d[k].platform_index, d[k].device_index,
		       d[k].kind, d[k].name, d[k].platform, d[k].compute_units,
		       (double)d[k].global_mem / (1u << 30), d[k].version);
	free(d);
}

static void print_machine_text(const struct machine_info *m)
{
	printf("cpu:        %s\npackages:   %u\ncores:      %u physical (threads 0 = %u)\n"
	       "logical:    %u CPUs\ncaches:    ",
	       m->cpu, m->topo.packages, m->topo.physical_cores, m->threads_available,
	       m->topo.logical_cpus);
	const char *sep = " ";
	for (int k = 0; k < MACHINE_CACHE_LEVELS; k++) {
		char buf[32];
		if (!m->topo.caches[k].size)
			continue;
		printf("%s%s %s x%u", sep, machine_cache_name(k),
		       size_text(m->topo.caches[k].size, buf, sizeof(buf)),
		       m->topo.caches[k].instances);
		sep = ", ";
	}
	printf("\nsource:     %s\n", m->topo.from_hwloc ? "hwloc" : "affinity mask (hwloc failed)");
	print_opencl_text();
}

static int info_machine(bool json)
{
	struct machine_info m;
	machine_info_read(&m);
	if (json)
		print_machine_json(&m);
	else
		print_machine_text(&m);
	return 0;
}

int cmd_info(int argc, char **argv)
{
	static const struct option longopts[] = {{"subdivide", required_argument, NULL, 's'},
	                                         {"json", no_argument, NULL, 'j'},
	                                         {"machine", no_argument, NULL, 'm'},
	                                         {"help", no_argument, NULL, 'h'},
	                                         {NULL, 0, NULL, 0}};
	unsigned long subdivide = 0;
	bool json = false, machine = false;
	int c;
	while ((c = getopt_long(argc, argv, "h", longopts, NULL)) != -1) {
		if (c == 'h')
			return fputs(usage, stdout), 0;
		if (c == 's' && cli_parse_uint("--subdivide", optarg, 8, &subdivide) == 0)
			continue;
		if (c == 'j' || c == 'm') {
			*(c == 'j' ? &json : &machine) = true;
			continue;
		}
		return EXIT_USAGE;
	}
	if (machine && optind == argc)
		return info_machine(json);
	if (machine || optind != argc - 1) {
		fprintf(stderr, "bvhlab info: expected one scene, or --machine alone\n\n%s", usage);
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
