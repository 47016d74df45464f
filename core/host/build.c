/*
 * Running one build: the host's function table and the call into a plugin.
 */
#include <errno.h>
#include <pthread.h>
#include <sched.h>
#include <stdarg.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include <bvhlab/host.h>
#include <bvhlab/machine.h>

#include "host/options_fill.h"
#include "device/device.h"
#include "host/build_ctx.h"
#include "machine/machine.h"
#include "tree/tree_view.h"

/* Messages above this level are dropped; BVHLAB_LOG=error|warn|info|debug. */
static int log_threshold(void)
{
	static const char *names[] = {"error", "warn", "info", "debug"};
	const char *env = getenv("BVHLAB_LOG");
	for (int k = 0; env && k < 4; k++)
		if (strcmp(env, names[k]) == 0)
			return k;
	return BVHLAB_LOG_WARN;
}

static void host_log(bvhlab_build_ctx *ctx, int level, const char *fmt, ...)
{
	static const char *names[] = {"error", "warning", "info", "debug"};
	if (level > log_threshold())
		return;
	char line[1024];
	va_list ap;
	va_start(ap, fmt);
	vsnprintf(line, sizeof(line), fmt, ap);
	va_end(ap);
	/* One fprintf per line keeps lines from different threads whole. */
	fprintf(stderr, "[%s] %s: %s\n", ctx->builder->name,
	        names[level < 0 ? 0 : level > 3 ? 3 : level], line);
}

static void host_set_error(bvhlab_build_ctx *ctx, const char *fmt, ...)
{
	va_list ap;
	va_start(ap, fmt);
	error_setv(ctx->err, fmt, ap);
	va_end(ap);
	ctx->error_set = true;
}

/* The declared option `name` of type `type`, or NULL with *r set. */
static const bvhlab_option_value *get(bvhlab_build_ctx *ctx, const char *name, uint32_t type,
                                      int *r)
{
	int k = bvhlab_options_find(ctx->opts, name);
	if (k < 0) {
		*r = -ENOENT;
		return NULL;
	}
	if (ctx->opts->values[k].type != type) {
		*r = -EINVAL;
		return NULL;
	}
	*r = 0;
	return &ctx->opts->values[k];
}

static int host_option_bool(bvhlab_build_ctx *ctx, const char *name, bool *out)
{
	int r;
	const bvhlab_option_value *v = get(ctx, name, BVHLAB_OPTION_BOOL, &r);
	if (v)
		*out = v->b;
	return r;
}

static int host_option_int(bvhlab_build_ctx *ctx, const char *name, int64_t *out)
{
	int r;
	const bvhlab_option_value *v = get(ctx, name, BVHLAB_OPTION_INT, &r);
	if (v)
		*out = v->i;
	return r;
}

static int host_option_float(bvhlab_build_ctx *ctx, const char *name, double *out)
{
	int r;
	const bvhlab_option_value *v = get(ctx, name, BVHLAB_OPTION_FLOAT, &r);
	if (v)
		*out = v->f;
	return r;
}

static int host_option_string(bvhlab_build_ctx *ctx, const char *name, const char **out)
{
	int r;
	const bvhlab_option_value *v = get(ctx, name, BVHLAB_OPTION_STRING, &r);
	if (v)
		*out = v->s ? v->s : "";
	return r;
}

static int host_grow_output(bvhlab_build_ctx *ctx, bvhlab_build_output *out, uint32_t nodes,
                            uint32_t indices)
{
	bvhlab_tree *t = ctx->tree;
	if (!t) /* fill_options has no output to grow */
		return -EINVAL;
	int rc = bvhlab_tree_reserve(t, nodes, indices);
	/* Even a refused reserve may have moved the node array (it grows
	 * first), so the builder gets the current pointers either way. */
	out->nodes = t->nodes;
	out->node_capacity = t->node_capacity;
	out->prim_index = t->prim_index;
	out->index_capacity = t->index_capacity;
	return rc < 0 ? -ENOMEM : 0;
}

static void host_progress(bvhlab_build_ctx *ctx, double fraction)
{
	(void)ctx;
	(void)fraction;
}

static uint32_t host_hardware_threads(bvhlab_build_ctx *ctx)
{
	return exec_place_cpus(&ctx->place);
}

static int host_pin_thread(bvhlab_build_ctx *ctx, uint32_t worker)
{
	return exec_place_pin(&ctx->place, worker);
}

static bool phase_name_ok(const char *name)
{
	size_t n = name ? strlen(name) : 0;
	if (n == 0 || n >= BVHLAB_PHASE_NAME_MAX)
		return false;
	for (size_t k = 0; k < n; k++)
		if (!((name[k] >= 'a' && name[k] <= 'z') || (name[k] >= '0' && name[k] <= '9') ||
		      name[k] == '_'))
			return false;
	return true;
}

/* A refused report is kept for explain(): the build then fails naming it,
 * rather than its figures going missing without a word. */
static void host_phase(bvhlab_build_ctx *ctx, const char *name, double ms)
{
	bvhlab_tree *t = ctx->tree;
	uint32_t k = 0;
	if (ctx->bad_phase[0] || !t) /* no phases in fill_options */
		return;
	if (!phase_name_ok(name)) {
		snprintf(ctx->bad_phase, sizeof(ctx->bad_phase), "'%.40s' (%g ms): names are "
		         "[a-z0-9_], 1 to %d characters", name ? name : "(null)", ms,
		         BVHLAB_PHASE_NAME_MAX - 1);
		return;
	}
	if (!(ms >= 0 && ms <= 1e12)) {
		snprintf(ctx->bad_phase, sizeof(ctx->bad_phase), "'%s' (%g ms): times are finite, "
		         ">= 0 and at most 1e12 ms", name, ms);
		return;
	}
	while (k < t->phase_count && strcmp(t->phases[k].name, name) != 0)
		k++;
	if (k == BVHLAB_MAX_PHASES) {
		snprintf(ctx->bad_phase, sizeof(ctx->bad_phase), "'%s' (more than %d phases)",
		         name, BVHLAB_MAX_PHASES);
		return;
	}
	if (k == t->phase_count) {
		snprintf(t->phases[k].name, sizeof(t->phases[k].name), "%s", name);
		t->phases[k].ms = 0;
		t->phase_count++;
	}
	t->phases[k].ms += ms;
}

static int host_device_program(bvhlab_build_ctx *ctx, const char *spec, const char *source,
                               size_t len, const char *options, const void **device,
                               void **program)
{
	char why[sizeof(ctx->err->message)];
	int r = device_program(spec, source, len, options, device, program, why, sizeof(why));
	if (r < 0)
		host_set_error(ctx, "%s", why);
	return r;
}

static const bvhlab_host host_table = {
	.abi_version = BVHLAB_ABI_CURRENT,
	.struct_size = sizeof(bvhlab_host),
	.log = host_log,
	.set_error = host_set_error,
	.option_bool = host_option_bool,
	.option_int = host_option_int,
	.option_float = host_option_float,
	.option_string = host_option_string,
	.grow_output = host_grow_output,
	.progress = host_progress,
	.hardware_threads = host_hardware_threads,
	.pin_thread = host_pin_thread,
	.phase = host_phase,
	.device_program = host_device_program,
	.run = host_exec_run,
	.for_each = host_exec_for_each,
	.reduce = host_exec_reduce,
	.scan = host_exec_scan,
	.partition = host_exec_partition,
	.sort = host_exec_sort,
	.spawn = host_exec_spawn,
	.join = host_exec_join,
};

static int prepare_tree(bvhlab_tree *tree, uint32_t prims)
{
	uint32_t nodes = prims > 0 ? 2 * prims - 1 : 1;
	if (tree->nodes)
		return bvhlab_tree_reserve(tree, nodes, prims);
	return bvhlab_tree_init(tree, nodes, prims);
}

/* The place comes from the caller's mask now, before any worker (the
 * caller included) narrows it; the caller gets its mask back after. */
static int place_begin(struct bvhlab_build_ctx *ctx)
{
	int r = exec_place_begin(&ctx->place);
	if (r < 0) {
		exec_place_end(&ctx->place);
		error_set(ctx->err, "builder '%s': cannot plan thread pinning (%s)",
		          ctx->builder->name, strerror(-r));
		return r;
	}
	return 0;
}

/* A phase is part of its build: one longer than the whole call is a
 * plugin's mistake (a unit, a clock), refused like a negative one. The
 * margin is for the clocks' resolution. */
static void phases_within(struct bvhlab_build_ctx *ctx, double call_ms)
{
	const bvhlab_tree *t = ctx->tree;
	for (uint32_t k = 0; !ctx->bad_phase[0] && k < t->phase_count; k++)
		if (t->phases[k].ms > call_ms * 1.01 + 0.05)
			snprintf(ctx->bad_phase, sizeof(ctx->bad_phase), "'%s' (%g ms) in a build that "
			         "took %.3g ms: a phase is part of its build, never longer",
			         t->phases[k].name, t->phases[k].ms, call_ms);
}

/* The plugin's status, with a message that names it whatever it said. */
static int explain(const struct bvhlab_build_ctx *ctx, int r)
{
	const char *name = ctx->builder->name;
	if (r == 0 && ctx->bad_phase[0]) {
		error_set(ctx->err, "builder '%s' reported phase %s", name, ctx->bad_phase);
		return -EPROTO;
	}
	if (r < 0 && !ctx->error_set)
		error_set(ctx->err, "builder '%s' failed (%s) without saying why", name,
		          strerror(-r));
	else if (r < 0)
		error_prefix(ctx->err, "builder '%s'", name);
	else if (r > 0) {
		error_set(ctx->err, "builder '%s' returned %d; the ABI allows 0 or a negative errno",
		          name, r);
		r = -EPROTO;
	}
	return r;
}

int options_fill(bvhlab_options *opts, bvhlab_error *err)
{
	const bvhlab_builder *b = opts->builder;
	bvhlab_fill_options_fn fill = bvhlab_builder_fill_options(b);
	free(opts->filled);
	opts->filled = NULL;
	if (!fill)
		return 0;
	void *out = calloc(1, b->options_size);
	if (!out) {
		error_set(err, "plugin '%s': out of memory for its options", b->name);
		return -ENOMEM;
	}
	struct bvhlab_build_ctx ctx = {.builder = b, .opts = opts, .err = err};
	int r = fill(&host_table, &ctx, out);
	if (r == 0) {
		opts->filled = out;
		return 0;
	}
	free(out);
	if (!ctx.error_set)
		error_set(err, "its options are refused (%s) without saying why", strerror(-r));
	error_prefix(err, "plugin '%s'", b->name);
	return r < 0 ? r : -EPROTO;
}

/* The call into the plugin, with pinning around it and the counts back
 * into the tree; `in_place` is its refine or update function (the tree's
 * counts go in), NULL for build. */
static int call_plugin(const bvhlab_plugin *plugin, const bvhlab_options *opts,
                       const bvhlab_build_input *input, uint32_t threads, bvhlab_tree *tree,
                       bvhlab_refine_fn in_place, bvhlab_error *err)
{
	const bvhlab_builder *b = bvhlab_plugin_builder(plugin);
	bvhlab_build_input in = *input;
	in.threads = threads ? threads : bvhlab_hardware_threads();
	in.options = opts ? opts->filled : NULL;
	bvhlab_build_output out = {
		.struct_size = sizeof(out),
		.node_capacity = tree->node_capacity,
		.nodes = tree->nodes,
		.prim_index = tree->prim_index,
		.index_capacity = tree->index_capacity,
		.node_count = in_place ? tree->node_count : 0,
		.index_count = in_place ? tree->index_count : 0,
		.width = in_place ? tree_width(tree) : 2,
	};
	struct bvhlab_build_ctx ctx = {.builder = b, .opts = opts, .tree = tree, .err = err,
	                               .threads = in.threads};
	tree->phase_count = 0;
	int r = place_begin(&ctx);
	if (r < 0)
		return r;
	double t0 = util_now();
	r = in_place ? in_place(&host_table, &ctx, &in, &out)
	             : b->build(&host_table, &ctx, &in, &out);
	phases_within(&ctx, (util_now() - t0) * 1e3);
	exec_place_end(&ctx.place);
	tree->node_count = out.node_count;
	tree->index_count = out.index_count;
	tree->width = out.width;
	return explain(&ctx, r);
}

/* The primitive kind of the input, refused by name to a builder that
 * does not take it (ABI 1.5), before the call. */
static int check_kind(const bvhlab_builder *b, const bvhlab_build_input *input,
                      bvhlab_error *err)
{
	uint32_t kind = input->struct_size >= offsetof(bvhlab_build_input, prim_kind) +
	                                          sizeof(input->prim_kind)
	                        ? input->prim_kind
	                        : BVHLAB_PRIM_TRIANGLES;
	if (kind == BVHLAB_PRIM_TRIANGLES)
		return 0;
	if (kind != BVHLAB_PRIM_BOXES) {
		error_set(err, "builder '%s': unknown primitive kind %u (triangles 0, boxes 1)",
		          b->name, kind);
		return -EINVAL;
	}
	if (bvhlab_builder_takes_boxes(b))
		return 0;
	error_set(err, "builder '%s' builds over triangles only (its descriptor lacks "
	          "BVHLAB_BUILDER_BOXES, ABI 1.5); this build is over boxes", b->name);
	return -ENOTSUP;
}

int bvhlab_build(const bvhlab_plugin *plugin, const bvhlab_options *opts,
                 const bvhlab_build_input *input, uint32_t threads, bvhlab_tree *tree,
                 bvhlab_error *err)
{
	const bvhlab_builder *b = bvhlab_plugin_builder(plugin);
	if (!b->build) {
		error_set(err, "plugin '%s' builds no trees (it refines or updates them); use it in "
		          "a builder's \"refine\" list or \"animation\"", b->name);
		return -ENOTSUP;
	}
	int r = check_kind(b, input, err);
	if (r < 0)
		return r;
	if (prepare_tree(tree, input->prim_count) < 0) {
		error_set(err, "builder '%s': cannot allocate the output for %u primitives", b->name,
		          input->prim_count);
		return -ENOMEM;
	}
	return call_plugin(plugin, opts, input, threads, tree, NULL, err);
}

int bvhlab_refine(const bvhlab_plugin *plugin, const bvhlab_options *opts,
                  const bvhlab_build_input *input, uint32_t threads, bvhlab_tree *tree,
                  bvhlab_error *err)
{
	const bvhlab_builder *b = bvhlab_plugin_builder(plugin);
	if (!bvhlab_builder_refine(b)) {
		error_set(err, "plugin '%s' has no refinement stage (ABI 1.2 refine)", b->name);
		return -ENOTSUP;
	}
	char stage[96];
	snprintf(stage, sizeof(stage), "refinement '%s'", b->name);
	int r = tree_require_binary(tree, stage, err);
	if (r < 0)
		return r;
	return call_plugin(plugin, opts, input, threads, tree, bvhlab_builder_refine(b), err);
}

/* The references a tree over another primitive count would have: fewer
 * slots than primitives (some could not be referenced), or one past the
 * last primitive. Cheap next to any update: one read of prim_index. */
static int check_update_counts(const bvhlab_builder *b, const bvhlab_build_input *input,
                               const bvhlab_tree *tree, bvhlab_error *err)
{
	uint32_t most = 0;
	for (uint32_t k = 0; k < tree->index_count; k++)
		most = tree->prim_index[k] > most ? tree->prim_index[k] : most;
	if (tree->node_count && tree->index_count >= input->prim_count &&
	    most < input->prim_count)
		return 0;
	error_set(err, "update '%s': the tree holds %u references (primitives up to %u), the frame "
	          "has %u triangles: an update keeps the topology (same triangles, same order); "
	          "rebuild instead", b->name, tree->index_count, most, input->prim_count);
	return -EINVAL;
}

int bvhlab_update(const bvhlab_plugin *plugin, const bvhlab_options *opts,
                  const bvhlab_build_input *input, uint32_t threads, bvhlab_tree *tree,
                  bvhlab_error *err)
{
	const bvhlab_builder *b = bvhlab_plugin_builder(plugin);
	if (!bvhlab_builder_update(b)) {
		error_set(err, "plugin '%s' has no update function (ABI 1.4 update)", b->name);
		return -ENOTSUP;
	}
	char stage[96];
	snprintf(stage, sizeof(stage), "update '%s'", b->name);
	int r = tree_require_binary(tree, stage, err);
	if (r == 0)
		r = check_update_counts(b, input, tree, err);
	if (r == 0)
		r = call_plugin(plugin, opts, input, threads, tree, bvhlab_builder_update(b), err);
	return r;
}
