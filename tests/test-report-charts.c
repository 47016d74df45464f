/*
 * The report's charts and verdicts that issue 45 asked to be honest: no
 * colour repeated within a chart (40 builders and more), each peer
 * library's points in a shape of its own, every front point named (past
 * 128 points), busy and noisy marks on the speedup chart, the summary's
 * Pareto verdict counted per scene (never a group of one), and no
 * thesis table against a parallel reference.
 */
#include <math.h>

#include <cJSON.h>

#include "output/report.h"
#include "testutil.h"

static void test_palette(void)
{
	char c[200][16];
	for (int k = 0; k < 200; k++) {
		svg_colour(k, c[k], sizeof(c[k]));
		CHECK_INT((int)strlen(c[k]), 7);
		CHECK(strcmp(c[k], "#888888") != 0); /* the colour of no builder */
		for (int j = 0; j < k; j++)
			if (strcmp(c[j], c[k]) == 0) {
				fprintf(stderr, "colours %d and %d are both %s\n", j, k, c[k]);
				CHECK(false);
			}
	}
}

static void test_shapes(void)
{
	enum svg_shape e = svg_plugin_shape("embree"), t = svg_plugin_shape("tinybvh"),
	               b = svg_plugin_shape("bvh2");
	CHECK_INT(svg_plugin_shape("lbvh"), SVG_CIRCLE);
	CHECK(e != SVG_CIRCLE && t != SVG_CIRCLE && b != SVG_CIRCLE);
	CHECK(e != t && t != b && e != b);
	CHECK(strcmp(svg_shape_name(t), "tinybvh") == 0);
}

/* Counts the occurrences of needle in text. */
static int count(const char *text, const char *needle)
{
	int n = 0;
	for (const char *p = strstr(text, needle); p; p = strstr(p + 1, needle))
		n++;
	return n;
}

/* 200 points, every one on the front (a falling line): each named twice,
 * beside its point and in the legend. */
static void test_many_labels(void)
{
	struct svg_point p[200];
	char names[200][8];
	for (int i = 0; i < 200; i++) {
		snprintf(names[i], sizeof(names[i]), "g%d", i);
		p[i] = (struct svg_point){.label = names[i], .group = names[i], .x = 1 + i,
		                          .y = 400 - i, .front = true};
		svg_colour(i, p[i].colour, sizeof(p[i].colour));
	}
	struct strbuf sb = {0};
	svg_scatter(&sb, "many", "build time (ms)", "SAH cost", p, 200);
	char *svg = sb_take(&sb);
	CHECK(svg != NULL);
	CHECK_INT(count(svg, "text-anchor=\"start\">g199</text>"), 2);
	CHECK_INT(count(svg, "text-anchor=\"start\">g150</text>"), 2);
	free(svg);
}

/* A run of a scene, as the reports read it. */
struct run_row {
	const char *scene, *builder, *plugin;
	int threads;
	double ms, sah; /* median build time, SAH cost */
	const char *status;
};

static void add(cJSON *runs, const struct run_row *r)
{
	char text[512];
	snprintf(text, sizeof(text),
	         "{\"scene\": \"%s\", \"builder\": \"%s\", \"plugin\": \"%s\", \"threads\": %d, "
	         "\"status\": \"%s\", \"build_ms\": {\"median\": %g, \"min\": %g, \"max\": %g}, "
	         "\"tree\": {\"sah_cost\": %g}}",
	         r->scene, r->builder, r->plugin, r->threads, r->status, r->ms, r->ms, r->ms, r->sah);
	cJSON_AddItemToArray(runs, cJSON_Parse(text));
}

/* A results document over `scenes` (the members of its array) with the n
 * runs of rows, `reference` the report's reference builder. */
static cJSON *doc_of(const char *reference, const char *scenes, const struct run_row *rows,
                     size_t n)
{
	char text[512];
	snprintf(text, sizeof(text), "{\"machine\": {\"cpu\": \"t\", \"cores\": 2}, \"config\": "
	                             "{\"report\": {\"reference\": \"%s\"}}, \"scenes\": [%s], "
	                             "\"runs\": []}", reference, scenes);
	cJSON *doc = cJSON_Parse(text);
	for (size_t k = 0; doc && k < n; k++)
		add(cJSON_GetObjectItem(doc, "runs"), &rows[k]);
	return doc;
}

#define ROWS(rows) rows, sizeof(rows) / sizeof(rows[0])

/* x is invalid on s3: of the two scenes that compared it, it is on the
 * front of one (s1, faster than y) and behind y on the other (s2). The
 * old verdict, over geometric means grouped by scene count, put x alone
 * in its group and called it "front". The peer's points are squares. */
static void test_summary_verdict(void)
{
	static const struct run_row rows[] = {
		{"s1", "y", "sah_seq", 1, 10, 40, "ok"},  {"s1", "x", "embree", 1, 5, 42, "ok"},
		{"s2", "y", "sah_seq", 1, 10, 40, "ok"},  {"s2", "x", "embree", 1, 12, 42, "ok"},
		{"s3", "y", "sah_seq", 1, 10, 40, "ok"},  {"s3", "x", "embree", 1, 1, 99, "invalid"},
	};
	cJSON *doc = doc_of("y", "{\"name\": \"s1\"}, {\"name\": \"s2\"}, {\"name\": \"s3\"}",
	                    ROWS(rows));
	char *md = report_markdown(doc), *html = report_html(doc);
	CHECK_CONTAINS(md, "| front on 1 of 2 scenes, dominated on 1 by y |");
	CHECK_CONTAINS(md, "| y | 1 | 3 |");
	CHECK_CONTAINS(md, "| front on 3 of 3 scenes |");
	CHECK_CONTAINS(html, "<rect x=\""); /* the embree peer's square */
	CHECK_CONTAINS(html, "<title>x x1</title></rect>");
	free(md);
	free(html);
	cJSON_Delete(doc);
}

/* The speedup chart shows a time: its busy run is ringed and says why. */
static void test_speedup_marks(void)
{
	static const struct run_row rows[] = {
		{"s", "p", "sah_tasks", 1, 10, 40, "ok"},
		{"s", "p", "sah_tasks", 2, 6, 40, "ok"},
		{"s", "q", "sah_seq", 1, 12, 40, "ok"},
	};
	cJSON *doc = doc_of("p", "{\"name\": \"s\"}", ROWS(rows));
	cJSON *busy = cJSON_GetArrayItem(cJSON_GetObjectItem(doc, "runs"), 1);
	cJSON_AddNumberToObject(busy, "load_other", 1.5); /* 2 threads on 2 CPUs: none free */
	char *html = report_html(doc), *md = report_markdown(doc);
	const char *speedup = strstr(html, "Speedup over 1 thread");
	CHECK(speedup != NULL);
	const char *end = speedup ? strstr(speedup, "</svg>") : NULL;
	const char *ring = speedup ? strstr(speedup, "stroke-dasharray=\"2,1.5\"") : NULL;
	CHECK(ring && end && ring < end);
	CHECK(speedup && strstr(speedup, "<title>p x2 (busy: "));
	/* p is parallel: no table of gains over its own 1-thread run. */
	CHECK(!strstr(md, "Parallel builders against"));
	free(html);
	free(md);
	cJSON_Delete(doc);
	/* A sequential reference keeps the table. */
	static const struct run_row seq_first[] = {
		{"s", "q", "sah_seq", 1, 12, 40, "ok"},
		{"s", "p", "sah_tasks", 2, 6, 40, "ok"},
	};
	doc = doc_of("q", "{\"name\": \"s\"}", ROWS(seq_first));
	md = report_markdown(doc);
	CHECK_CONTAINS(md, "## Parallel builders against q");
	CHECK_CONTAINS(md, "| s | 12.00 | 6.00 | 50.0 % | 2.00 |");
	free(md);
	cJSON_Delete(doc);
}

int main(void)
{
	test_palette();
	test_shapes();
	test_many_labels();
	test_summary_verdict();
	test_speedup_marks();
	return test_finish();
}
