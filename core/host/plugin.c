/*
 * Loading and checking builder plugins (finding them is plugin_search.c).
 *
 * Every way a plugin can be unusable is caught here, once, with a message
 * naming the plugin, so the harness can report it and go on.
 */
#include <dlfcn.h>
#include <errno.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <unistd.h>

#include <bvhlab/host.h>

#include "host/plugin_search.h"
#include "util/util.h"

/* The fields of bvhlab_builder up to and including `build` (ABI 1.0). */
#define BUILDER_MIN_SIZE (offsetof(bvhlab_builder, build) + sizeof(((bvhlab_builder *)0)->build))

struct bvhlab_plugin {
	void *handle;
	const bvhlab_builder *builder;
	char *path;
};

/* An INT option's choices (1.6): integers within its range, the default
 * one of them; a mistake here would refuse every config. */
static int check_int_choices(const bvhlab_builder *b, const bvhlab_option_decl *d,
                             const char *path, bvhlab_error *err)
{
	bool has_def = false;
	for (const char *p = d->choices; *p;) {
		char *end;
		long long v = strtoll(p, &end, 10);
		bool in_range = !(d->min <= d->max) || ((double)v >= d->min && (double)v <= d->max);
		if (end == p || (*end && *end != '|') || !in_range) {
			error_set(err, "plugin %s ('%s'): option '%s' declares choices '%s': integers "
			          "within its range, separated by '|'", path, b->name, d->name, d->choices);
			return -EINVAL;
		}
		has_def = has_def || v == d->def_int;
		p = *end ? end + 1 : end;
	}
	if (has_def)
		return 0;
	error_set(err, "plugin %s ('%s'): option '%s' defaults to %lld, not one of its choices %s",
	          path, b->name, d->name, (long long)d->def_int, d->choices);
	return -EINVAL;
}

static int check_options(const bvhlab_builder *b, const char *path, bvhlab_error *err)
{
	if (b->option_count && !b->options) {
		error_set(err, "plugin %s: option_count %u but no option table", path,
		          b->option_count);
		return -EINVAL;
	}
	for (uint32_t k = 0; k < b->option_count; k++) {
		const bvhlab_option_decl *d = &b->options[k];
		if (!d->name || !*d->name || d->type < BVHLAB_OPTION_BOOL ||
		    d->type > BVHLAB_OPTION_STRING) {
			error_set(err, "plugin %s: option %u has no name or an unknown type", path, k);
			return -EINVAL;
		}
		if (d->type == BVHLAB_OPTION_INT && d->choices && bvhlab_builder_int_choices(b) &&
		    check_int_choices(b, d, path, err) < 0)
			return -EINVAL;
	}
	if (bvhlab_builder_fill_options(b) && b->options_size == 0) {
		error_set(err, "plugin %s ('%s'): fill_options without options_size", path, b->name);
		return -EINVAL;
	}
	return 0;
}

/* The descriptor checks, in the order a user would want them reported. */
static int check_builder(const bvhlab_builder *b, const char *path, bvhlab_error *err)
{
	if (!b) {
		error_set(err, "plugin %s: entry point returned no builder for ABI major %d",
		          path, BVHLAB_ABI_MAJOR);
		return -ENOTSUP;
	}
	uint32_t major = BVHLAB_ABI_VERSION_MAJOR(b->abi_version);
	if (major != BVHLAB_ABI_MAJOR) {
		error_set(err, "plugin %s: built for ABI %u.%u, this host speaks ABI %d.x", path,
		          major, BVHLAB_ABI_VERSION_MINOR(b->abi_version), BVHLAB_ABI_MAJOR);
		return -ENOTSUP;
	}
	if (b->struct_size < BUILDER_MIN_SIZE) {
		error_set(err, "plugin %s: descriptor struct_size %u is smaller than ABI 1.0's %zu",
		          path, b->struct_size, (size_t)BUILDER_MIN_SIZE);
		return -EINVAL;
	}
	if (!b->name || !*b->name) {
		error_set(err, "plugin %s: descriptor has no name", path);
		return -EINVAL;
	}
	if (!b->build && !bvhlab_builder_refine(b) && !bvhlab_builder_update(b)) {
		error_set(err, "plugin %s ('%s'): descriptor has no build function", path, b->name);
		return -EINVAL;
	}
	return check_options(b, path, err);
}

bvhlab_refine_fn bvhlab_builder_refine(const bvhlab_builder *b)
{
	return BVHLAB_BUILDER_HAS(b, refine) ? b->refine : NULL;
}

bool bvhlab_builder_takes_boxes(const bvhlab_builder *b)
{
	/* The flag bit was unused before 1.5: an older plugin's is not it. */
	return BVHLAB_ABI_VERSION_MINOR(b->abi_version) >= 5 && (b->flags & BVHLAB_BUILDER_BOXES);
}

bvhlab_refine_fn bvhlab_builder_update(const bvhlab_builder *b)
{
	return BVHLAB_BUILDER_HAS(b, update) ? b->update : NULL;
}

bvhlab_fill_options_fn bvhlab_builder_fill_options(const bvhlab_builder *b)
{
	return BVHLAB_BUILDER_HAS(b, options_size) ? b->fill_options : NULL;
}

bool bvhlab_builder_int_choices(const bvhlab_builder *b)
{
	/* Before 1.6 choices meant nothing on an INT option: whatever an older
	 * plugin left there is not a rule it asked for. */
	return BVHLAB_ABI_VERSION_MINOR(b->abi_version) >= 6;
}

uint32_t bvhlab_builder_peak_bytes_per_prim(const bvhlab_builder *b, const void *filled,
                                            bool *declared)
{
	uint32_t bytes = BVHLAB_BUILDER_HAS(b, peak_bytes_per_prim) ? b->peak_bytes_per_prim : 0;
	if (filled && BVHLAB_BUILDER_HAS(b, peak_bytes_for) && b->peak_bytes_for &&
	    b->peak_bytes_for(filled))
		bytes = b->peak_bytes_for(filled);
	*declared = bytes != 0;
	return bytes ? bytes : BVHLAB_UNDECLARED_BYTES_PER_PRIM;
}

static int load(bvhlab_plugin *p, bvhlab_error *err)
{
	p->handle = dlopen(p->path, RTLD_NOW | RTLD_LOCAL);
	if (!p->handle) {
		const char *why = dlerror();
		error_set(err, "plugin %s: cannot load: %s", p->path, why ? why : "unknown error");
		return access(p->path, F_OK) == 0 ? -ENOEXEC : -ENOENT;
	}
	dlerror();
	void *sym = dlsym(p->handle, BVHLAB_PLUGIN_ENTRY_NAME);
	if (!sym) {
		error_set(err, "plugin %s: no entry point '%s' (not a bvhlab plugin?)", p->path,
		          BVHLAB_PLUGIN_ENTRY_NAME);
		return -ENOEXEC;
	}
	bvhlab_plugin_entry_fn entry;
	/* POSIX guarantees object/function pointer round trips for dlsym. */
	memcpy(&entry, &sym, sizeof(entry));
	p->builder = entry(BVHLAB_ABI_MAJOR);
	return check_builder(p->builder, p->path, err);
}

int bvhlab_plugin_open(const char *name_or_path, bvhlab_plugin **out, bvhlab_error *err)
{
	char path[4096];
	*out = NULL;
	int r = plugin_resolve(name_or_path, path, sizeof(path), err);
	if (r < 0)
		return r;
	bvhlab_plugin *p = calloc(1, sizeof(*p));
	if (!p || !(p->path = strdup(path))) {
		free(p);
		error_set(err, "plugin '%s': out of memory", name_or_path);
		return -ENOMEM;
	}
	r = load(p, err);
	if (r < 0) {
		bvhlab_plugin_close(p);
		return r;
	}
	*out = p;
	return 0;
}

void bvhlab_plugin_close(bvhlab_plugin *plugin)
{
	if (!plugin)
		return;
	if (plugin->handle)
		dlclose(plugin->handle);
	free(plugin->path);
	free(plugin);
}

const bvhlab_builder *bvhlab_plugin_builder(const bvhlab_plugin *plugin)
{
	return plugin->builder;
}

const char *bvhlab_plugin_path(const bvhlab_plugin *plugin)
{
	return plugin->path;
}
