/*
 * Reading a results document for the reports: values by dotted path, the
 * machine of a run, and the text forms the renderings share. Nothing here
 * renders a section; every report*.c file builds on these.
 */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include <cJSON.h>

#include "output/report_doc.h"

const cJSON *report_at(const cJSON *o, const char *path)
{
	char key[64];
	while (o && *path) {
		size_t len = strcspn(path, ".");
		if (len >= sizeof(key))
			return NULL;
		memcpy(key, path, len);
		key[len] = '\0';
		o = cJSON_GetObjectItemCaseSensitive(o, key);
		path += len + (path[len] == '.');
	}
	return o;
}

const char *report_str(const cJSON *o, const char *path)
{
	const cJSON *v = report_at(o, path);
	return cJSON_IsString(v) ? v->valuestring : "";
}

double report_num(const cJSON *o, const char *path)
{
	const cJSON *v = report_at(o, path);
	return cJSON_IsNumber(v) ? v->valuedouble : NAN;
}

const cJSON *report_machine(const cJSON *doc, const cJSON *run)
{
	const cJSON *m = cJSON_GetObjectItemCaseSensitive(run, "machine");
	return m ? m : cJSON_GetObjectItemCaseSensitive(doc, "machine");
}

bool report_same_machine(const cJSON *a, const cJSON *b)
{
	double ca = report_num(a, "cores"), cb = report_num(b, "cores");
	return a == b || (strcmp(report_str(a, "hostname"), report_str(b, "hostname")) == 0 &&
	                  strcmp(report_str(a, "cpu"), report_str(b, "cpu")) == 0 &&
	                  (ca == cb || (isnan(ca) && isnan(cb))));
}

bool report_heat_scale(const cJSON *scene, const cJSON *run, double *lo, double *hi)
{
	*lo = report_num(run, "heat_scale.min");
	*hi = report_num(run, "heat_scale.max");
	if (!isfinite(*lo) || !isfinite(*hi)) {
		*lo = report_num(scene, "images.heat_min");
		*hi = report_num(scene, "images.heat_max");
	}
	return isfinite(*lo) && isfinite(*hi);
}

bool report_heat_scales_differ(const cJSON *scene, const cJSON *const *runs, size_t n)
{
	double lo = report_num(scene, "images.heat_min"), hi = report_num(scene, "images.heat_max");
	if (cJSON_IsTrue(report_at(scene, "images.heat_scales_differ")))
		return true;
	for (size_t k = 0; k < n; k++) {
		double a, b;
		if (*report_str(runs[k], "heat_image") && report_heat_scale(scene, runs[k], &a, &b) &&
		    (a != lo || b != hi))
			return true;
	}
	return false;
}

void report_escape(struct strbuf *sb, const char *text)
{
	for (const char *p = text; *p; p++) {
		switch (*p) {
		case '&': sb_printf(sb, "&amp;"); break;
		case '<': sb_printf(sb, "&lt;"); break;
		case '>': sb_printf(sb, "&gt;"); break;
		case '"': sb_printf(sb, "&quot;"); break;
		case '\'': sb_printf(sb, "&#39;"); break;
		default: sb_printf(sb, "%c", *p);
		}
	}
}

/* Decimals for a magnitude: three significant digits, at least. */
static int plain_decimals(double a)
{
	return a >= 100 ? 0 : a >= 10 ? 1 : a >= 1 ? 2 : 3;
}

const char *report_plain(char *buf, size_t size, double v)
{
	if (!isfinite(v)) {
		snprintf(buf, size, "%s", "");
		return buf;
	}
	int d = plain_decimals(fabs(v));
	double scale = pow(10, d);
	d = plain_decimals(fabs(round(v * scale) / scale)); /* 9.996 is "10.0", not "10.00" */
	snprintf(buf, size, "%.*f", d, v);
	return buf;
}

const char *report_figure(char *buf, size_t size, double v, int decimals)
{
	if (isfinite(v))
		snprintf(buf, size, "%.*f", decimals, v);
	else
		snprintf(buf, size, "not measured");
	return buf;
}

const char *report_phases(char *buf, size_t size, const cJSON *run)
{
	const cJSON *p;
	size_t len = 0;
	buf[0] = '\0';
	cJSON_ArrayForEach(p, cJSON_GetObjectItemCaseSensitive(run, "build_phases")) {
		char v[32];
		if (!cJSON_IsNumber(p) || !p->string || len >= size)
			continue;
		int n = snprintf(buf + len, size - len, "%s%s %s", len ? ", " : "", p->string,
		                 report_plain(v, sizeof(v), p->valuedouble));
		len += n > 0 ? (size_t)n : 0;
	}
	return buf;
}

bool report_any_phases(const cJSON *const *runs, size_t n)
{
	for (size_t k = 0; k < n; k++)
		if (cJSON_GetArraySize(cJSON_GetObjectItemCaseSensitive(runs[k], "build_phases")) > 0)
			return true;
	return false;
}

/* Markdown text: raw HTML (a <script>, a <!-- that hides the rest) as
 * entities, pipes that would split a table cell escaped, line breaks that
 * would end the table's row or the paragraph flattened. */
void report_byline(struct strbuf *sb, const cJSON *doc,
                   void (*text)(struct strbuf *sb, const char *text))
{
	sb_printf(sb, "bvhlab ");
	text(sb, report_str(doc, "bvhlab_version"));
	sb_printf(sb, ", ");
	text(sb, report_str(doc, "created"));
	sb_printf(sb, ". Machine: ");
	text(sb, report_str(doc, "machine.cpu"));
}

void report_md_text(struct strbuf *sb, const char *text)
{
	for (const unsigned char *p = (const unsigned char *)text; *p; p++) {
		if (*p == '&' || *p == '<' || *p == '>')
			sb_printf(sb, *p == '&' ? "&amp;" : *p == '<' ? "&lt;" : "&gt;");
		else if (*p == '|')
			sb_printf(sb, "\\|");
		else
			sb_printf(sb, "%c", *p < 0x20 || *p == 0x7f ? ' ' : *p);
	}
}

void report_md_cell(struct strbuf *sb, const char *s)
{
	sb_printf(sb, " ");
	report_md_text(sb, s);
	sb_printf(sb, " |");
}

/* Whether s reads as a number (-1.5, +3, 2e-7): left as it is in CSV. */
static bool numeric_text(const char *s)
{
	char *end;
	if (!*s)
		return false;
	strtod(s, &end);
	return *end == '\0';
}

void report_csv_field(struct strbuf *sb, const char *s, bool last)
{
	/* A spreadsheet runs a cell that starts with = + - @ (or a tab or CR
	 * before one) as a formula: such text gets a leading ' to stay text. */
	bool formula = strchr("=+-@\t\r", s[0]) && s[0] && !numeric_text(s);
	if (formula || strpbrk(s, ",\"\n\r")) {
		sb_printf(sb, "\"%s", formula ? "'" : "");
		for (const char *p = s; *p; p++)
			sb_printf(sb, *p == '"' ? "\"\"" : "%c", *p);
		sb_printf(sb, "\"");
	} else {
		sb_printf(sb, "%s", s);
	}
	sb_printf(sb, last ? "\n" : ",");
}

void report_scene_instances(struct strbuf *sb, const cJSON *scene)
{
	if (!report_at(scene, "instances"))
		return;
	sb_printf(sb, ", %.0f instances of %.0f meshes (%.0f unique triangles, %.0f instanced)",
	          report_num(scene, "instances.instances"), report_num(scene, "instances.meshes"),
	          report_num(scene, "instances.unique_triangles"),
	          report_num(scene, "instances.instanced_triangles"));
}
