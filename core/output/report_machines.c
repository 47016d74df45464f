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

/* Distinct machines of the runs, in order of first appearance; their count. */
static size_t machines(const cJSON *doc, const cJSON **out)
{
	size_t n = 0;
	const cJSON *run;
	cJSON_ArrayForEach(run, cJSON_GetObjectItemCaseSensitive(doc, "runs")) {
		const cJSON *m = report_machine(doc, run);
		size_t k = 0;
		while (k < n && !report_same_machine(out[k], m))
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
		if (!report_same_machine(report_machine(doc, run), m))
			continue;
		sb_printf(sb, "%s", sep);
		(html ? report_escape : report_md_text)(sb, report_str(run, "scene"));
		sb_printf(sb, " ");
		(html ? report_escape : report_md_text)(sb, report_str(run, "builder"));
		sb_printf(sb, "/%.0f", report_num(run, "threads"));
		sep = ", ";
	}
}

static const char warning[] =
	"The runs were measured on %zu different machines: compare build times only "
	"between runs of the same machine.";

/* Text into a cell: escaped in HTML, pipes escaped in Markdown. */
static void cell(struct strbuf *sb, const char *text, bool html)
{
	if (html) {
		sb_printf(sb, "<td>");
		report_escape(sb, text);
		sb_printf(sb, "</td>");
	} else {
		report_md_cell(sb, text);
	}
}

/* Both renderings share the table: one row per machine, M1 first. */
static void machines_table(struct strbuf *sb, const cJSON *doc, bool html)
{
	const cJSON *list[MAX_MACHINES];
	size_t n = machines(doc, list);
	if (n < 2)
		return;
	sb_printf(sb, html ? "<h2>Machines</h2>\n<p class=\"bad\">" : "\n## Machines\n\n");
	sb_printf(sb, warning, n);
	sb_printf(sb, html ? "</p>\n<table><tr><th>machine</th><th>hostname</th><th>CPU</th>"
	                     "<th>cores</th><th>runs (scene builder/threads)</th></tr>\n"
	                   : "\n\n| machine | hostname | CPU | cores | runs (scene builder/threads) "
	                     "|\n|---|---|---|---:|---|\n");
	for (size_t k = 0; k < n; k++) {
		sb_printf(sb, html ? "<tr><td>M%zu</td>" : "| M%zu |", k + 1);
		cell(sb, report_str(list[k], "hostname"), html);
		cell(sb, report_str(list[k], "cpu"), html);
		sb_printf(sb, html ? "<td>%.0f</td><td>" : " %.0f | ", report_num(list[k], "cores"));
		runs_on(sb, doc, list[k], html);
		sb_printf(sb, html ? "</td></tr>\n" : " |\n");
	}
	if (html)
		sb_printf(sb, "</table>\n");
}

void report_machines_md(struct strbuf *sb, const cJSON *doc)
{
	machines_table(sb, doc, false);
}

void report_machines_html(struct strbuf *sb, const cJSON *doc)
{
	machines_table(sb, doc, true);
}
