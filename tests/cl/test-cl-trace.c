/*
 * The device traversals through the bvhlab command (rays.traversal
 * device_stack, device_stackless and device_wide8, core/trace/trace_cl*.cl):
 *   trace   every hit of every primary and diffuse ray equal, bit for bit,
 *           to the CPU stack traversal's, and every shadow and AO ray
 *           blocked or not as the CPU's (rays.traversal_disagreements 0),
 *           and the nodes counted per ray equal to the CPU stack and
 *           stackless traversals' own, on the trees of several builders
 *           and on lbvh's collapsed into 4- and 8-wide trees (the
 *           wide_collapse test stage: the kernels read the open tree as
 *           the CPU does), over a shared mesh and degenerate scenes (one
 *           triangle, two, 50 copies of one triangle: all centroids equal
 *           and every hit a tie in t, zero-area triangles, needles), timed
 *           in rounds;
 *   errors  a bad rays.device is a config error naming the key; a device
 *           that does not exist, or no OpenCL platform at all, leaves the
 *           runs ok with rays.error saying why; a two-level run (20
 *           instances) traces its primary rays with the device traversals
 *           too, as above, and with no platform is ok, saying why;
 *           info --machine lists the device.
 * Skips (77) when this machine has no OpenCL device. PoCL runs under ASan
 * and TSan (checked; under TSan not in a forked child, see run_rays);
 * sanitizer builds leave out the bunny (CL_TRACE_NO_MESH), which the
 * release build traces.
 * Usage: test-cl-trace BVHLAB_EXE trace|errors
 */
#include <math.h>
#include <stdlib.h>

#include <bvhlab/opencl.h>

#include "../cli/cliutil.h"
#include "cl_device.h"

static const char rays_keys[] =
	"\"rays\": { \"width\": 40, \"height\": 30, \"diffuse\": 2, \"min_ms\": 1, \"rounds\": 2,\n"
	"  \"kinds\": [\"primary\", \"diffuse\", \"shadow\", \"ao\"],\n"
	"  \"traversal\": [\"stack\", \"stackless\", {\"name\": \"stack\", \"device\": true},\n"
	"    {\"name\": \"stackless\", \"device\": true}, {\"name\": \"wide8\", \"device\": true}] },\n";

/* A triangle repeated: every ray that hits one hits all 50 at the same t. */
static void write_meshes(void)
{
	char text[8192];
	size_t n = 0;
	write_config("one.obj", "v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 3\n");
	write_config("two.obj", "v 0 0 0\nv 1 0 0\nv 0 1 0\nv 1 1 0.5\nf 1 2 3\nf 2 4 3\n");
	n += (size_t)snprintf(text + n, sizeof(text) - n, "v -1 -1 0\nv 1 -1 0\nv 0 1 0.2\n");
	for (int i = 0; i < 50; i++)
		n += (size_t)snprintf(text + n, sizeof(text) - n, "f 1 2 3\n");
	write_config("same.obj", text);
	/* zero-area triangles (collinear, and a point) beside a real one */
	write_config("flat.obj", "v 0 0 0\nv 1 0 0\nv 2 0 0\nv 0 1 0\nv 3 3 3\n"
	                         "f 1 2 3\nf 5 5 5\nf 1 2 4\nf 2 3 4\nf 1 3 2\n");
}

static double num(const cJSON *run, const char *a, const char *b, const char *c)
{
	const cJSON *v = cJSON_GetObjectItem(cJSON_GetObjectItem(run, "rays"), a);
	if (b)
		v = cJSON_GetObjectItem(v, b);
	if (c)
		v = cJSON_GetObjectItem(v, c);
	return cJSON_IsNumber(v) ? v->valuedouble : NAN;
}

/* A run's device traversals against its CPU ones over its first `kinds`
 * ray kinds (primary, diffuse, shadow, ao). */
static void check_run_kinds(const cJSON *run, int kinds_traced)
{
	const cJSON *rays = cJSON_GetObjectItem(run, "rays");
	const char *what = run_str(run, "scene");
	if (strcmp(run_str(run, "status"), "ok") != 0 || !rays)
		fprintf(stderr, "%s / %s: %s %s\n", what, run_str(run, "builder"),
		        run_str(run, "status"), run_str(run, "error"));
	CHECK(rays != NULL);
	CHECK(cJSON_GetObjectItem(rays, "error") == NULL);
	CHECK(strlen(run_str(rays, "device")) > 0);
	CHECK(num(run, "traversal_disagreements", NULL, NULL) == 0);
	static const char *const kinds[] = {"primary", "diffuse", "shadow", "ao"};
	for (int k = 0; k < kinds_traced; k++) {
		double n = num(run, kinds[k], "rays", NULL);
		CHECK(num(run, "device_stack", kinds[k], "rays") == n);
		CHECK(num(run, "device_stackless", kinds[k], "rays") == n);
		CHECK(num(run, "device_wide8", kinds[k], "rays") == n);
		if (k >= 2) /* any hit: blocked or not, agreement checked above */
			continue;
		/* The same walk: the same nodes entered, summed over the rays. */
		CHECK(num(run, "device_stack", kinds[k], "nodes_per_ray") ==
		      num(run, kinds[k], "nodes_per_ray", NULL));
		CHECK(num(run, "device_stackless", kinds[k], "nodes_per_ray") ==
		      num(run, "stackless", kinds[k], "nodes_per_ray"));
		CHECK(num(run, "device_stack", kinds[k], "tris_per_ray") ==
		      num(run, kinds[k], "tris_per_ray", NULL));
		if (n > 0) {
			CHECK(num(run, "device_stack", kinds[k], "mrays_per_s") > 0);
			CHECK(num(run, "device_stackless", kinds[k], "wall_mrays_per_s") > 0);
			CHECK(num(run, "device_wide8", kinds[k], "mrays_per_s") > 0);
			/* its own count: compressed nodes entered */
			CHECK(num(run, "device_wide8", kinds[k], "nodes_per_ray") > 0);
		}
	}
}

static void check_run(const cJSON *run)
{
	check_run_kinds(run, 4);
}

/* lbvh's tree collapsed into 4- and 8-wide ones (tests/fake/wide_collapse). */
#define WIDE_BUILDERS                                                                      \
	"{ \"plugin\": \"lbvh\", \"name\": \"lbvh_w4\", \"refine\": [ { \"plugin\": "          \
	"\"wide_collapse\", \"options\": { \"width\": 4 } } ] },\n"                               \
	"    { \"plugin\": \"lbvh\", \"name\": \"lbvh_w8\", \"refine\": [ { \"plugin\": "      \
	"\"wide_collapse\", \"options\": { \"width\": 8 } } ] }"

/* One sweep over these scenes and builders (`per_builder` runs each); its
 * runs checked. */
static void trace_sweep(const char *name, const char *scenes, const char *builders,
                        int builder_count, int per_builder)
{
	int runs = builder_count * per_builder;
	char config[4096], out[600];
	snprintf(config, sizeof(config),
	         "{ \"format_version\": 1, \"output\": \"%s\", \"repeat\": 1, \"warmup\": 0,\n"
	         "  \"threads\": [1], \"validate_rays\": 16, \"isolate\": false, %s"
	         "  \"scenes\": [ %s ],\n  \"builders\": [ %s ] }\n",
	         name, rays_keys, scenes, builders);
	snprintf(out, sizeof(out), "%s.json", name);
	char *path = write_config(out, config);
	int rc = run(ARGS("run", path, "--quiet"));
	if (rc != 0)
		fprintf(stderr, "%s", err_text);
	CHECK_INT(rc, 0);
	snprintf(out, sizeof(out), "%s/%s", tmpdir, name);
	cJSON *doc = load_results(out);
	const cJSON *r;
	int n = 0;
	cJSON_ArrayForEach(r, cJSON_GetObjectItem(doc, "runs")) {
		check_run(r);
		n++;
	}
	CHECK_INT(n, runs);
	CHECK_INT(count_runs(doc, "lbvh", "ok"), per_builder);
	CHECK_INT(count_runs(doc, "lbvh_w4", "ok"), per_builder);
	CHECK_INT(count_runs(doc, "lbvh_w8", "ok"), per_builder);
	cJSON_Delete(doc);
}

/* "isolate": false: one process, so PoCL builds the kernels once. sbvh
 * (references duplicated by spatial splits) only on the small scenes:
 * it takes seconds on the bunny. */
static void trace_mode(void)
{
	char scene[1024];
	write_meshes();
	snprintf(scene, sizeof(scene), "{ \"path\": \"%s/stanford-bunny.obj\" }",
	         BVHLAB_SHARED_SCENES);
	if (getenv("CL_TRACE_NO_MESH")) /* a sanitizer build: the release build has it */
		printf("the bunny left to the release build (CL_TRACE_NO_MESH)\n");
	else
		trace_sweep("mesh", scene, "{ \"plugin\": \"lbvh\" }, { \"plugin\": \"ploc\" }, "
		            "{ \"plugin\": \"sah_tasks\" },\n    " WIDE_BUILDERS, 5, 1);
	trace_sweep("degenerate",
	            "{ \"path\": \"one.obj\" }, { \"path\": \"two.obj\" },\n"
	            "    { \"path\": \"same.obj\" }, { \"path\": \"flat.obj\" },\n"
	            "    { \"name\": \"needles\", \"generator\": \"needles\", \"count\": 300 }",
	            "{ \"plugin\": \"lbvh\" }, { \"plugin\": \"ploc\" }, { \"plugin\": \"sah_tasks\" },\n"
	            "    { \"plugin\": \"sbvh\" }, " WIDE_BUILDERS,
	            6, 5);
}

/* `bvhlab run` of this config, written as NAME.json, exiting want_rc; the
 * document of its output folder NAME (NULL for exit 2). */
static cJSON *run_config(const char *name, const char *config, int want_rc)
{
	char out[600];
	snprintf(out, sizeof(out), "%s.json", name);
	int rc = run(ARGS("run", write_config(out, config), "--quiet"));
	if (rc != want_rc)
		fprintf(stderr, "%s: %s", name, err_text);
	CHECK_INT(rc, want_rc);
	if (want_rc == 2)
		return NULL;
	snprintf(out, sizeof(out), "%s/%s", tmpdir, name);
	return load_results(out);
}

/* A run of one scene with this "rays" object; the document. */
static cJSON *run_rays(const char *name, const char *rays, int want_rc)
{
	char config[2048];
	/* Isolated (each run in a forked child) as a sweep runs, except under
	 * TSan: it kills a child of bvhlab's (multi-threaded) process that
	 * starts threads, as PoCL does ("starting new threads after
	 * multi-threaded fork is not supported"). */
	snprintf(config, sizeof(config),
	         "{ \"format_version\": 1, \"output\": \"%s\", \"repeat\": 1, \"threads\": [1],\n"
	         "  \"isolate\": %s, \"rays\": %s,\n"
	         "  \"scenes\": [ { \"name\": \"ico\", \"generator\": \"icosphere\", \"frequency\": 4 } ],\n"
	         "  \"builders\": [ { \"plugin\": \"sah_seq\" } ] }\n", name,
	         UNDER_TSAN ? "false" : "true", rays);
	return run_config(name, config, want_rc);
}

static const cJSON *first_rays(const cJSON *doc)
{
	const cJSON *run = cJSON_GetArrayItem(cJSON_GetObjectItem(doc, "runs"), 0);
	CHECK(strcmp(run_str(run, "status"), "ok") == 0);
	return cJSON_GetObjectItem(run, "rays");
}

static void errors_mode(void)
{
	run_rays("bad", "{ \"traversal\": {\"name\": \"stack\", \"device\": true}, "
	         "\"device\": \"banana\" }", 2);
	CHECK_CONTAINS(err_text, "'rays.device' must be \"auto\", \"gpu\", \"cpu\" or \"P:D\"");
	CHECK_CONTAINS(err_text, "not \"banana\"");

	/* No such device: the CPU traversal is measured, the device one says why. */
	cJSON *doc = run_rays("nodev", "{ \"width\": 8, \"height\": 8, \"min_ms\": 1, "
	                      "\"traversal\": [\"stack\", {\"name\": \"stack\", \"device\": true}], "
	                      "\"device\": \"7:3\" }", 0);
	const cJSON *rays = first_rays(doc);
	CHECK(cJSON_GetObjectItem(rays, "primary") != NULL);
	CHECK(cJSON_GetObjectItem(rays, "device_stack") == NULL);
	CHECK_CONTAINS(run_str(rays, "error"), "device_stack: cl: device '7:3': no such OpenCL device");
	cJSON_Delete(doc);

	/* No platform at all (the ICD loader finds no vendor file): the main
	 * traversal fails, the run stays ok and its rays say why. */
	setenv("OCL_ICD_VENDORS", "/nonexistent-bvhlab-vendors", 1);
	doc = run_rays("noplat", "{ \"width\": 8, \"height\": 8, \"traversal\": "
	               "{\"name\": \"stackless\", \"device\": true} }", 0);
	rays = first_rays(doc);
	CHECK(cJSON_GetObjectItem(rays, "primary") == NULL);
	CHECK(strcmp(run_str(rays, "traversal"), "device_stackless") == 0);
	CHECK_CONTAINS(run_str(rays, "error"), "device_stackless: cl: no OpenCL platform found");
	CHECK_CONTAINS(run_str(rays, "error"), "pocl-opencl-icd");
	cJSON_Delete(doc);
	CHECK_INT(run(ARGS("info", "--machine")), 0);
	CHECK_CONTAINS(out_text, "OpenCL:     cl: no OpenCL platform found");
	unsetenv("OCL_ICD_VENDORS");
}

/* A two-level scene (20 instances of one sphere) with this "rays" object
 * (its main traversal "stack", the others any); its run's rays. */
static cJSON *run_two_level(const char *name, const char *traversals)
{
	char config[2048];
	snprintf(config, sizeof(config),
	         "{ \"format_version\": 1, \"output\": \"%s\", \"repeat\": 1, \"threads\": [1],\n"
	         "  \"isolate\": %s, \"rays\": { \"width\": 16, \"height\": 16, \"min_ms\": 1,\n"
	         "    \"traversal\": [\"stack\", %s] },\n"
	         "  \"scenes\": [ { \"name\": \"grove\", \"meshes\": [ { \"name\": \"ball\",\n"
	         "    \"generator\": \"icosphere\", \"frequency\": 2 } ], \"instances\": [\n"
	         "    { \"scatter\": { \"mesh\": \"ball\", \"count\": 20, \"seed\": 3,\n"
	         "      \"bounds\": [[-5, 0, -5], [5, 1, 5]], \"scale\": [0.5, 1.5],\n"
	         "      \"rotate\": \"random-y\" } } ] } ],\n"
	         "  \"builders\": [ { \"bottom\": \"sah_seq\", \"top\": \"lbvh\" } ] }\n", name,
	         UNDER_TSAN ? "false" : "true", traversals);
	return run_config(name, config, 0);
}

/* Two-level runs trace with the device traversals too: the same hits as
 * the CPU's, the same nodes entered as the CPU stack and stackless
 * traversals'; with no OpenCL platform the run is ok and says why. */
static void two_level_mode(void)
{
	cJSON *doc = run_two_level("inst", "\"stackless\", {\"name\": \"stack\", \"device\": true}, "
	                           "{\"name\": \"stackless\", \"device\": true}, "
	                           "{\"name\": \"wide8\", \"device\": true}");
	const cJSON *run = cJSON_GetArrayItem(cJSON_GetObjectItem(doc, "runs"), 0);
	check_run_kinds(run, 1);
	CHECK(num(run, "primary", "rays", NULL) == 256);
	cJSON_Delete(doc);
	setenv("OCL_ICD_VENDORS", "/nonexistent-bvhlab-vendors", 1);
	doc = run_two_level("inst-noplat", "{\"name\": \"stack\", \"device\": true}");
	run = cJSON_GetArrayItem(cJSON_GetObjectItem(doc, "runs"), 0);
	const cJSON *rays = first_rays(doc);
	CHECK(cJSON_GetObjectItem(rays, "device_stack") == NULL);
	CHECK(num(run, "primary", "rays", NULL) == 256);
	CHECK_CONTAINS(run_str(rays, "error"), "device_stack: cl: no OpenCL platform found");
	cJSON_Delete(doc);
	unsetenv("OCL_ICD_VENDORS");
}

/* info --machine names the device the layer picks for "auto". */
static void info_mode(const char *device)
{
	CHECK_INT(run(ARGS("info", "--machine")), 0);
	CHECK_CONTAINS(out_text, "OpenCL:     0:");
	CHECK_CONTAINS(out_text, device);
	CHECK_INT(run(ARGS("info", "--machine", "--json")), 0);
	cJSON *doc = cJSON_Parse(out_text);
	const cJSON *devs = cJSON_GetObjectItem(cJSON_GetObjectItem(doc, "opencl"), "devices");
	CHECK(cJSON_GetArraySize(devs) >= 1);
	CHECK(cJSON_GetObjectItem(cJSON_GetArrayItem(devs, 0), "compute_units") != NULL);
	cJSON_Delete(doc);
}

int main(int argc, char **argv)
{
	char device[sizeof(((bvhlab_cl *)0)->name)];
	if (!cli_begin(argc, argv))
		return 99;
	if (!cl_device_present(device, sizeof(device)))
		return TEST_SKIP;
	if (strcmp(argv[2], "trace") == 0) {
		trace_mode();
	} else if (strcmp(argv[2], "errors") == 0) {
		errors_mode();
		two_level_mode();
		info_mode(device);
	} else {
		return 99;
	}
	return cli_end();
}
