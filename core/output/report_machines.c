/*
 * The machines a results document's runs were measured on, for the
 * reports. A merged sweep may come from several; their build times must
 * not be read as if from one, so the reports then list each machine with
 * its runs. Runs without their own "machine" (a plain `bvhlab run`) share
 * the document's.
 */
#include <string.h>

#include <cJSON.h>

#include "output/report.h"

#define MAX_MACHINES 64

static const cJSON *machine_of(const cJSON *doc, const cJSON *run)
{
	const cJSON *m = cJSON_GetObjectItemCaseSensitive(run, "machine");
	return m ? m : cJSON_GetObjectItemCaseSensitive(doc, "machine");
}

static bool same(const cJSON *a, const cJSON *b)
{
	return strcmp(report_str(a, "hostname"), report_str(b, "hostname")) == 0 &&
	       strcmp(report_str(a, "cpu"), report_str(b, "cpu")) == 0 &&
	       report_num(a, "cores") == report_num(b, "cores");
}

/* Distinct machines of the runs, in order of first appearance; their count. */
static size_t machines(const cJSON *doc, const cJSON **out)
{
	size_t n = 0;
	const cJSON *run;
	cJSON_ArrayForEach(run, cJSON_GetObjectItemCaseSensitive(doc, "runs")) {
		const cJSON *m = machine_of(doc, run);
		size_t k = 0;
		while (k < n && !same(out[k], m))
			k++;
		if (k == n && n < MAX_MACHINES)
			out[n++] = m;
	}
	return n;
}

/* "scene builder/threads, ..." of the runs measured on machine m. */
static void runs_on(struct strbuf *sb, const cJSON *doc, const cJSON *m, bool html)
{
	const char *sep = "";
	const cJSON *run;
	cJSON_ArrayForEach(run, cJSON_GetObjectItemCaseSensitive(doc, "runs")) {
		if (!same(machine_of(doc, run), m))
			continue;
		sb_printf(sb, "%s", sep);
		if (html) {
			report_escape(sb, report_str(run, "scene"));
			sb_printf(sb, " ");
			report_escape(sb, report_str(run, "builder"));
		} else {
			sb_printf(sb, "%s %s", report_str(run, "scene"), report_str(run, "builder"));
		}
		sb_printf(sb, "/%.0f", report_num(run, "threads"));
		sep = ", ";
	}
}

static const char warning[] =
	"The runs were measured on %zu different machines: compare build times only "
	"between runs of the same machine.";

void report_machines_md(struct strbuf *sb, const cJSON *doc)
{
	const cJSON *list[MAX_MACHINES];
	size_t n = machines(doc, list);
	if (n < 2)
		return;
	sb_printf(sb, "\n## Machines\n\n");
	sb_printf(sb, warning, n);
	sb_printf(sb, "\n\n| machine | hostname | CPU | cores | runs (scene builder/threads) |\n"
	              "|---|---|---|---:|---|\n");
	for (size_t k = 0; k < n; k++) {
		sb_printf(sb, "| M%zu | %s | %s | %.0f | ", k + 1, report_str(list[k], "hostname"),
		          report_str(list[k], "cpu"), report_num(list[k], "cores"));
		runs_on(sb, doc, list[k], false);
		sb_printf(sb, " |\n");
	}
}

void report_machines_html(struct strbuf *sb, const cJSON *doc)
{
	const cJSON *list[MAX_MACHINES];
	size_t n = machines(doc, list);
	if (n < 2)
		return;
	sb_printf(sb, "<h2>Machines</h2>\n<p class=\"bad\">");
	sb_printf(sb, warning, n);
	sb_printf(sb, "</p>\n<table><tr><th>machine</th><th>hostname</th><th>CPU</th>"
	              "<th>cores</th><th>runs (scene builder/threads)</th></tr>\n");
	for (size_t k = 0; k < n; k++) {
		sb_printf(sb, "<tr><td>M%zu</td><td>", k + 1);
		report_escape(sb, report_str(list[k], "hostname"));
		sb_printf(sb, "</td><td>");
		report_escape(sb, report_str(list[k], "cpu"));
		sb_printf(sb, "</td><td>%.0f</td><td>", report_num(list[k], "cores"));
		runs_on(sb, doc, list[k], true);
		sb_printf(sb, "</td></tr>\n");
	}
	sb_printf(sb, "</table>\n");
}
