/*
 * Experiment configs: reading the file, the top-level keys, defaults and
 * cleanup. Scenes and builders are in config_entries.c, the checking
 * helpers in config_check.c.
 */
#include <errno.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "config/config_internal.h"
#include "config/json_locate.h"
#include "trace/trace_cl.h"

#define DEFAULT_OUTPUT "results"
#define READ_CHUNK 65536
/* Generous: a run that takes longer is stuck rather than slow. */
#define DEFAULT_TIMEOUT_S 600
/* Long enough that a pass of a few ms is repeated dozens of times. */
#define DEFAULT_RAY_MIN_MS 200.0
#define DEFAULT_RAY_ROUNDS 8

static int out_of_memory(const char *path, bvhlab_error *err)
{
	error_set(err, "%s: out of memory", path);
	return -ENOMEM;
}

static int set_defaults(struct config *cfg)
{
	cfg->format_version = 1;
	cfg->repeat = 5;
	cfg->warmup = 1;
	cfg->validate = true;
	cfg->validate_rays = 256;
	cfg->ray_width = 256;
	cfg->ray_height = 256;
	cfg->ray_diffuse = 1;
	cfg->ray_threads = 1;
	cfg->ray_min_ms = DEFAULT_RAY_MIN_MS;
	cfg->ray_rounds = DEFAULT_RAY_ROUNDS;
	cfg->ray_traversals = 1u << BVHLAB_TRAVERSAL_WIDE;
	cfg->ray_traversal = BVHLAB_TRAVERSAL_WIDE;
	cfg->ray_kinds = RAY_KINDS_DEFAULT;
	cfg->ray_ao_length = DEFAULT_AO_LENGTH;
	cfg->report_reference = strdup("sah_seq");
	if (!cfg->report_reference)
		return -ENOMEM;
	cfg->images = false;
	cfg->isolate = true;
	cfg->timeout_s = DEFAULT_TIMEOUT_S;
	cfg->rays_per_frame = 1000000;
	cfg->threads = malloc(sizeof(*cfg->threads));
	if (!cfg->threads)
		return -ENOMEM;
	cfg->threads[0] = 1;
	cfg->thread_count = 1;
	return 0;
}

static char *folder_of(const char *path)
{
	const char *slash = strrchr(path, '/');
	if (!slash)
		return strdup(".");
	if (slash == path)
		return strdup("/");
	return strndup(path, (size_t)(slash - path));
}

static int parse_format_version(struct config *cfg, bvhlab_error *err)
{
	const cJSON *item = config_member(cfg->root, "format_version");
	uint64_t v = 0;
	if (!item)
		return 0;
	if (!cJSON_IsNumber(item) || json_get_uint64(cfg->locations, item, &v) || v != 1) {
		char got[48];
		return config_error(cfg, item, false, err,
		                    "'format_version' must be 1 (the version this bvhlab reads), not %s",
		                    config_describe(cfg, item, got, sizeof(got)));
	}
	cfg->format_version = 1;
	return 0;
}

/* "output" as read (or the default), resolved against the config's folder. */
static int resolve_output(struct config *cfg, bvhlab_error *err)
{
	char *output = cfg->output;
	int rc = config_resolve(cfg, output ? output : DEFAULT_OUTPUT, &cfg->output);
	free(output);
	if (rc)
		cfg->output = NULL;
	return rc ? out_of_memory(cfg->path, err) : 0;
}

/* enum bvhlab_traversal of a CPU traversal's name; -1 for none (a device
 * traversal is one of these with "device": true). */
static int traversal_of(const char *name)
{
	for (int k = 0; k < BVHLAB_TRAVERSAL_COUNT; k++)
		if (!trace_cl_traversal(k) && strcmp(name, bvhlab_traversal_name(k)) == 0)
			return k;
	return -1;
}

/* The names the device traversals had, or have in results.json: refused
 * with the config's way to say them. 0 for another name. */
static int old_device_name(struct config *cfg, const cJSON *item, bvhlab_error *err)
{
	static const char *const names[][2] = {{"cl_stack", "stack"}, {"cl_stackless", "stackless"},
	                                       {"device_stack", "stack"},
	                                       {"device_stackless", "stackless"},
	                                       {"device_wide8", "wide8"}};
	for (size_t i = 0; cJSON_IsString(item) && i < sizeof(names) / sizeof(names[0]); i++)
		if (strcmp(item->valuestring, names[i][0]) == 0)
			return config_error(cfg, item, false, err,
			                    "'rays.traversal' \"%s\" is written {\"name\": \"%s\", "
			                    "\"device\": true}: a traversal is named for what it does, "
			                    "and \"device\" runs it on the device rays.device picks",
			                    names[i][0], names[i][1]);
	return 0;
}

static int bad_traversal(struct config *cfg, const cJSON *item, bvhlab_error *err)
{
	char got[48];
	if (old_device_name(cfg, item, err) < 0)
		return -EINVAL;
	if (cJSON_IsString(item)) /* a long name shown cut, and said to be */
		snprintf(got, sizeof(got), "\"%.36s%s\"", item->valuestring,
		         strlen(item->valuestring) > 36 ? "..." : "");
	return config_error(cfg, item, false, err,
	                    "'rays.traversal' must be \"wide\", \"wide4\", \"wide8\", \"stack\", "
	                    "\"stackless\", \"both\" "
	                    "(stack and stackless), an entry {\"name\": NAME, \"device\": true, "
	                    "\"optional\": true} (both settings may be left out) or an array of "
	                    "those, not %s",
	                    cJSON_IsString(item) ? got
	                                         : config_describe(cfg, item, got, sizeof(got)));
}

/* The device traversals exist only in a build with a device backend. */
static int traversal_built(struct config *cfg, const cJSON *item, int k, bvhlab_error *err)
{
#ifdef BVHLAB_HAVE_OPENCL
	(void)cfg, (void)item, (void)k, (void)err;
	return 0;
#else
	if (!trace_cl_traversal(k))
		return 0;
	return config_error(cfg, item, false, err,
	                    "'rays.traversal' \"%s\" with \"device\": true runs on a device, and "
	                    "this bvhlab was built without OpenCL, its device backend (install "
	                    "ocl-icd-opencl-dev and opencl-c-headers, then meson setup again)",
	                    bvhlab_traversal_name(k) + strlen("device_"));
#endif
}

/* An entry's settings besides its name. */
struct entry {
	bool optional, device;
};

/* {"name": NAME, "device": BOOL, "optional": BOOL}: its name (or NULL, an
 * error said) and settings. */
static const cJSON *entry_name(struct config *cfg, const cJSON *item, struct entry *e,
                               bvhlab_error *err)
{
	const cJSON *m, *name = NULL;
	*e = (struct entry){false, false};
	if (!cJSON_IsObject(item))
		return item;
	cJSON_ArrayForEach(m, item) {
		if (strcmp(m->string, "name") == 0 && cJSON_IsString(m)) {
			name = m;
		} else if (strcmp(m->string, "optional") == 0 && cJSON_IsBool(m)) {
			e->optional = cJSON_IsTrue(m);
		} else if (strcmp(m->string, "device") == 0 && cJSON_IsBool(m)) {
			e->device = cJSON_IsTrue(m);
		} else {
			config_error(cfg, m, true, err, "'rays.traversal' entries as objects take "
			             "\"name\" (a string), \"device\" and \"optional\" (true or false) "
			             "only");
			return NULL;
		}
	}
	if (!name)
		config_error(cfg, item, false, err, "'rays.traversal' entry lacks \"name\"");
	return name;
}

static bool trace_is_wide_name(int k)
{
	return k == BVHLAB_TRAVERSAL_WIDE || k == BVHLAB_TRAVERSAL_WIDE4 ||
	       k == BVHLAB_TRAVERSAL_WIDE8;
}

/* The traversal an entry asks for: its name's, on the device with
 * "device": true (stack, stackless and wide8 have device kernels). */
static int entry_traversal(struct config *cfg, const cJSON *name, const struct entry *e,
                           bvhlab_error *err)
{
	int k = cJSON_IsString(name) ? traversal_of(name->valuestring) : -1;
	if (k < 0)
		return bad_traversal(cfg, name, err);
	if (!e->device)
		return k;
	if (k == BVHLAB_TRAVERSAL_WIDE8)
		return BVHLAB_TRAVERSAL_DEVICE_WIDE8;
	if (trace_is_wide_name(k))
		return config_error(cfg, name, false, err, "'rays.traversal' \"%s\" has no device "
		                    "kernel: \"device\": true is for \"stack\", \"stackless\" and "
		                    "\"wide8\"", bvhlab_traversal_name(k));
	return BVHLAB_TRAVERSAL_DEVICE_STACK + k;
}

/* One entry of the array form: the first kept is the main traversal. An
 * optional one that this build lacks (a device one without OpenCL) is left
 * out quietly, like an optional builder whose plugin is missing. */
static int add_traversal(struct config *cfg, const cJSON *item, bvhlab_error *err)
{
	struct entry e;
	const cJSON *name = entry_name(cfg, item, &e, err);
	if (!name)
		return -EINVAL;
	int k = entry_traversal(cfg, name, &e, err);
	if (k < 0)
		return -EINVAL;
	if (e.optional && traversal_built(cfg, name, k, NULL) < 0)
		return 0;
	if (traversal_built(cfg, name, k, err) < 0)
		return -EINVAL;
	if (cfg->ray_traversals & (1u << k))
		return config_error(cfg, name, false, err, "'rays.traversal' names \"%s\"%s twice",
		                    name->valuestring, e.device ? " on the device" : "");
	if (cfg->ray_traversals == 0)
		cfg->ray_traversal = k;
	cfg->ray_traversals |= 1u << k;
	return 0;
}

/* "traversal": a name, "both" (stack, then stackless), one entry object
 * or an array of names and entries, the first the main one. */
static int parse_traversal(struct config *cfg, const cJSON *rays, bvhlab_error *err)
{
	const cJSON *t = config_member(rays, "traversal");
	if (!t)
		return 0;
	if (cJSON_IsString(t) && strcmp(t->valuestring, "both") == 0) {
		cfg->ray_traversals = 1u << BVHLAB_TRAVERSAL_STACK | 1u << BVHLAB_TRAVERSAL_STACKLESS;
		cfg->ray_traversal = BVHLAB_TRAVERSAL_STACK;
		return 0;
	}
	if (cJSON_IsString(t) || cJSON_IsObject(t)) {
		cfg->ray_traversals = 0;
		int rc = add_traversal(cfg, t, err);
		if (rc == 0 && cfg->ray_traversals == 0)
			return config_error(cfg, t, false, err, "'rays.traversal': the one entry is "
			                    "optional and not built here (OpenCL was not built)");
		return rc;
	}
	if (!cJSON_IsArray(t) || cJSON_GetArraySize(t) == 0)
		return bad_traversal(cfg, t, err);
	cfg->ray_traversals = 0;
	int rc = 0;
	const cJSON *item;
	cJSON_ArrayForEach(item, t) {
		if (rc == 0)
			rc = add_traversal(cfg, item, err);
	}
	if (rc == 0 && cfg->ray_traversals == 0)
		return config_error(cfg, t, false, err, "'rays.traversal': every entry is optional "
		                    "and none is built here (OpenCL was not built)");
	return rc;
}

/* "device": auto, gpu, cpu or P:D, checked here so a typo fails the
 * config, not every run (which device exists is known only when tracing). */
static int check_device(struct config *cfg, const cJSON *rays, bvhlab_error *err)
{
	const char *d = cfg->ray_device;
	if (!d || !strcmp(d, "auto") || !strcmp(d, "gpu") || !strcmp(d, "cpu"))
		return 0;
	const char *p = d;
	size_t a = strspn(p, "0123456789"), b = a && p[a] == ':' ? strspn(p + a + 1, "0123456789") : 0;
	if (a && a <= 5 && b && b <= 5 && p[a + 1 + b] == '\0')
		return 0;
	return config_error(cfg, config_member(rays, "device"), false, err,
	                    "'rays.device' must be \"auto\", \"gpu\", \"cpu\" or \"P:D\" (OpenCL "
	                    "platform and device indices, e.g. \"0:0\"; clinfo -l lists them), "
	                    "not \"%.40s\"", d);
}

const char *ray_kind_name(int kind)
{
	static const char *const names[RAY_KINDS] = {"primary", "diffuse", "shadow", "ao"};
	return kind >= 0 && kind < RAY_KINDS ? names[kind] : NULL;
}

static int bad_kinds(struct config *cfg, const cJSON *item, bvhlab_error *err)
{
	char got[48];
	if (cJSON_IsString(item))
		snprintf(got, sizeof(got), "\"%.40s\"", item->valuestring);
	else
		config_describe(cfg, item, got, sizeof(got));
	return config_error(cfg, item, false, err, "'rays.kinds' must be an array of \"primary\", "
	                    "\"diffuse\", \"shadow\" and \"ao\", each at most once, not %s", got);
}

/* "kinds": primary must be among them (the others start at its hits), and
 * diffuse needs bounces to make ("diffuse" above 0). */
static int parse_kinds(struct config *cfg, const cJSON *rays, bvhlab_error *err)
{
	const cJSON *t = config_member(rays, "kinds"), *item;
	cfg->has_light = config_member(rays, "light") != NULL;
	if (!t)
		return 0;
	if (!cJSON_IsArray(t) || cJSON_GetArraySize(t) == 0)
		return bad_kinds(cfg, t, err);
	cfg->ray_kinds = 0;
	cJSON_ArrayForEach(item, t) {
		int k = RAY_KINDS;
		while (cJSON_IsString(item) && --k >= 0 && strcmp(item->valuestring, ray_kind_name(k)))
			;
		if (!cJSON_IsString(item) || k < 0 || (cfg->ray_kinds & (1u << k)))
			return bad_kinds(cfg, item, err);
		cfg->ray_kinds |= 1u << k;
	}
	if (!(cfg->ray_kinds & (1u << RAY_PRIMARY)))
		return config_error(cfg, t, false, err, "'rays.kinds' must name \"primary\": the "
		                    "other kinds of rays start at the primary rays' hits");
	if ((cfg->ray_kinds & (1u << RAY_DIFFUSE)) && cfg->ray_diffuse == 0)
		return config_error(cfg, t, false, err, "'rays.kinds' names \"diffuse\" but "
		                    "'rays.diffuse' is 0 (bounces per primary hit)");
	return 0;
}

static int parse_rays(struct config *cfg, bvhlab_error *err)
{
	const cJSON *rays = config_member(cfg->root, "rays");
	if (!rays)
		return 0;
	if (!cJSON_IsObject(rays)) {
		char got[48];
		return config_error(cfg, rays, false, err,
		                    "'rays' must be an object {width, height, diffuse, camera}, not %s",
		                    config_describe(cfg, rays, got, sizeof(got)));
	}
	int rc = config_check_keys(cfg, rays, config_ray_keys, "in rays", err);
	if (!rc)
		rc = config_read_keys(cfg, rays, config_ray_keys, "rays.", cfg, err);
	if (!rc)
		rc = parse_traversal(cfg, rays, err);
	if (!rc)
		rc = check_device(cfg, rays, err);
	if (!rc)
		rc = parse_kinds(cfg, rays, err);
	if (!rc)
		rc = config_parse_camera(cfg, rays, err);
	return rc;
}

static int parse_report(struct config *cfg, bvhlab_error *err)
{
	const cJSON *report = config_member(cfg->root, "report");
	if (!report)
		return 0;
	if (!cJSON_IsObject(report)) {
		char got[48];
		return config_error(cfg, report, false, err,
		                    "'report' must be an object {reference}, not %s",
		                    config_describe(cfg, report, got, sizeof(got)));
	}
	int rc = config_check_keys(cfg, report, config_report_keys, "in report", err);
	if (!rc)
		rc = config_read_keys(cfg, report, config_report_keys, "report.", cfg, err);
	return rc;
}

static int parse_top(struct config *cfg, bvhlab_error *err)
{
	if (!cJSON_IsObject(cfg->root)) {
		char got[48];
		return config_error(cfg, cfg->root, false, err, "a config must be an object, not %s",
		                    config_describe(cfg, cfg->root, got, sizeof(got)));
	}
	int rc = config_check_keys(cfg, cfg->root, config_top_keys, "at the top level", err);
	if (!rc)
		rc = parse_format_version(cfg, err);
	if (!rc)
		rc = config_read_keys(cfg, cfg->root, config_top_keys, "", cfg, err);
	if (!rc)
		rc = resolve_output(cfg, err);
	if (!rc)
		rc = parse_rays(cfg, err);
	if (!rc)
		rc = parse_report(cfg, err);
	if (!rc)
		rc = config_parse_scenes(cfg, err);
	if (!rc)
		rc = config_parse_builders(cfg, err);
	return rc;
}

/* Takes ownership of text. */
static int parse_owned(struct config *cfg, const char *path, char *text, bvhlab_error *err)
{
	memset(cfg, 0, sizeof(*cfg));
	cfg->text = text;
	cfg->path = strdup(path);
	cfg->dir = folder_of(path);
	int rc = cfg->path && cfg->dir ? set_defaults(cfg) : -ENOMEM;
	if (rc) {
		out_of_memory(path, err);
		goto fail;
	}
	rc = json_parse_located(path, text, &cfg->root, &cfg->locations, err);
	if (!rc)
		rc = parse_top(cfg, err);
	if (rc)
		goto fail;
	return 0;
fail:
	config_finish(cfg);
	return rc;
}

int config_parse(struct config *cfg, const char *path, const char *text, bvhlab_error *err)
{
	char *copy = strdup(text);
	if (!copy) {
		memset(cfg, 0, sizeof(*cfg));
		return out_of_memory(path, err);
	}
	return parse_owned(cfg, path, copy, err);
}

static int read_all(FILE *f, char **out, size_t *length)
{
	char *buf = NULL;
	size_t used = 0, capacity = 0;
	for (;;) {
		if (capacity - used < READ_CHUNK + 1) {
			char *grown = realloc(buf, capacity + READ_CHUNK + 1);
			if (!grown) {
				free(buf);
				return -ENOMEM;
			}
			buf = grown;
			capacity += READ_CHUNK + 1;
		}
		size_t n = fread(buf + used, 1, READ_CHUNK, f);
		used += n;
		if (n < READ_CHUNK)
			break;
	}
	if (ferror(f)) {
		free(buf);
		return errno ? -errno : -EIO;
	}
	buf[used] = '\0';
	*out = buf;
	*length = used;
	return 0;
}

int config_load(struct config *cfg, const char *path, bvhlab_error *err)
{
	char *text = NULL;
	size_t length = 0;
	memset(cfg, 0, sizeof(*cfg));
	FILE *f = fopen(path, "rb");
	if (!f) {
		int e = errno;
		error_set(err, "%s: cannot open: %s", path, strerror(e));
		return -e;
	}
	errno = 0;
	int rc = read_all(f, &text, &length);
	fclose(f);
	if (rc) {
		error_set(err, "%s: cannot read: %s", path, strerror(-rc));
		return rc;
	}
	if (strlen(text) != length) {
		/* cJSON would stop at the NUL and read half the file. */
		int line, col;
		json_offset_position(text, strlen(text), &line, &col);
		error_set(err, "%s:%d:%d: NUL byte in the file (not a JSON text file?)", path, line,
		          col);
		free(text);
		return -EINVAL;
	}
	return parse_owned(cfg, path, text, err);
}

void config_finish(struct config *cfg)
{
	if (!cfg)
		return;
	for (size_t i = 0; cfg->scenes && i < cfg->scene_count; i++) {
		free(cfg->scenes[i].name);
		free(cfg->scenes[i].path);
		free(cfg->scenes[i].generator);
		free(cfg->scenes[i].frame_pattern);
		config_parts_free(&cfg->scenes[i]);
		config_instances_free(&cfg->scenes[i]);
	}
	for (size_t i = 0; cfg->builders && i < cfg->builder_count; i++) {
		free(cfg->builders[i].plugin);
		free(cfg->builders[i].top);
		free(cfg->builders[i].name);
		free(cfg->builders[i].threads);
		free(cfg->builders[i].picks);
		config_refine_finish(&cfg->builders[i]);
	}
	config_anim_finish(cfg);
	free(cfg->scenes);
	free(cfg->builders);
	free(cfg->threads);
	free(cfg->output);
	free(cfg->ray_device);
	free(cfg->report_reference);
	json_locations_destroy(cfg->locations);
	cJSON_Delete(cfg->root);
	free(cfg->text);
	free(cfg->dir);
	free(cfg->path);
	memset(cfg, 0, sizeof(*cfg));
}

int config_set_threads(struct config *cfg, const uint32_t *threads, size_t count)
{
	if (!threads || count == 0)
		return -EINVAL;
	for (size_t i = 0; i < count; i++)
		for (size_t j = 0; j < i; j++)
			if (threads[i] == threads[j])
				return -EINVAL;
	uint32_t *copy = malloc(count * sizeof(*copy));
	if (!copy)
		return -ENOMEM;
	memcpy(copy, threads, count * sizeof(*copy));
	free(cfg->threads);
	cfg->threads = copy;
	cfg->thread_count = count;
	return 0;
}
