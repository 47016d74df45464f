/*
 * The report's wide-tree section (report_wide.c) from a hand-written
 * results document, every figure worked out by hand: Spearman's rank
 * correlation (ties, reversal, too few), the wide table's collapse and
 * binary SAH per run, the ranking of the 8-wide runs by binary SAH and by
 * measured ray cost per collapse method, and the wide runs on the front of
 * build time against ray cost; a document with binary trees only has no
 * such section.
 */
#include <math.h>

#include <cJSON.h>

#include "output/report.h"
#include "testutil.h"

static void test_spearman(void)
{
	const double up[] = {1, 2, 3, 4}, down[] = {9, 7, 5, 1}, swapped[] = {2, 1, 4, 3};
	CHECK(fabs(report_spearman(up, up, 4) - 1) < 1e-12);
	CHECK(fabs(report_spearman(up, down, 4) + 1) < 1e-12);
	/* 1 - 6 * sum d^2 / (n (n^2 - 1)) = 1 - 6 * 4 / 60 = 0.6 */
	CHECK(fabs(report_spearman(up, swapped, 4) - 0.6) < 1e-12);
	/* ranks (1.5, 1.5, 3) against (1, 2, 3): 1.5 / sqrt(1.5 * 2) */
	const double tied[] = {5, 5, 8};
	CHECK(fabs(report_spearman(tied, up, 3) - 1.5 / sqrt(3.0)) < 1e-12);
	CHECK(isnan(report_spearman(up, down, 2)));
	const double flat[] = {3, 3, 3};
	CHECK(isnan(report_spearman(flat, up, 3)));
}

/* A run: its width (2: binary), collapse method (NULL: none), binary SAH
 * before the collapse, SAH, build ms, primary nodes and triangles per ray,
 * primary Mrays/s. */
static void add_run(cJSON *runs, const char *builder, int width, const char *method,
                    double before, double sah, double ms, double nodes, double tris,
                    double mrays)
{
	char text[1400], stages[300] = "[]", refine[200] = "[]";
	if (method) {
		snprintf(stages, sizeof(stages), "[{\"plugin\": \"collapse\", \"ms\": 1, "
		         "\"sah_before\": %g, \"sah_after\": %g}]", before, sah);
		snprintf(refine, sizeof(refine), "[{\"plugin\": \"collapse\", \"options\": "
		         "{\"width\": %d, \"method\": \"%s\"}}]", width, method);
	}
	snprintf(text, sizeof(text),
	         "{\"scene\": \"s\", \"builder\": \"%s\", \"plugin\": \"p\", \"threads\": 1, "
	         "\"status\": \"ok\", \"build_ms\": {\"median\": %g, \"min\": %g, \"max\": %g}, "
	         "\"stages\": %s, \"config\": {\"builder\": {\"refine\": %s}}, "
	         "\"tree\": {\"sah_cost\": %g, \"width\": %d, \"bytes_per_triangle\": 60, "
	         "\"packed_bytes_per_triangle\": 50}, \"rays\": {\"primary\": {\"rays\": 100, "
	         "\"mrays_per_s\": %g, \"nodes_per_ray\": %g, \"tris_per_ray\": %g}}}",
	         builder, ms, ms, ms, stages, refine, sah, width, mrays, nodes, tris);
	cJSON_AddItemToArray(runs, cJSON_Parse(text));
}

static cJSON *document(bool wide)
{
	cJSON *doc = cJSON_Parse("{\"machine\": {\"cpu\": \"test\", \"cores\": 2, "
	                         "\"threads_available\": 2}, \"config\": {}, \"scenes\": "
	                         "[{\"name\": \"s\", \"triangles\": 100}], \"runs\": []}");
	cJSON *runs = cJSON_GetObjectItem(doc, "runs");
	add_run(runs, "a", 2, NULL, 0, 40, 1, 20, 2, 5);
	add_run(runs, "b", 2, NULL, 0, 30, 5, 18, 2, 6);
	add_run(runs, "c", 2, NULL, 0, 35, 3, 19, 2, 5.5);
	if (!wide)
		return doc;
	/* sah: ray costs a 11, b 12, c 9 reverse a and b; Mrays/s as the SAH. */
	add_run(runs, "a+sah8", 8, "sah", 40, 36, 2, 9, 2, 7);
	add_run(runs, "b+sah8", 8, "sah", 30, 27, 6, 10, 2, 9);
	add_run(runs, "c+sah8", 8, "sah", 35, 31, 4, 7, 2, 8);
	/* greedy: ray costs in the SAH's order. */
	add_run(runs, "a+greedy8", 8, "greedy", 40, 38, 1.5, 12, 2, 6);
	add_run(runs, "b+greedy8", 8, "greedy", 30, 29, 5.5, 10, 2, 7);
	add_run(runs, "c+greedy8", 8, "greedy", 35, 33, 3.5, 11, 2, 6.5);
	/* A method name from an edited document reaches no page as markup. */
	add_run(runs, "a+odd", 8, "<i>odd</i>", 40, 39, 9, 30, 2, 1);
	add_run(runs, "b+odd", 8, "<i>odd</i>", 30, 29, 9, 31, 2, 1);
	return doc;
}

static void test_sections(void)
{
	cJSON *doc = document(true);
	char *md = report_markdown(doc), *html = report_html(doc);
	CHECK(md && html);
	if (md && html) {
		CHECK_CONTAINS(md, "### Wide trees");
		CHECK_CONTAINS(md, "| b+sah8 | 1 | 8 | sah | 30.000 | 27.000 | 10.0 | 2.0 |");
		CHECK_CONTAINS(md, "| a | 1 | 2 | — | 40.000 | 40.000 |");
		CHECK_CONTAINS(md, "### Does the collapse change the ranking? 8-wide, sah");
		/* binary SAH ranks b 1, c 2, a 3; ray cost c 1, a 2, b 3:
		 * d = (0, 1, -1) in builder order b, c... 1 - 6 * 6 / 24 = -0.5 */
		CHECK_CONTAINS(md, "| a+sah8 | 40.000 | 3 | 11.000 | 2 | 7.00 | 3 |");
		CHECK_CONTAINS(md, "ray cost's (nodes + triangles per primary ray): -0.50; with "
		                   "primary Mrays/s: 1.00 (3 builders");
		CHECK_CONTAINS(md, "### Does the collapse change the ranking? 8-wide, greedy");
		CHECK_CONTAINS(md, "ray cost's (nodes + triangles per primary ray): 1.00; with "
		                   "primary Mrays/s: 1.00 (3 builders");
		/* front of ms against ray cost over the wide runs: a+greedy8 (1.5,
		 * 14), a+sah8 (2, 11), c+sah8 (4, 9); the rest dominated */
		CHECK_CONTAINS(md, "against wide ray cost: a+sah8 (8-wide sah, 1 thread: 2.00 ms, "
		                   "11.0); c+sah8 (8-wide sah, 1 thread: 4.00 ms, 9.0); a+greedy8 "
		                   "(8-wide greedy, 1 thread: 1.50 ms, 14.0).");
		CHECK_CONTAINS(html, "<h3>Wide trees</h3>");
		CHECK_CONTAINS(html, "<h3>Does the collapse change the ranking? 8-wide, greedy</h3>");
		CHECK_CONTAINS(html, "8-wide, &lt;i&gt;odd&lt;/i&gt;</h3>");
		CHECK(!strstr(html, "<i>odd") && !strstr(md, "<i>odd"));
		CHECK_CONTAINS(md, "(2 builders; 1 the same order");
	}
	free(md);
	free(html);
	cJSON_Delete(doc);
	doc = document(false);
	md = report_markdown(doc);
	CHECK(md && !strstr(md, "Wide trees") && !strstr(md, "ranking?"));
	free(md);
	cJSON_Delete(doc);
}

int main(void)
{
	test_spearman();
	test_sections();
	return test_finish();
}
