/*
 * Issue 44's up-front memory estimate (cli-rel-estimate): a run whose
 * estimated peak (the scene's arrays plus the bytes per triangle its
 * builder declares, or the host's assumption for one that declares none)
 * exceeds memory_limit_mb is refused before anything is built, naming
 * scene, builder, estimate and limit; the sweep goes on, and a run that
 * fits records its estimate beside its measured memory per triangle, and
 * lbvh's measured bytes per triangle are within what it declares, its
 * whole run's within the estimate; a run whose builds would fit but whose
 * validation and tracing would not is refused as well.
 * Usage: test-cli-scale BVHLAB_EXE MODE
 */
#include <math.h>

#include "cliutil.h"

static double num_at(const cJSON *run, const char *object, const char *key)
{
	const cJSON *v = cJSON_GetObjectItem(cJSON_GetObjectItem(run, object), key);
	return cJSON_IsNumber(v) ? v->valuedouble : NAN;
}

/* A soup holds 3 vertices per triangle: 36 + 12 bytes of scene, 24 + 12
 * of primitive box and centroid. */
#define SOUP_SCENE_BYTES 84.0
#define TRIANGLES 300000

/* A run refused before building: "failed" with the estimate's message
 * naming scene and builder, no build figure, no memory; NULL if absent. */
static const cJSON *refused_run(const cJSON *doc, const char *builder)
{
	char named[128];
	const cJSON *run = find_run(doc, "big", builder, 1);
	CHECK(run != NULL);
	if (!run)
		return NULL;
	snprintf(named, sizeof(named), "scene 'big', builder '%s': refused before building: "
	         "estimated peak ", builder);
	CHECK_CONTAINS(run_str(run, "status"), "failed");
	CHECK_CONTAINS(run_str(run, "error"), named);
	CHECK(!cJSON_GetObjectItem(run, "build_ms") && !cJSON_GetObjectItem(run, "memory") &&
	      !cJSON_GetObjectItem(run, "tree"));
	return run;
}

/* "capped" would crash in build() (fail: segfault): refused first. */
static void check_refused(const cJSON *doc)
{
	const cJSON *run = refused_run(doc, "capped");
	if (!run)
		return;
	const char *error = run_str(run, "error");
	CHECK_CONTAINS(error, "300000 triangles x 400 bytes, the larger of the build's 400 per "
	                      "triangle (assumed, not declared) and validation and tracing's ");
	CHECK_CONTAINS(error, ") exceeds memory_limit_mb = 100");
	CHECK(!strstr(error, "SIGSEGV"));
	CHECK(num_at(run, "memory_estimate", "bytes") > num_at(run, "memory_estimate",
	                                                        "limit_bytes"));
	CHECK(num_at(run, "memory_estimate", "limit_bytes") == 100.0 * 1048576);
	CHECK(num_at(run, "memory_estimate", "scene_bytes") == SOUP_SCENE_BYTES * TRIANGLES);
}

/* "traced" (lbvh) would build within its limit, 60 MiB, but not validate
 * and trace after: refused too, for the tracing copies and the tree. */
static void check_refused_after(const cJSON *doc)
{
	const cJSON *run = refused_run(doc, "traced");
	if (!run)
		return;
	CHECK_CONTAINS(run_str(run, "error"), "(declared) and validation and tracing's 140) "
	                                      "exceeds memory_limit_mb = 60");
	double scene = num_at(run, "memory_estimate", "scene_bytes");
	double build = num_at(run, "memory_estimate", "bytes_per_triangle");
	double after = num_at(run, "memory_estimate", "after_bytes_per_triangle");
	double limit = num_at(run, "memory_estimate", "limit_bytes");
	CHECK(scene + build * TRIANGLES <= limit && after > build);
	CHECK(num_at(run, "memory_estimate", "bytes") == scene + after * TRIANGLES);
}

/* "free" (no limit: the memory available) fits and runs: its figures per
 * triangle add up, and its estimate is recorded. */
static void check_fitted(const cJSON *doc)
{
	const cJSON *run = find_run(doc, "big", "free", 1);
	CHECK(run != NULL);
	if (!run)
		return;
	CHECK_CONTAINS(run_str(run, "status"), "ok");
	double peak = num_at(run, "memory", "peak_bytes"), scene = num_at(run, "memory",
	                                                                   "scene_bytes");
	CHECK(scene == SOUP_SCENE_BYTES * TRIANGLES);
	CHECK(num_at(run, "memory", "scene_bytes_per_triangle") == SOUP_SCENE_BYTES);
	CHECK(fabs(num_at(run, "memory", "with_scene_bytes_per_triangle") -
	           (peak + scene) / TRIANGLES) < 1e-6);
	/* A quotient times its divisor is the dividend only to the last bit:
	 * exact equality failed for some resident sizes (seen under load). */
	double rss = num_at(run, "memory", "peak_rss_bytes");
	CHECK(rss > 0 && fabs(num_at(run, "memory", "child_bytes_per_triangle") * TRIANGLES - rss) <=
	                     1e-9 * rss);
	CHECK_CONTAINS(run_str(cJSON_GetObjectItem(run, "memory_estimate"), "limit"), "available");
}

/* lbvh declares its bytes per triangle (ABI 1.7): what it measured is
 * within them. */
static void check_declared(const cJSON *doc)
{
	const cJSON *run = find_run(doc, "big", "lbvh", 1);
	CHECK(run != NULL);
	if (!run)
		return;
	const cJSON *est = cJSON_GetObjectItem(run, "memory_estimate");
	CHECK(cJSON_IsTrue(cJSON_GetObjectItem(est, "declared")));
	double declared = num_at(run, "memory_estimate", "bytes_per_triangle");
	CHECK(declared > 0 && declared < 400);
	/* The whole run, validation and tracing too, within its estimate. */
	double run_peak = num_at(run, "memory", "run_peak_rss_bytes");
	double added = run_peak - num_at(run, "memory", "start_rss_bytes");
	CHECK(run_peak >= num_at(run, "memory", "peak_rss_bytes"));
	CHECK(fabs(num_at(run, "memory", "run_bytes_per_triangle") * TRIANGLES - run_peak) < 1);
#ifndef __SANITIZE_ADDRESS__ /* ASan's redzones and quarantine add to what is resident */
	CHECK(num_at(run, "memory", "build_bytes_per_triangle") <= declared);
	CHECK(added > 0 && added <= num_at(run, "memory_estimate", "bytes") -
	                            num_at(run, "memory_estimate", "scene_bytes"));
#else
	(void)added;
#endif
}

static void estimate(void)
{
	/* The estimate is of what is resident; meson's MALLOC_PERTURB_ writes
	 * every byte allocated, such as the wide tracing copy's capacity,
	 * which is sized for the worst tree and mostly never touched. */
	unsetenv("MALLOC_PERTURB_");
	int status = run_in(tmpdir, ARGS("run", "--quiet", write_config("est.json",
		"{ \"output\": \"out-est\", \"repeat\": 1, \"warmup\": 0, \"threads\": [1],\n"
		"  \"rays\": { \"width\": 8, \"height\": 8, \"min_ms\": 1, \"rounds\": 1 },\n"
		"  \"scenes\": [ { \"name\": \"big\", \"generator\": \"soup\", \"count\": 300000 } ],\n"
		"  \"builders\": [ { \"name\": \"capped\", \"plugin\": \"fake_good\",\n"
		"                    \"memory_limit_mb\": 100, \"options\": { \"fail\": \"segfault\" } },\n"
		"                  { \"name\": \"free\", \"plugin\": \"fake_good\" },\n"
		"                  { \"name\": \"traced\", \"plugin\": \"lbvh\",\n"
		"                    \"memory_limit_mb\": 60 },\n"
		"                  { \"plugin\": \"lbvh\" } ] }\n")));
	CHECK_INT(status, 1);
	cJSON *doc = load_results(cli_path_in("out-est"));
	check_refused(doc);
	check_refused_after(doc);
	check_fitted(doc);
	check_declared(doc);
	cJSON_Delete(doc);
}

int main(int argc, char **argv)
{
	static const struct cli_mode modes[] = {{"estimate", estimate}};
	return cli_main_modes(argc, argv, "test-cli-scale", modes, 1);
}
