/*
 * Issue 44's report sections, from hand-made documents: a scene's memory
 * per triangle (the build's, with the scene, the whole child's; the
 * scene's share stated once), and "Cost per triangle against N": ns per
 * triangle of each builder, thread count and mesh over its sizes, each
 * held against the size nearest a million triangles, present only when
 * some series has three sizes.
 */
#include <math.h>

#include <cJSON.h>

#include "output/report.h"
#include "testutil.h"

/* A run on scene `scene` built in `ms` (median; cold: 3 x), its memory
 * per triangle given, as results.json has them. */
static void add(cJSON *runs, const char *scene, const char *builder, int threads, double ms,
                double with_scene)
{
	char text[768];
	snprintf(text, sizeof(text),
	         "{\"scene\": \"%s\", \"builder\": \"%s\", \"plugin\": \"%s\", \"threads\": %d, "
	         "\"status\": \"ok\", \"build_ms\": {\"median\": %g, \"min\": %g, \"max\": %g, "
	         "\"cold\": %g}, \"memory\": {\"scene_bytes\": 5400000, "
	         "\"build_bytes_per_triangle\": %g, \"with_scene_bytes_per_triangle\": %g, "
	         "\"child_bytes_per_triangle\": 200, \"scene_bytes_per_triangle\": 54}}",
	         scene, builder, builder, threads, ms, ms, ms, 3 * ms, with_scene - 54, with_scene);
	cJSON_AddItemToArray(runs, cJSON_Parse(text));
}

/* Three sizes of one mesh (and `other` from another source, one size). */
static cJSON *document(bool three)
{
	cJSON *doc = cJSON_Parse(
		"{\"machine\": {\"cpu\": \"t\", \"cores\": 2}, \"config\": {}, \"scenes\": ["
		"{\"name\": \"m0\", \"source\": \"mesh.ply\", \"triangles\": 100000},"
		"{\"name\": \"m1\", \"source\": \"mesh.ply\", \"triangles\": 1000000},"
		"{\"name\": \"m2\", \"source\": \"mesh.ply\", \"triangles\": 16000000},"
		"{\"name\": \"other\", \"source\": \"other.obj\", \"triangles\": 2000000}], "
		"\"runs\": []}");
	cJSON *runs = cJSON_GetObjectItem(doc, "runs");
	add(runs, "m0", "lbvh", 2, 2.0, 150);   /* 20 ns per triangle */
	add(runs, "m1", "lbvh", 2, 25.0, 140);  /* 25 */
	if (three)
		add(runs, "m2", "lbvh", 2, 800.0, 142); /* 50: 2.00 x the 1M figure */
	add(runs, "other", "lbvh", 2, 60.0, 141);
	return doc;
}

/* A document (document(three)) and both reports of it. */
struct rendered {
	cJSON *doc;
	char *md, *html;
};

static struct rendered render(bool three)
{
	cJSON *doc = document(three);
	return (struct rendered){doc, report_markdown(doc), report_html(doc)};
}

static void rendered_free(struct rendered *r)
{
	free(r->md);
	free(r->html);
	cJSON_Delete(r->doc);
}

/* What the reports of document(three) hold: lines of report.md, then of
 * report.html, each list ended by NULL. */
struct holds {
	bool three;
	const char *md[6], *html[4];
};

static const struct holds sections[] = {
	{ true, /* the scaling section */
	  { "## Cost per triangle against N",
	    "| lbvh | 2 | mesh.ply | 100000 | 20.0 | 60.0 | 3.00 | 150.0 | 0.80 |",
	    "| lbvh | 2 | mesh.ply | 1000000 | 25.0 | 75.0 | 3.00 | 140.0 | 1.00 |",
	    "| lbvh | 2 | mesh.ply | 16000000 | 50.0 | 150.0 | 3.00 | 142.0 | 2.00 |",
	    "| lbvh | 2 | other.obj | 2000000 | 30.0 | 90.0 | 3.00 | 141.0 | 1.00 |", NULL },
	  { "<h2>Cost per triangle against N</h2>", "lbvh: ns per triangle",
	    "triangles (log scale)" /* 100 k to 16 M */, NULL } },
	{ false, /* the memory table */
	  { "### Memory per triangle", "are 54.0 bytes per triangle (5.1 MiB)",
	    "| lbvh | 2 | 86.0 | 140.0 | 200.0 |", NULL },
	  { "<h3>Memory per triangle</h3>", "<td>86.0</td><td>140.0</td><td>200.0</td>", NULL } },
};

static void test_sections(void)
{
	for (size_t k = 0; k < sizeof(sections) / sizeof(sections[0]); k++) {
		const struct holds *h = &sections[k];
		struct rendered r = render(h->three);

		for (size_t j = 0; h->md[j]; j++)
			CHECK_CONTAINS(r.md, h->md[j]);
		for (size_t j = 0; h->html[j]; j++)
			CHECK_CONTAINS(r.html, h->html[j]);
		rendered_free(&r);
	}
}

/* Two sizes at most: not a scaling sweep. */
static void test_no_scale_section(void)
{
	struct rendered r = render(false);

	CHECK(r.md && !strstr(r.md, "Cost per triangle against N"));
	CHECK(r.html && !strstr(r.html, "Cost per triangle against N"));
	rendered_free(&r);
}

int main(void)
{
	test_sections();
	test_no_scale_section();
	return test_finish();
}
