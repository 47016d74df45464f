/*
 * The scene files of a plan, by content: a plan's identity covers the data
 * its runs measure, not only the config's text, so a part run after a mesh
 * was regenerated is refused, and a plan made again over other data is
 * another plan (its parts do not merge with the old ones).
 */
#include <errno.h>
#include <fcntl.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>
#include <unistd.h>

#include <cJSON.h>

#include "plan/plan.h"
#include "util/util.h"

/* Size and 64-bit FNV-1a of the file's bytes; a negative errno if unreadable. */
int plan_fingerprint(const char *path, struct plan_fingerprint *fp)
{
	static unsigned char buf[1 << 16];
	uint64_t h = 0xcbf29ce484222325ULL, size = 0;
	int fd = open(path, O_RDONLY | O_CLOEXEC | O_NONBLOCK);
	struct stat st;
	if (fd < 0)
		return -errno;
	if (fstat(fd, &st) < 0 || !S_ISREG(st.st_mode)) {
		close(fd);
		return -EINVAL; /* a FIFO or device is refused when the run loads it */
	}
	ssize_t n;
	while ((n = read(fd, buf, sizeof(buf))) > 0) {
		for (ssize_t k = 0; k < n; k++)
			h = (h ^ buf[k]) * 0x100000001b3ULL;
		size += (uint64_t)n;
	}
	int e = n < 0 ? errno : 0;
	close(fd);
	fp->size = (double)size;
	snprintf(fp->hash, sizeof(fp->hash), "%016llx", (unsigned long long)h);
	return -e;
}

int plan_scene_each_file(const struct config_scene *cs, plan_file_fn fn, size_t *k, void *ctx)
{
	char frame[4096], what[64];
	/* A frame pattern's path is frame 0's file unless it names one of its own. */
	frame[0] = '\0';
	if (cs->frame_pattern)
		snprintf(frame, sizeof(frame), cs->frame_pattern, (int)cs->frame_first);
	int r = cs->path ? fn(cs->path, strcmp(frame, cs->path) ? "" : "frame 0: ", (*k)++, ctx) : 0;
	for (size_t p = 0; r == 0 && p < cs->part_count; p++) {
		snprintf(what, sizeof(what), "part %zu: ", p);
		if (cs->parts[p].src.path)
			r = fn(cs->parts[p].src.path, what, (*k)++, ctx);
	}
	for (size_t m = 0; r == 0 && m < cs->mesh_count; m++) {
		snprintf(what, sizeof(what), "mesh '%.40s': ", cs->meshes[m].name);
		if (cs->meshes[m].src.path)
			r = fn(cs->meshes[m].src.path, what, (*k)++, ctx);
	}
	for (uint32_t f = 0; r == 0 && cs->frame_pattern && f < cs->frames; f++) {
		snprintf(frame, sizeof(frame), cs->frame_pattern, (int)(cs->frame_first + f));
		snprintf(what, sizeof(what), "frame %u: ", f);
		if (!cs->path || strcmp(frame, cs->path) != 0) /* frame 0's is the path */
			r = fn(frame, what, (*k)++, ctx);
	}
	return r;
}

/* Calls fn for every file the config's scenes read, in config order. */
static int each_file(const struct config *cfg, plan_file_fn fn, void *ctx)
{
	size_t k = 0;
	int r = 0;
	for (size_t s = 0; r == 0 && s < cfg->scene_count; s++)
		r = plan_scene_each_file(&cfg->scenes[s], fn, &k, ctx);
	return r;
}

static int add_file(const char *path, const char *what, size_t k, void *ctx)
{
	struct plan_fingerprint fp;
	cJSON *o = cJSON_CreateObject();
	(void)what;
	(void)k;
	cJSON_AddItemToArray(ctx, o);
	cJSON_AddStringToObject(o, "path", path);
	if (plan_fingerprint(path, &fp) < 0)
		return 0; /* missing here: the run that loads it says so */
	cJSON_AddNumberToObject(o, "size", fp.size);
	cJSON_AddStringToObject(o, "hash", fp.hash);
	return 0;
}

struct cJSON *plan_scene_files(const struct config *cfg)
{
	cJSON *files = cJSON_CreateArray();
	if (files)
		each_file(cfg, add_file, files);
	return files;
}

struct check {
	const cJSON *files;
	const char *plan;
	bvhlab_error *err;
};

static int check_file(const char *path, const char *what, size_t k, void *ctx)
{
	struct check *c = ctx;
	(void)what;
	const cJSON *then = cJSON_GetArrayItem(c->files, (int)k);
	const cJSON *size = cJSON_GetObjectItemCaseSensitive(then, "size");
	const cJSON *hash = cJSON_GetObjectItemCaseSensitive(then, "hash");
	struct plan_fingerprint now;
	if (!cJSON_IsNumber(size) || !cJSON_IsString(hash) || plan_fingerprint(path, &now) < 0)
		return 0; /* not known then, or not here now: loading will tell */
	if (now.size == size->valuedouble && strcmp(now.hash, hash->valuestring) == 0)
		return 0;
	error_set(c->err, "%s: scene file %s has changed since planning (%.0f bytes, hash %s "
	          "then; %.0f bytes, hash %s now): its runs would measure other data than the "
	          "plan's other parts; plan again into a new folder", c->plan, path,
	          size->valuedouble, hash->valuestring, now.size, now.hash);
	return -ESTALE;
}

int plan_check_scene_files(const struct plan_file *plan, const struct config *cfg,
                           bvhlab_error *err)
{
	struct check c = {.files = cJSON_GetObjectItemCaseSensitive(plan->doc, "scene_files"),
	                  .plan = plan->path, .err = err};
	if (!cJSON_IsArray(c.files))
		return 0; /* a plan made before scene files were recorded */
	return each_file(cfg, check_file, &c);
}
