/*
 * Interleaved ray timing rounds over a scene's trees (harness_rounds.h).
 * The parent keeps the list of trees; the rounds run in one child that
 * reads them back, checks them again (the file passed through the disk),
 * makes each batch's tracing copies once and then only times slices.
 */
#include <dirent.h>
#include <errno.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>
#include <unistd.h>

#include <bvhlab/trace.h>

#include "harness/harness_rays.h"
#include "harness/harness_rounds.h"
#include "harness/isolate.h"
#include "output/safe_file.h"
#include "trace/trace_series.h"
#include "util/util.h"

static const char TREE_MAGIC[8] = "bvhltree";

struct tree_header {
	char magic[8];
	uint32_t node_count, index_count;
	uint32_t width, reserved; /* bvhlab_tree.width (0 reads as 2) */
};

/*
 * What a tree holds in the rounds' child: the tree itself, and per
 * traversal the node copy, the triangles in leaf order and the wide view,
 * shared by the primary and diffuse batches. Measured on igea subdivided
 * once (1.07M triangles, lbvh, wide): about 160 MB a tree, 150 bytes a
 * triangle, its file 68 MB. Before the runs only the triangle count is
 * known, and spatial splits may add references: 400 bytes a triangle.
 * After them, the file's size: itself plus 1.5 times it per traversal.
 */
#define BYTES_PER_TRIANGLE 400.0
#define COPIES_PER_FILE_BYTE 1.5

/* Half of this machine's memory: what the rounds' child may hold. */
static double memory_budget(void)
{
	long pages = sysconf(_SC_PHYS_PAGES), page = sysconf(_SC_PAGESIZE);
	return pages > 0 && page > 0 ? 0.5 * (double)pages * (double)page : 1e300;
}

static unsigned traversal_count(const struct config *cfg)
{
	return (unsigned)__builtin_popcount(cfg->ray_traversals);
}

static bool rounds_fit(const struct config *cfg, uint32_t triangles)
{
	if (cfg->ray_rounds <= 1 || cfg->ray_width == 0 || cfg->ray_height == 0)
		return false;
	return BYTES_PER_TRIANGLE * traversal_count(cfg) * triangles <= memory_budget();
}

/* What the entry's tree will hold in the rounds' child. */
static double entry_bytes(const struct config *cfg, const struct rounds_entry *e)
{
	struct stat st;
	double file = stat(e->path, &st) == 0 ? (double)st.st_size : 0;
	return file * (1 + COPIES_PER_FILE_BYTE * traversal_count(cfg));
}

int harness_rounds_path(char *buf, size_t size, const char *dir, size_t scene, uint32_t run)
{
	int n = snprintf(buf, size, "%s/.tree-%zu-%u.raw", dir, scene, run);
	return n < 0 || (size_t)n >= size ? -ENAMETOOLONG : 0;
}

void harness_rounds_sweep(const char *dir)
{
	char path[4096];
	DIR *d = opendir(dir);
	struct dirent *e;
	while (d && (e = readdir(d)) != NULL) {
		size_t len = strlen(e->d_name);
		bool ours = !strncmp(e->d_name, ".tree-", 6) || !strncmp(e->d_name, ".heat-", 6) ||
		            !strncmp(e->d_name, ".shade-", 7);
		if (!ours || len < 10 || strcmp(e->d_name + len - 4, ".raw") != 0)
			continue;
		if (snprintf(path, sizeof(path), "%s/%s", dir, e->d_name) < (int)sizeof(path))
			unlink(path);
	}
	if (d)
		closedir(d);
}

int harness_rounds_write_tree(const char *path, const bvhlab_tree *tree)
{
	struct tree_header h = {.node_count = tree->node_count, .index_count = tree->index_count,
	                        .width = tree->width};
	memcpy(h.magic, TREE_MAGIC, sizeof(h.magic));
	const struct safe_part parts[] = {
		{&h, sizeof(h)},
		{tree->nodes, (size_t)h.node_count * sizeof(*tree->nodes)},
		{tree->prim_index, (size_t)h.index_count * sizeof(uint32_t)},
	};
	return safe_write_parts(path, parts, 3);
}

int harness_rounds_add(struct harness_rounds *r, const char *path,
                       const struct run_identity *run, bool duplicates,
                       const struct ray_metrics *rays)
{
	if (r->count == r->cap) {
		size_t cap = r->cap ? 2 * r->cap : 16;
		struct rounds_entry *e = realloc(r->entries, cap * sizeof(*e));
		if (!e)
			return -ENOMEM;
		r->entries = e;
		r->cap = cap;
	}
	char *copy = strdup(path);
	if (!copy)
		return -ENOMEM;
	r->entries[r->count++] = (struct rounds_entry){.path = copy, .run = run,
	                                               .duplicates = duplicates, .rays = *rays};
	return 0;
}

/* Deletes the tree files and forgets the entries (keeps the array). */
static void rounds_clear(struct harness_rounds *r)
{
	for (size_t i = 0; i < r->count; i++) {
		unlink(r->entries[i].path);
		free(r->entries[i].path);
	}
	r->count = 0;
}

void harness_rounds_finish(struct harness_rounds *r)
{
	rounds_clear(r);
	free(r->entries);
	*r = (struct harness_rounds){0};
}

/* ---- in the rounds' child ------------------------------------------------ */

/* One tree and its batches' series, by traversal. */
struct timed_tree {
	bvhlab_tree tree;
	bvhlab_hit *hits; /* the main primary series' first pass, until the
	                   * secondary rays are made from it */
	bvhlab_ray *secondary[RAY_KINDS]; /* by enum ray_kind, primary's unused */
	size_t secondary_count[RAY_KINDS];
	struct trace_series *primary[BVHLAB_TRAVERSAL_COUNT];
	struct trace_series *bounce[RAY_KINDS][BVHLAB_TRAVERSAL_COUNT]; /* by kind */
};

/* What comes back per entry. */
struct rounds_slot {
	uint32_t ok;
	uint64_t rays[RAY_KINDS]; /* the rounds' secondary batches: the run's, or none is taken */
	bvhlab_trace_timing timing[RAY_KINDS][BVHLAB_TRAVERSAL_COUNT]; /* by kind */
};

struct rounds_job {
	const struct rounds_entry *entries; /* [count] */
	size_t count;
	const struct config *cfg;
	const bvhlab_scene *scene;
	const bvhlab_prims *prims;
	/* in the child */
	struct ray_settings rs;
	const bvhlab_ray *primary; /* [n] */
	size_t n;
};

static int read_exact(FILE *f, void *p, size_t bytes)
{
	return fread(p, 1, bytes, f) == bytes ? 0 : -EIO;
}

/* The tree of a file, over arrays of its own (freed with free()). */
static int load_tree(const char *path, bvhlab_tree *t)
{
	struct tree_header h;
	FILE *f = fopen(path, "rb");
	if (!f)
		return -errno;
	int r = read_exact(f, &h, sizeof(h));
	if (r == 0 && memcmp(h.magic, TREE_MAGIC, sizeof(h.magic)) != 0)
		r = -EINVAL;
	if (r == 0) {
		t->nodes = malloc(((size_t)h.node_count + 1) * sizeof(*t->nodes));
		t->prim_index = malloc(((size_t)h.index_count + 1) * sizeof(uint32_t));
		r = t->nodes && t->prim_index ? 0 : -ENOMEM;
	}
	if (r == 0)
		r = read_exact(f, t->nodes, (size_t)h.node_count * sizeof(*t->nodes));
	if (r == 0)
		r = read_exact(f, t->prim_index, (size_t)h.index_count * sizeof(uint32_t));
	if (r == 0 && fgetc(f) != EOF)
		r = -EINVAL;
	if (r == 0) {
		t->node_count = t->node_capacity = h.node_count;
		t->index_count = t->index_capacity = h.index_count;
		t->width = h.width;
	}
	fclose(f);
	return r;
}

static void free_timed(struct timed_tree *tt)
{
	for (int k = 0; k < BVHLAB_TRAVERSAL_COUNT; k++) {
		for (int kind = 0; kind < RAY_KINDS; kind++) /* borrow primary[k]'s copies */
			trace_series_destroy(tt->bounce[kind][k]);
		trace_series_destroy(tt->primary[k]);
	}
	free(tt->hits);
	for (int kind = 0; kind < RAY_KINDS; kind++)
		free(tt->secondary[kind]);
	free(tt->tree.nodes);
	free(tt->tree.prim_index);
	*tt = (struct timed_tree){0};
}

/* A series per traversal for the primary rays; the main one keeps its
 * first pass's hits for the diffuse rays. No counting pass: the run's
 * counters stay. */
static int prepare(const struct rounds_job *job, const struct rounds_entry *e,
                   struct timed_tree *tt)
{
	bvhlab_error err = {{0}};
	const struct ray_settings *rs = &job->rs;
	int r = load_tree(e->path, &tt->tree);
	if (r == 0)
		r = bvhlab_validate_tree(&tt->tree, &job->prims->input, e->duplicates, &err);
	/* Zeroed: make_bounces reads them even if no pass could run. */
	if (r == 0 && !(tt->hits = calloc(job->n, sizeof(*tt->hits))))
		r = -ENOMEM;
	/* The traversals the run's child could trace with (a device one that
	 * could not run there is left out here too). */
	for (int k = 0; r == 0 && k < BVHLAB_TRAVERSAL_COUNT; k++) {
		if (!(rs->traversals & e->rays.traversals & (1u << k)))
			continue;
		bvhlab_trace_options o = {.traversal = k, .threads = rs->threads,
		                          .device = rs->device};
		r = trace_series_create(&tt->tree, job->scene, job->primary, job->n, &o,
		                        k == rs->main ? tt->hits : NULL, NULL, false,
		                        &tt->primary[k], &err);
	}
	return r;
}

/* After the main primary series' first slice: the secondary rays from
 * its hits, as the run's child made them, and a series for each kind
 * beside each primary one, on its copies. */
static int make_bounces(const struct rounds_job *job, struct timed_tree *tt)
{
	int r = 0;
	for (int kind = RAY_DIFFUSE; r == 0 && kind < RAY_KINDS; kind++)
		r = harness_secondary_rays(kind, job->scene, &job->rs, job->primary, tt->hits, job->n,
		                           &tt->secondary[kind], &tt->secondary_count[kind]);
	free(tt->hits);
	tt->hits = NULL;
	for (int kind = RAY_DIFFUSE; r == 0 && kind < RAY_KINDS; kind++) {
		for (int k = 0; r == 0 && tt->secondary_count[kind] && k < BVHLAB_TRAVERSAL_COUNT; k++)
			if (tt->primary[k])
				r = trace_series_create_like(tt->primary[k], tt->secondary[kind],
				                             tt->secondary_count[kind], ray_kind_any(kind),
				                             &tt->bounce[kind][k]);
	}
	return r;
}

static void slice(struct trace_series *s, const bvhlab_trace_options *all,
                  const bvhlab_trace_options *o)
{
	if (s && !trace_series_done(s, all))
		trace_series_slice(s, o);
}

/* One round: a slice of every batch of every tree, the trees in turn. A
 * batch whose passes already meet the whole measurement's minimums (slow
 * batches: min_repeats gives way at 10 x min_ms) takes no more slices, so
 * the rounds cost no more time than one stretch would. */
static void one_round(const struct rounds_job *job, struct timed_tree *tt,
                      struct rounds_slot *slots)
{
	const struct ray_settings *rs = &job->rs;
	uint32_t rounds = rs->rounds;
	bvhlab_trace_options all = {.min_ms = rs->min_ms, .min_repeats = rs->min_repeats};
	bvhlab_trace_options o = {.min_ms = rs->min_ms / rounds,
	                          .min_repeats = (rs->min_repeats + rounds - 1) / rounds};
	for (size_t i = 0; i < job->count; i++) {
		if (!slots[i].ok)
			continue;
		slice(tt[i].primary[rs->main], &all, &o);
		if (tt[i].hits && make_bounces(job, &tt[i]) < 0) {
			slots[i].ok = 0;
			continue;
		}
		for (int k = 0; k < BVHLAB_TRAVERSAL_COUNT; k++) {
			if (k != rs->main)
				slice(tt[i].primary[k], &all, &o);
			for (int kind = RAY_DIFFUSE; kind < RAY_KINDS; kind++)
				slice(tt[i].bounce[kind][k], &all, &o);
		}
	}
}

/* A series that could not time one pass (no memory for its samples)
 * leaves the run its own figures. */
static void collect(struct timed_tree *tt, struct rounds_slot *slot)
{
	for (int kind = 0; kind < RAY_KINDS; kind++)
		slot->rays[kind] = tt->secondary_count[kind];
	for (int k = 0; slot->ok && k < BVHLAB_TRAVERSAL_COUNT; k++) {
		for (int kind = 0; kind < RAY_KINDS; kind++) {
			struct trace_series *s = kind ? tt->bounce[kind][k] : tt->primary[k];
			if (s)
				trace_series_timing(s, &slot->timing[kind][k]);
			slot->ok = slot->ok && (!s || slot->timing[kind][k].repeats);
		}
	}
}

static void rounds_work(void *arg, void *report, size_t size)
{
	struct rounds_job *job = arg;
	struct rounds_slot *slots = report;
	size_t count = job->count;
	bvhlab_camera cam;
	bvhlab_ray *primary = NULL;
	(void)size;
	harness_ray_settings(job->cfg, &job->rs);
	harness_camera(job->cfg, job->scene, &cam);
	job->n = (size_t)job->cfg->ray_width * job->cfg->ray_height;
	struct timed_tree *tt = calloc(count, sizeof(*tt));
	if (!tt || bvhlab_rays_primary(&cam, job->cfg->ray_width, job->cfg->ray_height, &primary))
		goto out;
	job->primary = primary;
	for (size_t i = 0; i < count; i++) {
		slots[i].ok = prepare(job, &job->entries[i], &tt[i]) == 0;
		if (!slots[i].ok)
			free_timed(&tt[i]);
	}
	for (uint32_t k = 0; k < job->rs.rounds; k++)
		one_round(job, tt, slots);
	for (size_t i = 0; i < count; i++)
		collect(&tt[i], &slots[i]);
out:
	for (size_t i = 0; tt && i < count; i++)
		free_timed(&tt[i]);
	free(tt);
	free(primary);
}

/* Long enough for every slice of every kind of rays at ten times its time
 * (see bvhlab_trace_options.min_repeats), plus the config's own limit. */
static double rounds_timeout(const struct config *cfg, size_t count)
{
	double batches = traversal_count(cfg) * (double)__builtin_popcount(cfg->ray_kinds);
	return cfg->timeout_s + 10.0 * cfg->ray_min_ms * 1e-3 * batches * (double)count;
}

/* The rounds' secondary batches are the run's (same rays, so same counts). */
static bool same_batches(const struct rounds_slot *slot, struct ray_metrics *m)
{
	for (int kind = RAY_DIFFUSE; kind < RAY_KINDS; kind++)
		if (slot->rays[kind] != ray_metrics_kind(m, kind)[m->main].stats.rays)
			return false;
	return true;
}

static void take(struct rounds_entry *entries, size_t count, const struct rounds_slot *slots,
                 uint32_t rounds)
{
	for (size_t i = 0; i < count; i++) {
		struct ray_metrics *m = &entries[i].rays;
		if (!slots[i].ok || m->main < 0 || m->main >= BVHLAB_TRAVERSAL_COUNT ||
		    !same_batches(&slots[i], m))
			continue;
		for (int kind = 0; kind < RAY_KINDS; kind++) {
			bvhlab_trace_timing *t = ray_metrics_kind(m, kind);
			for (int k = 0; k < BVHLAB_TRAVERSAL_COUNT; k++) {
				bvhlab_trace_stats st = t[k].stats; /* the run's exact counters stay */
				t[k] = slots[i].timing[kind][k];
				t[k].stats = st;
			}
		}
		m->rounds = rounds;
		m->provisional = false;
		entries[i].timed = true;
	}
}

/* The rounds over count entries, in one child (or here). */
static int run_group(struct rounds_entry *entries, size_t count, const struct config *cfg,
                     const bvhlab_scene *scene, const bvhlab_prims *prims, bvhlab_error *err)
{
	struct rounds_job job = {.entries = entries, .count = count, .cfg = cfg, .scene = scene,
	                         .prims = prims};
	struct isolate_limits limits = {.timeout_s = rounds_timeout(cfg, count)};
	size_t size = count * sizeof(struct rounds_slot);
	char why[256] = "";
	struct rounds_slot *slots = calloc(count, sizeof(*slots));
	if (!slots)
		return -ENOMEM;
	int outcome = ISOLATE_REPORTED;
	if (cfg->isolate)
		outcome = isolate_call(rounds_work, &job, slots, size, &limits, why, sizeof(why));
	else
		rounds_work(&job, slots, size);
	if (outcome == ISOLATE_REPORTED)
		take(entries, count, slots, cfg->ray_rounds);
	else
		error_set(err, "%s", why);
	free(slots);
	return outcome == ISOLATE_REPORTED ? 0 : outcome < 0 ? outcome : -EIO;
}

/* Trees that fit the memory budget together are timed together: the
 * scene's runs in one group on most configs, in a few on big scenes.
 * Entries whose tree loaded and traced get timed = true and the new
 * timings. 0, or a negative errno with err saying why a group was not. */
static int rounds_run(struct harness_rounds *r, const struct config *cfg,
                      const bvhlab_scene *scene, const bvhlab_prims *prims, bvhlab_error *err)
{
	double budget = memory_budget();
	int rc = 0;
	for (size_t i = 0, j; i < r->count; i = j) {
		double bytes = entry_bytes(cfg, &r->entries[i]);
		for (j = i + 1; j < r->count; j++) {
			bytes += entry_bytes(cfg, &r->entries[j]);
			if (bytes > budget)
				break;
		}
		int g = run_group(r->entries + i, j - i, cfg, scene, prims, err);
		rc = rc < 0 ? rc : g;
	}
	return rc;
}

bool harness_rounds_start(const struct config *cfg, const bvhlab_scene *scene, bool tty)
{
	bool on = rounds_fit(cfg, scene->triangle_count);
	if (!on && cfg->ray_rounds > 1 && cfg->ray_width && cfg->ray_height)
		fprintf(stderr, "%sbvhlab: scene '%s': a tree of %u triangles would not fit in half of "
		        "this machine's memory for interleaved ray rounds; each run times its rays "
		        "alone (rays.rounds 1)\n", tty ? "\n" : "", scene->name, scene->triangle_count);
	return on;
}

void harness_rounds_end(struct harness_rounds *r, struct results *res,
                        const struct config *cfg, const bvhlab_scene *scene,
                        const bvhlab_prims *prims, bool tty)
{
	bvhlab_error err = {{0}};
	int rc = rounds_run(r, cfg, scene, prims, &err);
	bool some = false;
	for (size_t i = 0; i < r->count; i++) {
		/* Not timed in the rounds (they failed): the run's slice is final,
		 * not a figure a resumed sweep must replace. */
		struct rounds_entry *e = &r->entries[i];
		e->rays.provisional = false;
		int u = results_set_run_rays(res, e->run, &e->rays);
		some = true;
		rc = rc < 0 ? rc : u;
	}
	int w = some ? results_write(res, &err) : 0;
	rc = rc < 0 ? rc : w;
	if (rc < 0)
		fprintf(stderr, "%sbvhlab: scene '%s': interleaved ray rounds: %s; runs not timed "
		        "there keep their provisional ray timings (rays.rounds 1)\n", tty ? "\n" : "",
		        scene->name, err.message[0] ? err.message : strerror(-rc));
	rounds_clear(r);
}
