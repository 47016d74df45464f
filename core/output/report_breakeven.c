/*
 * Break-even: the figure an engine developer asks for. A builder that
 * takes longer than the reference but builds a tree that traces faster
 * pays for itself after some number of rays; one that builds faster but
 * traces slower is cheaper only up to some number. Total cost of n rays:
 * build_ms / 1000 + n / (Mrays/s * 1e6) seconds, with Mrays/s as measured
 * (rays per CPU second of the tracing threads times their number, each
 * tile at its best pass), so the rays are traced with the run's ray
 * threads and the tree is built with the run's build threads.
 */
#include <math.h>
#include <stdio.h>
#include <string.h>

#include "output/report.h"

struct breakeven report_breakeven(double build_ms, double mrays, double ref_build_ms,
                                  double ref_mrays)
{
	struct breakeven b = {BREAKEVEN_NONE, NAN};
	if (!(build_ms >= 0 && mrays > 0 && ref_build_ms >= 0 && ref_mrays > 0))
		return b;
	double d_build = (build_ms - ref_build_ms) / 1e3;      /* seconds */
	double d_ray = 1 / (mrays * 1e6) - 1 / (ref_mrays * 1e6); /* seconds per ray */
	if (d_build == 0 && d_ray == 0)
		b.kind = BREAKEVEN_SAME;
	else if (d_build <= 0 && d_ray <= 0)
		b.kind = BREAKEVEN_ALWAYS;
	else if (d_build >= 0 && d_ray >= 0)
		b.kind = BREAKEVEN_NEVER;
	else {
		b.kind = d_build > 0 ? BREAKEVEN_AFTER : BREAKEVEN_UNTIL;
		b.rays = fabs(d_build / d_ray);
	}
	return b;
}

void report_ray_count(char *buf, size_t size, double n)
{
	static const char *const units[] = {"k", "M", "G", "T"};
	int u = -1;
	while (n >= 1e3 && u < 3) {
		n /= 1e3;
		u++;
	}
	if (u < 0)
		snprintf(buf, size, "%.0f", n);
	else
		snprintf(buf, size, "%.1f %s", n, units[u]);
}

void report_breakeven_text(char *buf, size_t size, struct breakeven b, double frame_rays)
{
	char n[32], frames[48] = "";
	switch (b.kind) {
	case BREAKEVEN_SAME: snprintf(buf, size, "same cost"); return;
	case BREAKEVEN_ALWAYS: snprintf(buf, size, "always cheaper"); return;
	case BREAKEVEN_NEVER: snprintf(buf, size, "never cheaper"); return;
	case BREAKEVEN_NONE: snprintf(buf, size, "—"); return;
	case BREAKEVEN_AFTER: case BREAKEVEN_UNTIL: break;
	}
	report_ray_count(n, sizeof(n), b.rays);
	if (frame_rays > 0)
		snprintf(frames, sizeof(frames), " (%s frames)",
		         report_plain((char[32]){0}, 32, b.rays / frame_rays));
	snprintf(buf, size, "%s %s rays%s", b.kind == BREAKEVEN_AFTER ? "after" : "up to", n,
	         frames);
}

/* The break-even of run against base for one kind of ray ("primary");
 * *noise when the two throughputs are within the noise. The same tree
 * traces at the same speed: a difference measured there is the machine's,
 * so only the builds count. */
static struct breakeven of_kind(const cJSON *run, const cJSON *base, const char *kind,
                                bool *noise)
{
	char key[64];
	snprintf(key, sizeof(key), "rays.%s.mrays_per_s", kind);
	double mine = report_num(run, key), theirs = report_num(base, key);
	bool same = report_same_tree(run, base);
	*noise = !same && fabs(mine - theirs) < REPORT_NOISE * fmin(mine, theirs);
	return report_breakeven(report_num(run, "build_ms.median"), same ? theirs : mine,
	                        report_num(base, "build_ms.median"), theirs);
}

static const char intro[] =
	"The rays after which a builder's total cost (build, then tracing) falls below "
	"the reference's (after N: a slower build that a faster tree pays back; up to N: "
	"a faster build that a slower tree loses again), from the median build time and "
	"the measured Mrays/s (best tile), against the reference's run with the same "
	"threads, else its fewest. A frame: the run's primary rays. The same tree as the "
	"reference's counts as tracing at its speed; ≈: the two Mrays/s differ by less "
	"than 5 %, within the noise, so the figure is uncertain.";

/* The verdicts of one run, in text, for both kinds of ray. */
static void run_texts(const cJSON *run, const cJSON *base, char (*out)[96])
{
	static const char *const kinds[2] = {"primary", "diffuse"};
	double frame = report_num(run, "rays.primary.rays");
	for (int k = 0; k < 2; k++) {
		bool noise;
		struct breakeven b = of_kind(run, base, kinds[k], &noise);
		report_breakeven_text(out[k], sizeof(out[k]) - 8, b, frame);
		if (noise && (b.kind == BREAKEVEN_AFTER || b.kind == BREAKEVEN_UNTIL))
			strcat(out[k], " ≈");
	}
}

/* The reference run an ok traced run is set against: the reference's on
 * the same scene and machine. *elsewhere: the reference ran on the scene
 * only on other machines, whose times say nothing about this one's. */
static const cJSON *base_of(const struct report_index *ix, const char *ref, const cJSON *run,
                            bool *elsewhere)
{
	const char *scene = report_str(run, "scene");
	double threads = report_num(run, "threads");
	*elsewhere = false;
	if (strcmp(report_str(run, "status"), "ok") != 0 ||
	    !isfinite(report_num(run, "rays.primary.mrays_per_s")))
		return NULL;
	const cJSON *base = report_reference_run(ix, ref, scene, report_machine_number(ix, run),
	                                         threads);
	*elsewhere = !base && report_reference_run(ix, ref, scene, -1, threads);
	return base;
}

static const char other_machine[] = "not compared: the reference ran on another machine";

/* One row of the table, as text both renderings write. */
struct row {
	char ms[32], ref_ms[32], texts[2][96];
};

/* Whether the run has a row (a traced ok run with a reference of its own,
 * or one whose reference ran only elsewhere), and its texts. */
static bool row_of(const struct report_index *ix, const char *ref, const cJSON *run,
                   struct row *r)
{
	bool elsewhere;
	const cJSON *base = base_of(ix, ref, run, &elsewhere);
	if ((!base && !elsewhere) || base == run)
		return false;
	report_plain(r->ms, sizeof(r->ms), report_num(run, "build_ms.median"));
	if (base) {
		report_plain(r->ref_ms, sizeof(r->ref_ms), report_num(base, "build_ms.median"));
		run_texts(run, base, r->texts);
	} else {
		snprintf(r->ref_ms, sizeof(r->ref_ms), "—");
		snprintf(r->texts[0], sizeof(r->texts[0]), "%s", other_machine);
		snprintf(r->texts[1], sizeof(r->texts[1]), "%s", other_machine);
	}
	return true;
}

/* How a rendering writes the table: its header (before the first row),
 * a row, and what closes it. */
struct form {
	void (*header)(struct strbuf *sb, const char *ref);
	void (*row)(struct strbuf *sb, const cJSON *run, const struct row *r);
	const char *end;
};

static void table(struct strbuf *sb, const struct report_index *ix, const char *ref,
                  const cJSON *const *runs, size_t n, const struct form *f)
{
	struct row r;
	bool header = false;
	for (size_t k = 0; ref && k < n; k++) {
		if (!row_of(ix, ref, runs[k], &r))
			continue;
		if (!header)
			f->header(sb, ref);
		header = true;
		f->row(sb, runs[k], &r);
	}
	if (header)
		sb_printf(sb, "%s", f->end);
}

static void md_header(struct strbuf *sb, const char *ref)
{
	sb_printf(sb, "\n### Break-even against ");
	report_md_text(sb, ref);
	sb_printf(sb, "\n\n%s\n\n| builder | threads | median ms | reference ms "
	              "| primary rays | diffuse rays |\n|---|---:|---:|---:|---|---|\n",
	          intro);
}

static void md_row(struct strbuf *sb, const cJSON *run, const struct row *r)
{
	sb_printf(sb, "|");
	report_md_cell(sb, report_str(run, "builder"));
	sb_printf(sb, " %.0f | %s | %s | %s | %s |\n", report_num(run, "threads"), r->ms,
	          r->ref_ms, r->texts[0], r->texts[1]);
}

void report_breakeven_md(struct strbuf *sb, const struct report_index *ix, const char *ref,
                         const cJSON *const *runs, size_t n)
{
	static const struct form md = {md_header, md_row, ""};
	table(sb, ix, ref, runs, n, &md);
}

static void html_header(struct strbuf *sb, const char *ref)
{
	sb_printf(sb, "<h3>Break-even against ");
	report_escape(sb, ref);
	sb_printf(sb, "</h3>\n<p>%s</p>\n<table class=\"breakeven\"><tr><th class=\"l\">"
	              "builder</th><th>threads</th><th>median ms</th><th>reference ms"
	              "</th><th class=\"l\">primary rays</th><th class=\"l\">diffuse rays"
	              "</th></tr>\n", intro);
}

static void html_row(struct strbuf *sb, const cJSON *run, const struct row *r)
{
	sb_printf(sb, "<tr><td class=\"l\">");
	report_escape(sb, report_str(run, "builder"));
	sb_printf(sb, "</td><td>%.0f</td><td>%s</td><td>%s</td><td class=\"l\">%s</td>"
	              "<td class=\"l\">%s</td></tr>\n", report_num(run, "threads"),
	          r->ms, r->ref_ms, r->texts[0], r->texts[1]);
}

void report_breakeven_html(struct strbuf *sb, const struct report_index *ix, const char *ref,
                           const cJSON *const *runs, size_t n)
{
	static const struct form html = {html_header, html_row, "</table>\n"};
	table(sb, ix, ref, runs, n, &html);
}
