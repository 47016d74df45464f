/*
 * The report's verdicts, from hand-written points and results documents
 * with every figure computed by hand: the Pareto front and who dominates
 * whom, the break-even ray counts, the reference's fallback when the one
 * asked for did not run, the noise and load marks, no empty tables, no
 * speedup for a builder that ran on 1 thread only, and build_phases; a
 * merged sweep's machines never compared with each other, heat maps
 * drawn on different scales each stated with its own, and the charts: no
 * name or leader line over another point, whole ticks for thread counts.
 */
#include <math.h>

#include <cJSON.h>

#include "output/report.h"
#include "output/results.h"
#include "testutil.h"

static void test_front_points(void)
{
	/* A and B on the front of group 1; C behind A; D behind both, and B,
	 * the faster, is named; F equals A (neither dominates); E alone in
	 * group 2; G lacks a figure; H is 0.025 % better than A but slower:
	 * within the tolerance, A dominates it. */
	const struct front_point p[] = {
		{10, 40, 1}, {5, 42, 1}, {12, 41, 1}, {11, 44, 1}, {100, 50, 2}, {10, 40, 1},
		{1, NAN, 1}, {10.5, 39.99, 1}};
	long by[8];
	char buf[128];
	report_front_points(p, 8, by);
	CHECK_INT(by[7], 0);
	report_front_text(buf, sizeof(buf), p, by[7], 7, "A", "SAH");
	CHECK(strcmp(buf, "dominated by A (0.95× time, same SAH)") == 0);
	CHECK_INT(by[0], FRONT_ON);
	CHECK_INT(by[1], FRONT_ON);
	CHECK_INT(by[2], 0);
	CHECK_INT(by[3], 1);
	CHECK_INT(by[4], FRONT_ON);
	CHECK_INT(by[5], FRONT_ON);
	CHECK_INT(by[6], FRONT_NONE);
	/* 10 / 12 = 0.83; (40 - 41) / 41 = -2.44 %. */
	report_front_text(buf, sizeof(buf), p, by[2], 2, "A", "SAH");
	CHECK(strcmp(buf, "dominated by A (0.83× time, −2.4 % SAH)") == 0);
	/* 5 / 11 = 0.45; (42 - 44) / 44 = -4.55 %. */
	report_front_text(buf, sizeof(buf), p, by[3], 3, "B", "SAH");
	CHECK(strcmp(buf, "dominated by B (0.45× time, −4.5 % SAH)") == 0);
	report_front_text(buf, sizeof(buf), p, by[0], 0, "", "SAH");
	CHECK(strcmp(buf, "front") == 0);
}

static void test_breakeven(void)
{
	char buf[128];
	/* 10 ms more to build, 1e-7 s less per ray: 100,000 rays. */
	struct breakeven b = report_breakeven(20, 10, 10, 5);
	CHECK_INT(b.kind, BREAKEVEN_AFTER);
	CHECK(fabs(b.rays - 1e5) < 1e-3);
	report_breakeven_text(buf, sizeof(buf), b, 10000);
	CHECK(strcmp(buf, "after 100.0 k rays (10.0 frames)") == 0);
	b = report_breakeven(10, 5, 20, 10);
	CHECK_INT(b.kind, BREAKEVEN_UNTIL);
	CHECK(fabs(b.rays - 1e5) < 1e-3);
	CHECK_INT(report_breakeven(5, 10, 10, 5).kind, BREAKEVEN_ALWAYS);
	CHECK_INT(report_breakeven(20, 5, 10, 10).kind, BREAKEVEN_NEVER);
	CHECK_INT(report_breakeven(10, 5, 10, 5).kind, BREAKEVEN_SAME);
	CHECK_INT(report_breakeven(10, NAN, 10, 5).kind, BREAKEVEN_NONE);
}

/* A run of scene s: build median (min, max), SAH, primary and diffuse Mrays/s. */
static void add_run(cJSON *runs, const char *builder, const char *plugin, int threads,
                    const double ms[3], double sah, double nodes_per_ray, double mrays,
                    double diffuse)
{
	char text[1024];
	snprintf(text, sizeof(text),
	         "{\"scene\": \"s\", \"builder\": \"%s\", \"plugin\": \"%s\", \"threads\": %d, "
	         "\"status\": \"ok\", \"build_ms\": {\"median\": %g, \"min\": %g, \"max\": %g}, "
	         "\"tree\": {\"sah_cost\": %g, \"nodes\": %d}, \"rays\": {\"primary\": "
	         "{\"rays\": 10000, \"mrays_per_s\": %g, \"nodes_per_ray\": %g, "
	         "\"tris_per_ray\": 2}, "
	         "\"diffuse\": {\"mrays_per_s\": %g, \"nodes_per_ray\": 20}}}",
	         builder, plugin, threads, ms[0], ms[1], ms[2], sah, (int)sah * 10, mrays,
	         nodes_per_ray, diffuse);
	cJSON_AddItemToArray(runs, cJSON_Parse(text));
}

/* No sah_seq ran: fast (the first builder) is the reference. */
static cJSON *document(const char *reference)
{
	char text[512];
	snprintf(text, sizeof(text),
	         "{\"machine\": {\"cpu\": \"test\", \"cores\": 2, \"threads_available\": 2}, "
	         "\"config\": {%s}, \"scenes\": [{\"name\": \"s\", \"triangles\": 100}], "
	         "\"runs\": []}", reference);
	cJSON *doc = cJSON_Parse(text), *runs = cJSON_GetObjectItem(doc, "runs");
	add_run(runs, "fast", "lbvh", 1, (double[]){2, 2, 2}, 50, 12, 10, 5);
	/* Spread (11 - 9) / 10 = 20 %: noisy. */
	add_run(runs, "mid", "sah_tasks", 1, (double[]){10, 9, 11}, 40, 9, 12.5, 6);
	add_run(runs, "slow", "sbvh", 1, (double[]){20, 20, 20}, 45, 10, 11, 5.5);
	/* fast's very tree, traced 25 % slower: both marked noisy. */
	add_run(runs, "twin", "lbvh", 1, (double[]){2.2, 2.2, 2.2}, 50, 12, 8, 5);
	add_run(runs, "fast", "lbvh", 2, (double[]){1.5, 1.5, 1.5}, 50, 12, 10, 5);
	/* A parallel builder that mid, on 1 thread only, beats on 2 threads too. */
	add_run(runs, "par", "sah_queue", 1, (double[]){30, 30, 30}, 45, 11, 11, 5);
	add_run(runs, "par", "sah_queue", 2, (double[]){15, 15, 15}, 45, 11, 11, 5);
	/* Load 3.5 on 2 CPUs with 1 build thread: 3.5 - 1 > 1 core free. */
	cJSON *slow = cJSON_GetArrayItem(runs, 2);
	cJSON_AddNumberToObject(slow, "load_before", 3.5);
	cJSON_AddNumberToObject(slow, "load_after", 3.0);
	cJSON *mid = cJSON_GetArrayItem(runs, 1);
	cJSON_AddNumberToObject(mid, "load_before", 1.5); /* 1.5 - 1 <= 1: not busy */
	cJSON_AddNumberToObject(mid, "load_after", 1.9);
	cJSON_AddItemToObject(mid, "build_phases", cJSON_Parse("{\"upload\": 0.5, \"device\": 1.5}"));
	/* load_other, where there, decides: the sweep's own 2 threads keep the
	 * 1-minute average at 2, but others used 0.1 of a CPU (not busy); on
	 * 1 thread, others using 1.6 CPUs leave it less than its free core. */
	int n = cJSON_GetArraySize(runs);
	cJSON *par1 = cJSON_GetArrayItem(runs, n - 2), *par2 = cJSON_GetArrayItem(runs, n - 1);
	cJSON_AddNumberToObject(par2, "load_before", 2.0);
	cJSON_AddNumberToObject(par2, "load_after", 2.0);
	cJSON_AddNumberToObject(par2, "load_other", 0.1);
	cJSON_AddNumberToObject(par1, "load_before", 0.5);
	cJSON_AddNumberToObject(par1, "load_after", 0.5);
	cJSON_AddNumberToObject(par1, "load_other", 1.6);
	return doc;
}

static void test_markdown_fallback(void)
{
	cJSON *doc = document("");
	char *md = report_markdown(doc);
	CHECK_CONTAINS(md, "(report.reference: 'sah_seq') did not run, so the reference is the "
	                   "first builder that did: fast.");
	CHECK_CONTAINS(md, "reference builder **fast**");
	/* Summary and scene front: slow behind mid, 10 / 20 and (40 - 45) / 45. */
	CHECK_CONTAINS(md, "| slow | 1 | 1 | 10.00× | 0.90× | n/a | 0.83× | 1.00× | dominated on 1 "
	                   "of 1 scene by mid |");
	/* Ray cost: 10 + 2 and 9 + 2 nodes and triangles per ray, -8.3 %. */
	CHECK_CONTAINS(md, "| slow | 1 | 20.0 | 45.000 | dominated by mid (0.50× time, −11.1 % SAH) "
	                   "| 12.0 | dominated by mid (0.50× time, −8.3 % ray cost) |");
	CHECK_CONTAINS(md, "| twin | 1 | 2.20 | 50.000 | dominated by fast (0.91× time, same SAH) |");
	CHECK_CONTAINS(md, "| fast | 2 | 1.50 | 50.000 | front | 14.0 | front |");
	/* The 1-thread-only builders compete on the 2-thread front too:
	 * twin's 2.2 ms against fast's 1.5 on 2 threads is 0.68x. */
	CHECK_CONTAINS(md, "| mid | 2 (ran on 1) | 10.0 | 40.000 | front |");
	/* 10 / 15 ms; (40 - 45) / 45. In the summary the same from the ratios
	 * to fast's: 5.0 / 7.5 and (0.80 - 0.90) / 0.90. */
	CHECK_CONTAINS(md, "| par | 2 | 15.0 | 45.000 | dominated by mid (0.67× time, −11.1 % SAH) |");
	CHECK_CONTAINS(md, "| par | 2 | 1 | 7.50× | 0.90× | n/a | 0.92× | 1.00× | dominated on 1 of "
	                   "1 scene by mid |");
	CHECK_CONTAINS(md, "| twin | 2 (ran on 1) | 2.20 | 50.000 | dominated by fast (0.68× time, "
	                   "same SAH) |");
	/* Break-even against fast: mid builds 8 ms longer and saves
	 * 1/10e6 - 1/12.5e6 = 2e-8 s per primary ray: 400,000 rays, 40 frames of
	 * 10,000; diffuse 1/5e6 - 1/6e6 = 3.33e-8 s: 240,000. slow: 18 ms over
	 * 1/10e6 - 1/11e6 = 9.09e-9 s: 1.98 M rays. */
	CHECK_CONTAINS(md, "| mid | 1 | 10.0 | 2.00 | after 400.0 k rays (40.0 frames) "
	                   "| after 240.0 k rays (24.0 frames) |");
	CHECK_CONTAINS(md, "| slow | 1 | 20.0 | 2.00 | after 2.0 M rays (198 frames) |");
	/* twin: the same tree as fast, so its slower rays are noise; it only
	 * builds slower. */
	CHECK_CONTAINS(md, "| twin | 1 | 2.20 | 2.00 | never cheaper | never cheaper |");
	CHECK_CONTAINS(md, "noisy: build repeats spread 20.0 %");
	CHECK_CONTAINS(md, "noisy: same tree as twin x1, Mrays/s 25 % apart");
	CHECK_CONTAINS(md, "busy: load 3.50 before, 3.00 after; 1 core left free");
	CHECK_CONTAINS(md, "busy: others kept 1.60 CPUs busy during the run; 1 core left free");
	CHECK(strstr(md, "others kept 0.10") == NULL);
	CHECK_CONTAINS(md, "**Busy machine:** 2 of 4 runs");
	/* No sah_seq: no thesis table of dashes. */
	CHECK(!strstr(md, "Parallel builders against"));
	/* Speedup: fast 2 / 1.5 = 1.33 on 2 threads; mid ran on 1 thread only. */
	CHECK_CONTAINS(md, "| fast | 2 | ok | 1.50 | 1.50 | 1.50 |  |  | 1.33 |");
	CHECK_CONTAINS(md, "| mid | 1 | ok | 10.00 | 9.00 | 11.00 |  |  |  |");
	/* build_phases: a column where some run of the scene has them. */
	CHECK_CONTAINS(md, "| marks | build phases ms | error |");
	CHECK_CONTAINS(md, "spread 20.0 % | upload 0.500, device 1.50 |  |");
	free(md);
	cJSON_Delete(doc);
}

static void test_reference_kept(void)
{
	cJSON *doc = document("\"report\": {\"reference\": \"mid\"}");
	char *md = report_markdown(doc);
	CHECK_CONTAINS(md, "reference builder **mid**");
	CHECK(!strstr(md, "did not run"));
	/* fast against mid: 8 ms less to build, 2e-8 s more per ray. */
	CHECK_CONTAINS(md, "| fast | 1 | 2.00 | 10.0 | up to 400.0 k rays (40.0 frames) |");
	free(md);
	cJSON_Delete(doc);
}

static void test_html(void)
{
	cJSON *doc = document("");
	char *html = report_html(doc);
	CHECK_CONTAINS(html, "did not run, so the reference is the first builder that did: fast.");
	CHECK_CONTAINS(html, "<td class=\"l front\">front</td>");
	CHECK_CONTAINS(html, "dominated by mid (0.50× time, −11.1 % SAH)");
	CHECK_CONTAINS(html, "stroke-dasharray=\"5,3\""); /* the front's line */
	CHECK_CONTAINS(html, "SAH cost vs. build time, 1 thread");
	CHECK_CONTAINS(html, "ray cost (nodes + tris per ray) vs. build time, 2 threads");
	CHECK_CONTAINS(html, "<h3>Break-even against fast</h3>");
	CHECK_CONTAINS(html, "⚠ Busy machine");
	CHECK_CONTAINS(html, "title=\"build repeats spread 20.0 %\">≈ noisy</td>");
	CHECK_CONTAINS(html, "title=\"load 3.50 before, 3.00 after; 1 core left free\">⚠ busy</td>");
	CHECK_CONTAINS(html, "primary Mrays/s (best tile)");
	/* (0.5 + 1.5) / 10 of the median build. */
	CHECK_CONTAINS(html, "<td class=\"l\" title=\"the phases add up to 20 % of the median "
	                     "build\">upload 0.500, device 1.50</td>");
	CHECK_CONTAINS(html, "per pass min–max");
	/* One colour per builder in every chart: mid is the second builder,
	 * its tooltip with its mark. Its bar: labels of 7 characters leave
	 * 12 + 7 * 6.2 = 55.4 px, and marked bars 170 px for the figure and
	 * its marks, so 10 of 30 ms is (640 - 55.4 - 170) / 3 = 138.2 px, its
	 * figure 6 px after. */
	CHECK_CONTAINS(html, "fill=\"#ff7f0e\" stroke=\"#222\" stroke-width=\"1.5\"><title>mid x1 "
	                     "(noisy: build repeats spread 20.0 %)</title>");
	CHECK_CONTAINS(html, "<text x=\"199.6\" y=\"79.0\" text-anchor=\"start\">10.0 ms ≈ noisy"
	                     "</text>");
	CHECK_CONTAINS(html, "fill=\"#ff7f0e\"/><text x=\"128.8\" y=\"352.0\" text-anchor=\"start\">"
	                     "mid</text>"); /* the legend */
	CHECK(!strstr(html, "e+0")); /* plain numbers */
	free(html);
	cJSON_Delete(doc);
}

/* Nothing ok: no summary, no front or break-even table, no chart. */
static void test_nothing_ok(void)
{
	cJSON *doc = cJSON_Parse("{\"scenes\": [{\"name\": \"s\"}], \"runs\": [{\"scene\": \"s\", "
	                         "\"builder\": \"a\", \"threads\": 1, \"status\": \"failed\", "
	                         "\"error\": \"no\"}]}");
	char *md = report_markdown(doc), *html = report_html(doc);
	CHECK_CONTAINS(md, "No ok run, so no summary.");
	CHECK(!strstr(md, "Pareto fronts") && !strstr(md, "Break-even"));
	CHECK(!strstr(html, "Pareto fronts") && !strstr(html, "Break-even") && !strstr(html, "<svg"));
	free(md);
	free(html);
	cJSON_Delete(doc);
}

/* The last run added was measured on the machine named host. */
static void on_machine(cJSON *runs, const char *host)
{
	char text[160];
	snprintf(text, sizeof(text), "{\"hostname\": \"%s\", \"cpu\": \"cpu-%s\", "
	         "\"cores\": 2}", host, host);
	cJSON_AddItemToObject(cJSON_GetArrayItem(runs, cJSON_GetArraySize(runs) - 1), "machine",
	                      cJSON_Parse(text));
}

/* A merged sweep from two machines: the reference ran on a only, par on 1
 * thread on a and on 2 on b, fast on b only. Every comparison that
 * crosses machines would compare the machines: none is made. */
static cJSON *merged_document(void)
{
	cJSON *doc = cJSON_Parse("{\"machine\": {\"hostname\": \"a\", \"cpu\": \"cpu-a\", "
	                         "\"cores\": 2}, \"config\": {\"report\": {\"reference\": "
	                         "\"ref\"}}, \"scenes\": [{\"name\": \"s\", \"triangles\": 100}], "
	                         "\"runs\": []}");
	cJSON *runs = cJSON_GetObjectItem(doc, "runs");
	add_run(runs, "ref", "sah_seq", 1, (double[]){10, 10, 10}, 50, 10, 10, 5);
	on_machine(runs, "a");
	add_run(runs, "par", "sah_queue", 1, (double[]){20, 20, 20}, 45, 9, 12, 6);
	on_machine(runs, "a");
	add_run(runs, "par", "sah_queue", 2, (double[]){4, 4, 4}, 45, 9, 12, 6);
	on_machine(runs, "b");
	add_run(runs, "fast", "lbvh", 1, (double[]){2, 2, 2}, 50, 10, 10, 5);
	on_machine(runs, "b");
	return doc;
}

static void test_merged_machines(void)
{
	cJSON *doc = merged_document();
	char *md = report_markdown(doc), *html = report_html(doc);
	/* No speedup of b's 2-thread par over a's 1-thread one (20 / 4). */
	CHECK_CONTAINS(md, "| par | 2 | ok | 4.00 | 4.00 | 4.00 |  |  |  |");
	/* Summary: a row per machine, fast (b) has no reference on b. */
	CHECK_CONTAINS(md, "| builder | threads | machine | scenes |");
	CHECK_CONTAINS(md, "| par | 1 | M1 | 1 | 2.00× | 0.90× |");
	/* Its Pareto verdict is its scene's, among M2's runs. */
	CHECK_CONTAINS(md, "| fast | 1 | M2 | 0 | n/a | n/a | n/a | n/a | n/a | front on 1 of 1 "
	                   "scene |");
	CHECK(!strstr(md, "0.20×") && !strstr(md, "0.40×"));
	/* Pareto: fast on b does not dominate ref on a. */
	CHECK_CONTAINS(md, "| ref | 1 on M1 | 10.0 | 50.000 | front |");
	CHECK_CONTAINS(md, "| fast | 1 on M2 | 2.00 | 50.000 | front |");
	CHECK(!strstr(md, "dominated by fast"));
	/* Break-even and the thesis table: said, not computed. */
	CHECK_CONTAINS(md, "| fast | 1 | 2.00 | — | not compared: the reference ran on another "
	                   "machine |");
	CHECK_CONTAINS(md, "| s (M1) | 10.00 | — | — | — |");
	CHECK_CONTAINS(md, "| s (M2) | — | 4.00 | — | — |");
	CHECK(!strstr(md, "2.50"));
	CHECK_CONTAINS(html, "<td>M2</td>");
	CHECK_CONTAINS(html, "not compared: the reference ran on another machine");
	CHECK_CONTAINS(html, "SAH cost vs. build time, 1 thread on M2");
	CHECK(!strstr(html, "dominated by fast") && !strstr(html, "Speedup over 1 thread"));
	free(md);
	free(html);
	cJSON_Delete(doc);
}

/* A merged scene whose parts drew heat maps on 0-35 and 0-45: each map
 * is stated with its own scale, never one for all. */
static void test_heat_scales(void)
{
	cJSON *doc = cJSON_Parse(
		"{\"scenes\": [{\"name\": \"s\", \"images\": {\"shaded\": \"images/s.png\", "
		"\"heat_scale\": \"log\", \"heat_scales_differ\": true}}], \"runs\": ["
		"{\"scene\": \"s\", \"builder\": \"a\", \"threads\": 1, \"status\": \"ok\", "
		"\"heat_image\": \"images/s--a.png\", \"heat_scale\": {\"min\": 0, \"max\": 35}}, "
		"{\"scene\": \"s\", \"builder\": \"b\", \"threads\": 1, \"status\": \"ok\", "
		"\"heat_image\": \"images/s--b.png\", \"heat_scale\": {\"min\": 0, \"max\": 45}}]}");
	char *md = report_markdown(doc), *html = report_html(doc);
	CHECK_CONTAINS(md, "drawn on different scales, each its own: a x1 0 to 35, b x1 0 to 45.");
	CHECK_CONTAINS(html, "<figcaption>a x1, 0–35</figcaption>");
	CHECK_CONTAINS(html, "<figcaption>b x1, 0–45</figcaption>");
	CHECK_CONTAINS(html, "the maps were drawn on different scales");
	CHECK(!strstr(html, "one log scale for every builder"));
	free(md);
	free(html);
	cJSON_Delete(doc);
}

/* Whether some leader line of the chart, from the edge of its own marker
 * (4.5 px) on, passes over a point other than its own (closer to its
 * centre than that radius) whose marker does not overlap its own (those
 * no leader can avoid). */
static bool leader_hides_point(const char *svg)
{
	for (const char *l = svg; (l = strstr(l, "<line x1=")) != NULL; l++) {
		double x1, y1, x2, y2;
		if (sscanf(l, "<line x1=\"%lf\" y1=\"%lf\" x2=\"%lf\" y2=\"%lf\"", &x1, &y1, &x2,
		           &y2) != 4 || !strstr(l, "stroke=\"#999\""))
			continue;
		for (const char *c = svg; (c = strstr(c, "<circle cx=")) != NULL; c++) {
			double cx, cy;
			if (sscanf(c, "<circle cx=\"%lf\" cy=\"%lf\"", &cx, &cy) != 2 ||
			    hypot(cx - x1, cy - y1) < 9)
				continue;
			double dx = x2 - x1, dy = y2 - y1, len = hypot(dx, dy);
			double t = ((cx - x1) * dx + (cy - y1) * dy) / (len * len);
			t = fmax(4.5 / len, fmin(1, t));
			if (hypot(x1 + t * dx - cx, y1 + t * dy - cy) < 4.5)
				return true;
		}
	}
	return false;
}

/* Whether some name on the chart covers a point: a box of 6.2 px a
 * character and a 12 px line, its text's baseline 2.5 px above its foot. */
static bool label_hides_point(const char *svg)
{
	for (const char *l = svg; (l = strstr(l, "<text x=")) != NULL; l++) {
		double x, y;
		char name[64];
		if (sscanf(l, "<text x=\"%lf\" y=\"%lf\" text-anchor=\"start\">%63[^<]", &x, &y,
		           name) != 3)
			continue;
		double x1 = x + 6.2 * (double)strlen(name), y0 = y + 2.5 - 12, y1 = y + 2.5;
		for (const char *c = svg; (c = strstr(c, "<circle cx=")) != NULL; c++) {
			double cx, cy;
			if (sscanf(c, "<circle cx=\"%lf\" cy=\"%lf\"", &cx, &cy) == 2 && cx > x - 4.5 &&
			    cx < x1 + 4.5 && cy > y0 - 4.5 && cy < y1 + 4.5)
				return true;
		}
	}
	return false;
}

/* Every chart of points with these figures of the default sweep's
 * icosphere on 2 threads (time, SAH cost, primary nodes per ray): neither
 * a name nor a leader line over another point. */
static void check_cluster(int view)
{
	static const char *const names[] = {"sah_sweep", "sah_binned", "sah_even", "sah_uneven",
	                                    "sah_queue", "sah_tasks", "lbvh", "ploc",
	                                    "lbvh+reinsert", "lbvh+treelet", "sbvh", "embree"};
	static const double fig[][3] = {
		{22.34, 38.132, 8.304}, {19.97, 38.362, 8.329}, {30.88, 38.132, 8.304},
		{23.09, 38.132, 8.304}, {20.02, 38.132, 8.304}, {33.04, 38.362, 8.329},
		{5.83, 43.294, 9.249},  {10.48, 41.150, 9.569}, {53.84, 40.493, 8.747},
		{259.0, 39.178, 8.429}, {448.1, 38.367, 8.345}, {47.93, 38.635, 8.392}};
	static const bool front[][12] = {{0, 1, 0, 0, 1, 0, 1, 1, 0, 0, 0, 0},
	                                 {0, 1, 0, 0, 1, 0, 1, 0, 0, 0, 0, 0}};
	struct svg_point p[12];
	for (int i = 0; i < 12; i++) {
		p[i] = (struct svg_point){.label = "", .group = names[i], .x = fig[i][0],
		                          .y = fig[i][1 + view], .front = front[view][i]};
		svg_colour(i, p[i].colour, sizeof(p[i].colour));
	}
	struct strbuf sb = {0};
	svg_scatter(&sb, "a view, 2 threads", "build time (ms)", "figure", p, 12);
	char *svg = sb_take(&sb);
	CHECK(svg != NULL);
	CHECK(strstr(svg, "stroke=\"#999\"") != NULL); /* some label was displaced */
	CHECK(!leader_hides_point(svg));
	CHECK(!label_hides_point(svg));
	free(svg);
}

/* sah_queue's label has no room beside its point (neighbours right, the
 * plot's edge below; on the nodes/ray chart sah_binned's marker overlaps
 * its own), and the first free slot above is reached past sah_binned's
 * point: its leader must not cross it, or the name reads as sah_binned's. */
static void test_leader_lines(void)
{
	check_cluster(0);
	check_cluster(1);
}

/* Thread counts 1 and 2 on the x axis: whole ticks only, no "1.5 threads";
 * the speedups on the y axis keep their fractional ticks. */
static void test_whole_ticks(void)
{
	const struct svg_point p[] = {{"", "a", 1, 1, "#1f77b4", false, SVG_CIRCLE, NULL},
	                              {"", "a", 2, 1.33, "#1f77b4", false, SVG_CIRCLE, NULL},
	                              {"", "b", 1, 1, "#ff7f0e", false, SVG_CIRCLE, NULL},
	                              {"", "b", 2, 2, "#ff7f0e", false, SVG_CIRCLE, NULL}};
	struct strbuf sb = {0};
	svg_lines(&sb, "Speedup over 1 thread", "threads", "speedup", p, 4);
	char *svg = sb_take(&sb);
	CHECK(svg != NULL);
	CHECK_CONTAINS(svg, "text-anchor=\"middle\">1</text>");
	CHECK_CONTAINS(svg, "text-anchor=\"middle\">2</text>");
	CHECK(!strstr(svg, "text-anchor=\"middle\">1.5</text>"));
	CHECK_CONTAINS(svg, "text-anchor=\"end\">1.5</text>");
	free(svg);
}

/* One degenerate tree's SAH, thousands of times the others' (tinybvh quick
 * on conference.obj): drawn as a triangle at the top edge with its value
 * in the tooltip, the axis scaled to the others (linear, its highest tick
 * near their highest value); without it the axis would be a log one up to
 * 259,446. The same points without the outlier draw no triangle. */
static void test_off_chart(void)
{
	struct svg_point p[] = {{"a x1", "a", 10, 31.2, "#1f77b4", true, SVG_CIRCLE, NULL},
	                        {"b x1", "b", 20, 30.1, "#ff7f0e", true, SVG_CIRCLE, NULL},
	                        {"c x1", "c", 30, 36.6, "#2ca02c", false, SVG_CIRCLE, NULL},
	                        {"q x1", "q", 7, 259446.2, "#d62728", true, SVG_CIRCLE, NULL}};
	struct strbuf sb = {0};
	svg_scatter(&sb, "SAH cost vs. build time, 1 thread", "build time (ms)", "SAH cost", p, 4);
	char *svg = sb_take(&sb);
	CHECK(svg != NULL);
	CHECK_CONTAINS(svg, "<polygon points=");
	CHECK_CONTAINS(svg, "q x1: 259446, off the chart</title></polygon>");
	CHECK_CONTAINS(svg, "off the chart, value in its tooltip");
	CHECK(!strstr(svg, "log scale"));
	CHECK_CONTAINS(svg, "text-anchor=\"end\">36</text>");
	CHECK(!strstr(svg, "text-anchor=\"end\">100000</text>"));
	free(svg);
	svg_scatter(&sb, "SAH cost vs. build time, 1 thread", "build time (ms)", "SAH cost", p, 3);
	svg = sb_take(&sb);
	CHECK(svg != NULL);
	CHECK(!strstr(svg, "<polygon"));
	CHECK(!strstr(svg, "off the chart"));
	free(svg);
}

/* Three builders whose cost lines cross at known ray counts, by hand:
 * a (1 ms, 10 Mrays/s: 1e-7 s a ray), b (5 ms, 5e-8 s), c (25 ms,
 * 2.5e-8 s). a and b cost the same at 0.004 / 5e-8 = 80,000 rays, b and
 * c at 0.020 / 2.5e-8 = 800,000 (a and c only at 320,000, past b's
 * lead). e (20 ms, 4e-8 s) is on the front (faster to build than c,
 * faster rays than b) but never lowest: c undercuts it from 333,333 rays,
 * before e would undercut b at 1.5 M. d (30 ms, 5e-8 s) is behind b;
 * f traced nothing and g failed: neither is a candidate. */
static cJSON *budget_document(void)
{
	cJSON *doc = cJSON_Parse("{\"machine\": {\"cpu\": \"test\", \"cores\": 2}, \"config\": {}, "
	                         "\"scenes\": [{\"name\": \"s\", \"triangles\": 100}], "
	                         "\"runs\": []}");
	cJSON *runs = cJSON_GetObjectItem(doc, "runs");
	add_run(runs, "a", "lbvh", 1, (double[]){1, 1, 1}, 50, 12, 10, 5);
	add_run(runs, "b", "sah_tasks", 1, (double[]){5, 5, 5}, 45, 10, 20, 5);
	add_run(runs, "c", "sbvh", 1, (double[]){25, 25, 25}, 40, 9, 40, 5);
	add_run(runs, "d", "ploc", 1, (double[]){30, 30, 30}, 45, 10, 20, 5);
	add_run(runs, "e", "embree", 1, (double[]){20, 20, 20}, 44, 10, 25, 5);
	cJSON_AddItemToArray(runs, cJSON_Parse("{\"scene\": \"s\", \"builder\": \"f\", "
	                                       "\"plugin\": \"lbvh\", \"threads\": 1, \"status\": "
	                                       "\"ok\", \"build_ms\": {\"median\": 0.5}}"));
	cJSON_AddItemToArray(runs, cJSON_Parse("{\"scene\": \"s\", \"builder\": \"g\", "
	                                       "\"threads\": 1, \"status\": \"failed\"}"));
	return doc;
}

static void test_budget(void)
{
	const double build[] = {1e-3, 5e-3, 25e-3, NAN, 20e-3}, ray[] = {1e-7, 5e-8, 2.5e-8, 1e-9, 4e-8};
	struct budget_interval iv[5];
	CHECK_INT(report_budget_intervals(build, ray, 5, iv), 3);
	CHECK_INT(iv[0].index, 0);
	CHECK_INT(iv[1].index, 1);
	CHECK_INT(iv[2].index, 2);
	CHECK(iv[0].from == 0 && fabs(iv[0].to - 8e4) < 1e-6);
	CHECK(fabs(iv[1].from - 8e4) < 1e-6 && fabs(iv[1].to - 8e5) < 1e-6);
	CHECK(fabs(iv[2].from - 8e5) < 1e-6 && isinf(iv[2].to));
	CHECK_INT(report_budget_intervals(build, ray, 0, iv), 0);
	cJSON *doc = budget_document();
	char *md = report_markdown(doc), *html = report_html(doc);
	CHECK_CONTAINS(md, "## Summary\n\n**Cheapest for a ray budget**");
	CHECK_CONTAINS(md, "- s, 1 thread: up to 80.0 k rays: a; up to 800.0 k: b; beyond: c\n");
	CHECK_CONTAINS(md, "| 1 thread | a | 1.00 | 10.0 | 0 | 80.0 k |\n"
	                   "| 1 thread | b | 5.00 | 20.0 | 80.0 k | 800.0 k |\n"
	                   "| 1 thread | e | 20.0 | 25.0 | never cheapest | — |\n"
	                   "| 1 thread | c | 25.0 | 40.0 | 800.0 k | beyond |\n");
	CHECK(!strstr(md, "| 1 thread | d |") && !strstr(md, "| 1 thread | f |"));
	CHECK_CONTAINS(html, "<li>s, 1 thread: up to 80.0 k rays: a; up to 800.0 k: b; beyond: c"
	                     "</li>");
	CHECK_CONTAINS(html, "Cost of a ray budget, 1 thread");
	CHECK_CONTAINS(html, "primary rays (log scale)");
	free(md);
	free(html);
	/* No run traced rays: said, not guessed; nothing crashes. */
	cJSON *run;
	cJSON_ArrayForEach(run, cJSON_GetObjectItem(doc, "runs"))
		cJSON_DeleteItemFromObject(run, "rays");
	md = report_markdown(doc);
	html = report_html(doc);
	CHECK_CONTAINS(md, "- s, 1 thread: not measured (no run traced rays)");
	CHECK_CONTAINS(md, "| 1 thread | not measured |");
	CHECK(!strstr(html, "Cost of a ray budget"));
	free(md);
	free(html);
	cJSON_Delete(doc);
}

/* Fronts and verdicts compare a build's own time: a peer whose whole call
 * (2.5 ms) is slower than lbvh's 2 ms, but whose library took 1.0 of it
 * (input 1.0 and convert 0.5 are bvhlab's translation), dominates lbvh at
 * a lower SAH; upload, a device builder's own work, is not taken out. */
static void test_own_time(void)
{
	cJSON *doc = cJSON_Parse(
		"{\"machine\": {\"cpu\": \"test\", \"cores\": 2, \"threads_available\": 2}, "
		"\"config\": {}, \"scenes\": [{\"name\": \"s\", \"triangles\": 100}], "
		"\"runs\": []}");
	cJSON *runs = cJSON_GetObjectItem(doc, "runs");
	add_run(runs, "ours", "lbvh", 1, (double[]){2, 2, 2}, 50, 12, 10, 5);
	add_run(runs, "peer", "tinybvh", 1, (double[]){2.5, 2.5, 2.5}, 45, 12, 10, 5);
	cJSON *peer = cJSON_GetArrayItem(runs, 1);
	cJSON_AddItemToObject(peer, "build_phases",
	                      cJSON_Parse("{\"input\": 1.0, \"upload\": 0.25, \"convert\": 0.5}"));
	CHECK(fabs(results_own_ms(peer) - 1.0) < 1e-12);
	CHECK(fabs(results_own_ms(cJSON_GetArrayItem(runs, 0)) - 2.0) < 1e-12);
	char *md = report_markdown(doc);
	CHECK_CONTAINS(md, "| ours | 1 | 2.00 | 50.000 | dominated by peer (0.50× time, −10.0 % SAH) ");
	CHECK_CONTAINS(md, "| peer | 1 | 1.00 | 45.000 | front |");
	CHECK_CONTAINS(md, "dominated on 1 of 1 scene by peer |");
	free(md);
	cJSON_Delete(doc);
}

int main(void)
{
	test_front_points();
	test_breakeven();
	test_markdown_fallback();
	test_reference_kept();
	test_html();
	test_nothing_ok();
	test_merged_machines();
	test_heat_scales();
	test_leader_lines();
	test_whole_ticks();
	test_off_chart();
	test_budget();
	test_own_time();
	return test_finish();
}
