/*
 * Two-level runs in report.md (docs/instances.md): per scene, each
 * two-level builder's levels apart (plugins, build times, nodes, SAH) and
 * the whole's two-level SAH, beside the scene's one-level runs above.
 */
#include <math.h>
#include <stdio.h>

#include "output/report.h"

/* The levels' columns: key under "two_level", format. */
static const char *const columns[][2] = {
	{"bottom.build_ms", "%.3f"}, {"top.build_ms", "%.3f"}, {"build_ms", "%.3f"},
	{"bottom.trees", "%.0f"}, {"bottom.nodes", "%.0f"}, {"top.nodes", "%.0f"},
	{"bottom.sah_cost", "%.3f"}, {"top.sah_cost", "%.3f"}, {"sah_cost", "%.3f"},
};

static void row(struct strbuf *sb, const cJSON *run)
{
	const cJSON *t = cJSON_GetObjectItemCaseSensitive(run, "two_level");
	char buf[64];
	sb_printf(sb, "|");
	report_md_cell(sb, report_str(run, "builder"));
	snprintf(buf, sizeof(buf), "%.0f", report_num(run, "threads"));
	report_md_cell(sb, buf);
	report_md_cell(sb, report_str(t, "bottom.plugin"));
	report_md_cell(sb, report_str(t, "top.plugin"));
	for (size_t k = 0; k < sizeof(columns) / sizeof(columns[0]); k++) {
		double v = report_num(t, columns[k][0]);
		snprintf(buf, sizeof(buf), columns[k][1], v);
		report_md_cell(sb, isnan(v) ? "" : buf);
	}
	sb_printf(sb, "\n");
}

void report_two_level_md(struct strbuf *sb, const cJSON *const *runs, size_t n)
{
	size_t shown = 0;
	for (size_t k = 0; k < n; k++) {
		if (!cJSON_GetObjectItemCaseSensitive(runs[k], "two_level"))
			continue;
		if (shown++ == 0)
			sb_printf(sb, "\nTwo-level builds (docs/instances.md): bottom build ms summed "
			              "over the meshes (each mesh's median), top over the instances' "
			              "boxes; SAH: the bottom trees' mean, the top's, and the two-level "
			              "SAH of the whole.\n\n| builder | threads | bottom | top "
			              "| bottom ms | top ms | sum ms | meshes | bottom nodes | top nodes "
			              "| bottom SAH | top SAH | two-level SAH |\n|---|---:|---|---|---:"
			              "|---:|---:|---:|---:|---:|---:|---:|---:|\n");
		row(sb, runs[k]);
	}
}
