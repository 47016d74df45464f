/*
 * Joining the results folders of a plan's parts (`bvhlab merge`). Runs are
 * copied as the parts recorded them, whatever fields they carry, so fields
 * added to results later pass through untouched; each gets its part's
 * machine record, since parts may have run on different machines.
 */
#include <dirent.h>
#include <errno.h>
#include <fcntl.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>
#include <time.h>
#include <unistd.h>

#include <cJSON.h>

#include "output/results.h"
#include "plan/plan.h"
#include "util/util.h"

/* One part folder as read. */
struct part {
	const char *dir;
	cJSON *doc;
};

struct merge {
	const struct plan_file *plan;
	bool mixed_versions; /* parts of other bvhlab versions allowed */
	struct part *parts;
	size_t part_count;
	const cJSON **owner_run; /* [run id] the run found for it, or NULL */
	size_t *owner_part;      /* [run id] the part it came from */
};

int results_set_plan(struct results *res, const char *hash, size_t runs, bvhlab_error *err)
{
	cJSON *o = cJSON_CreateObject();
	if (!o || !cJSON_AddStringToObject(o, "hash", hash) ||
	    !cJSON_AddNumberToObject(o, "runs", (double)runs)) {
		cJSON_Delete(o);
		error_set(err, "out of memory");
		return -ENOMEM;
	}
	cJSON_AddItemToObject(res->doc, "plan", o);
	return 0;
}

static const char *string_at(const cJSON *o, const char *key)
{
	const cJSON *v = cJSON_GetObjectItemCaseSensitive(o, key);
	return cJSON_IsString(v) ? v->valuestring : NULL;
}

/* The run's id, checked against the plan's run of that id. */
static int run_id(const struct merge *m, const char *dir, const cJSON *run, uint32_t *id,
                  bvhlab_error *err)
{
	const cJSON *v = cJSON_GetObjectItemCaseSensitive(run, "id");
	const cJSON *runs = cJSON_GetObjectItemCaseSensitive(m->plan->doc, "runs");
	if (!cJSON_IsNumber(v) || v->valuedouble < 0 ||
	    v->valuedouble >= (double)m->plan->run_count) {
		error_set(err, "part %s: a run (%s, %s) has no id of this plan's %zu runs", dir,
		          string_at(run, "scene"), string_at(run, "builder"), m->plan->run_count);
		return -EINVAL;
	}
	*id = (uint32_t)v->valuedouble;
	struct run_identity planned, have;
	const char *changed = NULL;
	run_identity_read(cJSON_GetArrayItem(runs, (int)*id), &planned);
	run_identity_read(run, &have);
	have.threads = 0; /* the plan knows the configured count only */
	enum run_match match = run_identity_compare(&planned, &have, &changed);
	if (match == RUN_OTHER) {
		error_set(err, "part %s: run %u is %s/%s there but %s/%s in the plan", dir, *id,
		          have.scene ? have.scene : "?", have.builder ? have.builder : "?",
		          planned.scene, planned.builder);
		return -EINVAL;
	}
	if (match == RUN_CHANGED && have.hash) { /* a part of an older bvhlab has none */
		error_set(err, "part %s: run %u (%s, %s) was made another way than the plan's (its "
		          "%s differs): nothing merged; run it again from the plan", dir, *id,
		          planned.scene, planned.builder, changed);
		return -EINVAL;
	}
	return 0;
}

/* Figures from other builds may differ for other reasons than the runs'. */
static int check_part_version(const struct merge *m, size_t p, bvhlab_error *err)
{
	const char *v = string_at(m->parts[p].doc, "bvhlab_version");
	const char *first = string_at(m->parts[0].doc, "bvhlab_version");
	if (p == 0 || m->mixed_versions || (v && first && strcmp(v, first) == 0))
		return 0;
	error_set(err, "part %s was run by bvhlab %s, part %s by %s: nothing merged (run every "
	          "part with one build, or merge with --allow-mixed-versions)", m->parts[p].dir,
	          v ? v : "(no version)", m->parts[0].dir, first ? first : "(no version)");
	return -EINVAL;
}

/* Reads every part and assigns each run to its id; a second claim is an error. */
static int collect(struct merge *m, const char *const *dirs, bvhlab_error *err)
{
	for (size_t p = 0; p < m->part_count; p++) {
		struct part *part = &m->parts[p];
		part->dir = dirs[p];
		int r = plan_part_read(part->dir, &part->doc, err);
		if (r == -ENOENT)
			error_set(err, "part %s has no results.json (not a results folder, or its run "
			          "never started)", part->dir);
		if (r == 0)
			r = plan_part_check(m->plan, part->dir, part->doc, err);
		r = r ? r : check_part_version(m, p, err);
		const cJSON *run;
		cJSON_ArrayForEach(run, cJSON_GetObjectItemCaseSensitive(part->doc, "runs")) {
			uint32_t id;
			if (r < 0 || (r = run_id(m, part->dir, run, &id, err)) < 0)
				break;
			if (m->owner_run[id]) {
				error_set(err, "run %u (%s, %s) is claimed by two parts, %s and %s: remove "
				          "one of them", id, string_at(run, "scene"), string_at(run, "builder"),
				          m->parts[m->owner_part[id]].dir, part->dir);
				r = -EINVAL;
				break;
			}
			m->owner_run[id] = run;
			m->owner_part[id] = p;
		}
		if (r < 0)
			return r;
	}
	return 0;
}

static bool same_string(const cJSON *a, const cJSON *b, const char *key)
{
	const char *x = string_at(a, key), *y = string_at(b, key);
	return x && y && strcmp(x, y) == 0;
}

/* Two runs of one scene and builder are one run when their thread counts
 * resolved alike (0 on a machine with that many): the merge would count it
 * twice. Runs of one builder made with other options come from another
 * configuration of it. */
static int check_pair(const struct merge *m, size_t a, size_t b, bvhlab_error *err)
{
	const cJSON *x = m->owner_run[a], *y = m->owner_run[b];
	const cJSON *tx = cJSON_GetObjectItemCaseSensitive(x, "threads");
	const cJSON *ty = cJSON_GetObjectItemCaseSensitive(y, "threads");
	const char *hx = string_at(x, "options_hash"), *hy = string_at(y, "options_hash");
	if (!same_string(x, y, "builder"))
		return 0;
	if (hx && hy && strcmp(hx, hy) != 0) {
		error_set(err, "runs %zu (part %s) and %zu (part %s) of builder '%s' were made with "
		          "other options (hash %s and %s): parts of another configuration; nothing "
		          "merged", a, m->parts[m->owner_part[a]].dir, b, m->parts[m->owner_part[b]].dir,
		          string_at(x, "builder"), hx, hy);
		return -EINVAL;
	}
	if (same_string(x, y, "scene") && cJSON_IsNumber(tx) && cJSON_IsNumber(ty) &&
	    tx->valuedouble == ty->valuedouble) {
		error_set(err, "runs %zu (part %s) and %zu (part %s) are the same run (%s, %s, %g "
		          "threads, a count of 0 resolved on its machine): remove one of them", a,
		          m->parts[m->owner_part[a]].dir, b, m->parts[m->owner_part[b]].dir,
		          string_at(x, "scene"), string_at(x, "builder"), tx->valuedouble);
		return -EINVAL;
	}
	return 0;
}

static int check_identities(const struct merge *m, bvhlab_error *err)
{
	for (size_t a = 0; a < m->plan->run_count; a++)
		for (size_t b = a + 1; m->owner_run[a] && b < m->plan->run_count; b++)
			if (m->owner_run[b] && check_pair(m, a, b, err) < 0)
				return -EINVAL;
	return 0;
}

/* ---- the merged document --------------------------------------------------------- */

static const cJSON *find_named(const cJSON *array, const char *name)
{
	const cJSON *e;
	cJSON_ArrayForEach(e, array) {
		const char *n = string_at(e, "name");
		if (n && strcmp(n, name) == 0)
			return e;
	}
	return NULL;
}

/* A copy of the run with its part's machine, unless it carries its own,
 * and the colour scale its heat map was drawn with in its part. */
static cJSON *run_copy(const cJSON *run, const cJSON *part_doc)
{
	cJSON *copy = cJSON_Duplicate(run, 1);
	const cJSON *machine = cJSON_GetObjectItemCaseSensitive(part_doc, "machine");
	const char *version = string_at(part_doc, "bvhlab_version");
	if (copy && machine && !cJSON_GetObjectItemCaseSensitive(copy, "machine"))
		cJSON_AddItemToObject(copy, "machine", cJSON_Duplicate(machine, 1));
	if (copy && version && !cJSON_GetObjectItemCaseSensitive(copy, "bvhlab_version"))
		cJSON_AddStringToObject(copy, "bvhlab_version", version);
	const char *scene = string_at(run, "scene");
	const cJSON *images = cJSON_GetObjectItemCaseSensitive(
		scene ? find_named(cJSON_GetObjectItemCaseSensitive(part_doc, "scenes"), scene) : NULL,
		"images");
	const cJSON *lo = cJSON_GetObjectItemCaseSensitive(images, "heat_min");
	const cJSON *hi = cJSON_GetObjectItemCaseSensitive(images, "heat_max");
	if (copy && string_at(run, "heat_image") && cJSON_IsNumber(lo) && cJSON_IsNumber(hi) &&
	    !cJSON_GetObjectItemCaseSensitive(copy, "heat_scale")) {
		cJSON *scale = cJSON_AddObjectToObject(copy, "heat_scale");
		cJSON_AddNumberToObject(scale, "min", lo->valuedouble);
		cJSON_AddNumberToObject(scale, "max", hi->valuedouble);
	}
	return copy;
}

static bool same_number(const cJSON *a, const cJSON *b, const char *key)
{
	const cJSON *x = cJSON_GetObjectItemCaseSensitive(a, key);
	const cJSON *y = cJSON_GetObjectItemCaseSensitive(b, key);
	return cJSON_IsNumber(x) && cJSON_IsNumber(y) && x->valuedouble == y->valuedouble;
}

/* Parts draw a scene's heat maps each on its own scale: when they differ
 * the merged scene states none (each run keeps its own, "heat_scale"). */
static void join_heat_scales(cJSON *kept, const cJSON *other)
{
	cJSON *a = cJSON_GetObjectItemCaseSensitive(kept, "images");
	const cJSON *b = cJSON_GetObjectItemCaseSensitive(other, "images");
	if (!cJSON_GetObjectItemCaseSensitive(a, "legend") ||
	    !cJSON_GetObjectItemCaseSensitive(b, "legend") ||
	    (same_number(a, b, "heat_min") && same_number(a, b, "heat_max")))
		return;
	cJSON_DeleteItemFromObjectCaseSensitive(a, "legend");
	cJSON_DeleteItemFromObjectCaseSensitive(a, "heat_min");
	cJSON_DeleteItemFromObjectCaseSensitive(a, "heat_max");
	cJSON_AddBoolToObject(a, "heat_scales_differ", true);
}

/* Every scene any part loaded, one entry each; one with images wins. */
static void add_scenes(cJSON *scenes, const struct merge *m)
{
	for (size_t p = 0; p < m->part_count; p++) {
		const cJSON *s;
		cJSON_ArrayForEach(s, cJSON_GetObjectItemCaseSensitive(m->parts[p].doc, "scenes")) {
			const char *name = string_at(s, "name");
			cJSON *old = name ? (cJSON *)find_named(scenes, name) : NULL;
			if (old)
				join_heat_scales(old, s);
			if (!name || (old && (cJSON_GetObjectItemCaseSensitive(old, "images") ||
			                      !cJSON_GetObjectItemCaseSensitive(s, "images"))))
				continue;
			if (old)
				cJSON_ReplaceItemViaPointer(scenes, old, cJSON_Duplicate(s, 1));
			else
				cJSON_AddItemToArray(scenes, cJSON_Duplicate(s, 1));
		}
	}
}

/* Every part notes the thread counts its run list left out (a serial
 * builder's): the merge states each builder's once, as one run does. */
static void add_not_applicable(cJSON *doc, const struct merge *m)
{
	cJSON *list = NULL;
	for (size_t p = 0; p < m->part_count; p++) {
		const cJSON *e;
		cJSON_ArrayForEach(e, cJSON_GetObjectItemCaseSensitive(m->parts[p].doc,
		                                                      "not_applicable")) {
			const char *builder = string_at(e, "builder");
			const cJSON *seen;
			bool known = false;
			cJSON_ArrayForEach(seen, list)
				known = known || (builder && same_string(seen, e, "builder"));
			if (!builder || known ||
			    (!list && !(list = cJSON_AddArrayToObject(doc, "not_applicable"))))
				continue;
			cJSON_AddItemToArray(list, cJSON_Duplicate(e, 1));
		}
	}
}

static cJSON *merged_header(const struct merge *m)
{
	char stamp[32];
	time_t now = time(NULL);
	struct tm tm;
	cJSON *doc = cJSON_CreateObject();
	strftime(stamp, sizeof(stamp), "%Y-%m-%dT%H:%M:%SZ", gmtime_r(&now, &tm));
	const char *version = string_at(m->parts[0].doc, "bvhlab_version"); /* the parts' */
	for (size_t p = 1; version && p < m->part_count; p++)
		version = same_string(m->parts[0].doc, m->parts[p].doc, "bvhlab_version") ? version : "mixed";
	cJSON_AddStringToObject(doc, "bvhlab_version", version ? version : "unknown");
	cJSON_AddStringToObject(doc, "created", stamp);
	/* The reports' header names one machine: the first part's (runs carry their own). */
	cJSON_AddItemToObject(doc, "machine", cJSON_Duplicate(cJSON_GetObjectItemCaseSensitive(
	                                          m->parts[0].doc, "machine"), 1));
	cJSON_AddItemToObject(doc, "config", cJSON_Duplicate(cJSON_GetObjectItemCaseSensitive(
	                                         m->plan->doc, "config"), 1));
	cJSON *plan = cJSON_AddObjectToObject(doc, "plan");
	cJSON_AddStringToObject(plan, "hash", m->plan->hash);
	cJSON_AddNumberToObject(plan, "runs", (double)m->plan->run_count);
	cJSON_AddStringToObject(plan, "path", m->plan->path);
	cJSON *merged = cJSON_AddObjectToObject(doc, "merged");
	cJSON *parts = cJSON_AddArrayToObject(merged, "parts");
	cJSON *versions = cJSON_AddArrayToObject(merged, "versions");
	for (size_t p = 0; p < m->part_count; p++) {
		const char *v = string_at(m->parts[p].doc, "bvhlab_version");
		cJSON_AddItemToArray(parts, cJSON_CreateString(m->parts[p].dir));
		cJSON_AddItemToArray(versions, v ? cJSON_CreateString(v) : cJSON_CreateNull());
	}
	return doc;
}

static bool same_machine(const cJSON *a, const cJSON *b)
{
	const char *keys[] = {"hostname", "cpu"};
	for (size_t k = 0; k < 2; k++) {
		const char *x = string_at(a, keys[k]), *y = string_at(b, keys[k]);
		if (!x != !y || (x && strcmp(x, y) != 0))
			return false;
	}
	const cJSON *ca = cJSON_GetObjectItemCaseSensitive(a, "cores");
	const cJSON *cb = cJSON_GetObjectItemCaseSensitive(b, "cores");
	return cJSON_IsNumber(ca) == cJSON_IsNumber(cb) &&
	       (!cJSON_IsNumber(ca) || ca->valuedouble == cb->valuedouble);
}

static size_t count_machines(const cJSON *runs)
{
	size_t n = 0;
	for (const cJSON *r = runs->child; r; r = r->next) {
		const cJSON *mr = cJSON_GetObjectItemCaseSensitive(r, "machine"), *q = runs->child;
		while (q != r && !same_machine(cJSON_GetObjectItemCaseSensitive(q, "machine"), mr))
			q = q->next;
		n += q == r;
	}
	return n;
}

/* Runs in id order; the missing ids and the tallies into sum. */
static int build_runs(const struct merge *m, cJSON *runs, struct merge_summary *sum)
{
	sum->runs = m->plan->run_count;
	sum->missing = calloc(sum->runs ? sum->runs : 1, sizeof(*sum->missing));
	sum->not_ok = calloc(sum->runs ? sum->runs : 1, sizeof(*sum->not_ok));
	if (!sum->missing || !sum->not_ok)
		return -ENOMEM;
	for (size_t id = 0; id < sum->runs; id++) {
		const cJSON *run = m->owner_run[id];
		if (!run) {
			sum->missing[sum->missing_count++] = (uint32_t)id;
			continue;
		}
		cJSON *copy = run_copy(run, m->parts[m->owner_part[id]].doc);
		if (!copy)
			return -ENOMEM;
		cJSON_AddItemToArray(runs, copy);
		sum->present++;
		const char *status = string_at(run, "status");
		if (!status || strcmp(status, "ok") != 0)
			sum->not_ok[sum->not_ok_count++] = (uint32_t)id;
	}
	sum->machines = count_machines(runs);
	return 0;
}

/* ---- writing ------------------------------------------------------------------------ */

/* dir/results.json may only be replaced when it is an earlier merge of this plan. */
static int check_target(const struct plan_file *plan, const char *dir, bvhlab_error *err)
{
	cJSON *old = NULL;
	int r = plan_part_read(dir, &old, err);
	if (r == -ENOENT)
		return 0;
	if (r == 0 && (!cJSON_GetObjectItemCaseSensitive(old, "merged") || !plan_part_hash(old) ||
	               strcmp(plan_part_hash(old), plan->hash) != 0)) {
		error_set(err, "%s/results.json is not an earlier merge of this plan: nothing "
		          "overwritten; merge into another folder", dir);
		r = -EEXIST;
	}
	cJSON_Delete(old);
	return r;
}

/* Copies one file through a temporary one and rename, never following a link. */
static int copy_file(const char *from, const char *dir, const char *name, bvhlab_error *err)
{
	char to[4096], tmp[4096], buf[65536];
	if ((size_t)snprintf(to, sizeof(to), "%s/%s", dir, name) >= sizeof(to) ||
	    (size_t)snprintf(tmp, sizeof(tmp), "%s/.%s.merge.tmp", dir, name) >= sizeof(tmp)) {
		error_set(err, "path too long: %s/%s", dir, name);
		return -ENAMETOOLONG;
	}
	unlink(tmp);
	int from_fd = open(from, O_RDONLY | O_NOFOLLOW | O_CLOEXEC);
	FILE *in = from_fd >= 0 ? fdopen(from_fd, "rb") : NULL;
	if (from_fd >= 0 && !in)
		close(from_fd);
	int fd = in ? open(tmp, O_WRONLY | O_CREAT | O_EXCL | O_NOFOLLOW, 0644) : -1;
	FILE *out = fd >= 0 ? fdopen(fd, "wb") : NULL;
	bool ok = out != NULL;
	size_t n;
	while (ok && (n = fread(buf, 1, sizeof(buf), in)) > 0)
		ok = fwrite(buf, 1, n, out) == n;
	ok = ok && !ferror(in) && fflush(out) == 0 && fsync(fileno(out)) == 0;
	int e = errno ? errno : EIO;
	if (in)
		fclose(in);
	if (out ? fclose(out) != 0 : (fd >= 0 && close(fd) != 0))
		ok = false;
	if (ok && rename(tmp, to) == 0)
		return 0;
	unlink(tmp);
	error_set(err, "cannot copy %s to %s: %s", from, to, strerror(e));
	return -e;
}

/* Every part's images/ into dir/images/ (names are per scene and builder). */
static int copy_images(const struct merge *m, const char *dir, bvhlab_error *err)
{
	char from[4096], to[4096], file[4096];
	snprintf(to, sizeof(to), "%s/images", dir);
	for (size_t p = 0; p < m->part_count; p++) {
		snprintf(from, sizeof(from), "%s/images", m->parts[p].dir);
		DIR *d = opendir(from);
		if (!d)
			continue;
		int r = results_make_dirs(to, err);
		for (struct dirent *e; r == 0 && (e = readdir(d));) {
			if (e->d_name[0] == '.')
				continue; /* ., .. and temporary files */
			struct stat st;
			if ((size_t)snprintf(file, sizeof(file), "%s/%s", from, e->d_name) >= sizeof(file))
				continue; /* not a name bvhlab writes */
			if (lstat(file, &st) < 0 || !S_ISREG(st.st_mode))
				continue; /* bvhlab writes plain files: a link is not followed */
			r = copy_file(file, to, e->d_name, err);
		}
		closedir(d);
		if (r < 0)
			return r;
	}
	return 0;
}

static int write_merged(const struct merge *m, const char *dir, struct merge_summary *sum,
                        bvhlab_error *err)
{
	struct results res = {.doc = merged_header(m), .dir = (char *)dir};
	int r = res.doc ? 0 : -ENOMEM;
	if (r == 0) {
		res.scenes = cJSON_AddArrayToObject(res.doc, "scenes");
		res.runs = cJSON_AddArrayToObject(res.doc, "runs");
		r = res.scenes && res.runs ? 0 : -ENOMEM;
	}
	if (r == 0) {
		add_scenes(res.scenes, m);
		add_not_applicable(res.doc, m);
		r = build_runs(m, res.runs, sum);
	}
	if (r == -ENOMEM)
		error_set(err, "out of memory merging");
	if (r == 0)
		r = results_make_dirs(dir, err);
	if (r == 0)
		r = results_lock(&res, err); /* one writer: a run or another merge */
	if (r == 0)
		r = copy_images(m, dir, err);
	if (r == 0)
		r = results_write(&res, err);
	results_unlock(&res);
	cJSON_Delete(res.doc);
	return r;
}

int plan_merge(const struct plan_file *plan, const char *const *parts, size_t part_count,
               const char *dir, bool mixed, struct merge_summary *sum, bvhlab_error *err)
{
	struct merge m = {.plan = plan, .part_count = part_count, .mixed_versions = mixed};
	memset(sum, 0, sizeof(*sum));
	m.parts = calloc(part_count ? part_count : 1, sizeof(*m.parts));
	m.owner_run = calloc(plan->run_count ? plan->run_count : 1, sizeof(*m.owner_run));
	m.owner_part = calloc(plan->run_count ? plan->run_count : 1, sizeof(*m.owner_part));
	int r = m.parts && m.owner_run && m.owner_part ? 0 : -ENOMEM;
	if (r < 0)
		error_set(err, "out of memory");
	if (r == 0 && part_count == 0) {
		error_set(err, "no part folders to merge");
		r = -EINVAL;
	}
	if (r == 0)
		r = collect(&m, parts, err);
	if (r == 0)
		r = check_identities(&m, err);
	if (r == 0)
		r = check_target(plan, dir, err);
	if (r == 0)
		r = write_merged(&m, dir, sum, err);
	for (size_t p = 0; m.parts && p < part_count; p++)
		cJSON_Delete(m.parts[p].doc);
	free(m.parts);
	free(m.owner_run);
	free(m.owner_part);
	return r;
}

void merge_summary_finish(struct merge_summary *sum)
{
	free(sum->missing);
	free(sum->not_ok);
	memset(sum, 0, sizeof(*sum));
}
