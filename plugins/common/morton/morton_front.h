/*
 * What lbvh, ploc and hploc share around the Morton sort (a part of the
 * same static library): their common options, the team's size, the
 * output's room with scratch past the tree, the scratch mappings, the sort
 * run by a team, the tree of a single primitive, and the build around the
 * builder's own phases (morton_build).
 */
#ifndef BVHLAB_MORTON_FRONT_H
#define BVHLAB_MORTON_FRONT_H

#include <stdbool.h>
#include <stddef.h>
#include <stdint.h>

#include <bvhlab/builder.h>

#include "big_alloc.h"
#include "morton.h"
#include "plugin_options.h"
#include "team.h"

/* The options of the code length and the SAH collapse, in a plugin's
 * table (plugin_options.h), for its struct `owner`: the code length into
 * `bits_member` (uint32_t), the rest into the members of their names. */
#define MORTON_OPTIONS(owner, bits_member)                                                      \
	PLUGIN_OPTION(owner, bits_member, U32, .name = "bits",                                  \
	              .help = "Morton code length: 30 (10 bits per axis) or 63 (21 bits per "   \
	                      "axis)",                                                          \
	              .def_int = 63, .min = 30, .max = 63, .choices = "30|63"),                 \
	PLUGIN_OPTION(owner, collapse, BOOL, .name = "collapse",                                \
	              .help = "turn subtrees of at most max_leaf primitives into leaves where " \
	                      "the SAH says a leaf is cheaper (off: one primitive per leaf)",   \
	              .def_bool = true),                                                        \
	PLUGIN_MAX_LEAF(owner, max_leaf, U32, 64,                                               \
	                "most primitives in a collapsed leaf (8, as the SAH builders)"),        \
	PLUGIN_C_TRAV(owner, c_trav, FLOAT, 1e-6,                                               \
	              "SAH cost of traversing an inner node (> 0), for collapse"),              \
	PLUGIN_C_ISECT(owner, c_isect, FLOAT,                                                   \
	               "SAH cost of intersecting one primitive (> 0), for collapse")

/* Monotonic clock in milliseconds, for the phase times in the debug log. */
double morton_now_ms(void);

static inline size_t morton_align64(size_t x)
{
	return (x + 63) & ~(size_t)63;
}

/* Threads for a build of in: in->threads, fewer on a small input. */
unsigned morton_team_size(const bvhlab_build_input *in);

/* The sort's three buffers of n words, one after another at `at`. */
static inline size_t morton_sort_bytes(size_t n)
{
	return 3 * morton_align64(8 * n);
}

void morton_place_sort(morton_sort *s, char *at);

/* What morton_scratch_alloc() mapped or allocated. */
typedef struct morton_scratch {
	void *region; /* one huge-page mapping (big_alloc), or NULL */
	void *small;  /* the sort's digit counts, then the builder's words */
} morton_scratch;

/*
 * A zero-filled mapping of `region` bytes (none for 0), and the digit
 * counts of s->sort for `threads` threads followed by `extra` uint32_t per
 * thread, which it returns; NULL when out of memory.
 */
uint32_t *morton_scratch_alloc(morton_scratch *scratch, size_t region, morton_sort *sort,
                               unsigned threads, unsigned extra);
void morton_scratch_free(morton_scratch *scratch);

/*
 * A Morton build's scratch, placed: `work` bytes past the tree of n
 * primitives in the output when it has the `spare` nodes of room asked
 * for (big_spare_nodes; then *work_in_output, if not NULL, is true), else
 * at the start of a fresh mapping; the sort's buffers in the output's first nodes, which the
 * tree is written over only after the sort, when they fit, else in the
 * mapping after the work. The digit counts and `extra` words per thread as
 * morton_scratch_alloc. Returns the work area, or NULL when out of memory
 * (*counts then NULL too).
 */
char *morton_scratch_place(morton_scratch *scratch, const bvhlab_build_output *out, uint32_t n,
                           size_t work, uint32_t spare, morton_sort *sort, unsigned threads,
                           unsigned extra, uint32_t **counts, bool *work_in_output);

/* By every member t of tm: the sort of morton.h, barriers included. */
void morton_sort_team(morton_sort *s, team *tm, unsigned t,
                      void (*done)(void *arg, uint32_t first, uint32_t end), void *arg);

/* The whole tree of a single primitive: one leaf. */
void morton_single_leaf(const bvhlab_build_input *in, bvhlab_build_output *out);

/* A phase of a CPU Morton builder after the sort: run(b, t) by every
 * member t of the team, on the builder's state b. */
typedef struct morton_phase {
	const char *name; /* in the debug line */
	void (*run)(void *b, unsigned t);
} morton_phase;

/* The morton_phase's run of fn(type *, unsigned t), as fn##_phase. */
#define MORTON_PHASE_FN(type, fn)                          \
	static void fn##_phase(void *b, unsigned t) \
	{                                           \
		fn((type *)b, t);                   \
	}

/*
 * A CPU Morton builder's build (lbvh, ploc, hploc, hlbvh), for
 * morton_build(): the sort, its first phase, then the builder's own; its
 * state `b`, and in it the sort, the team, the count of threads to ask
 * for, the node count its phases set and its phase times.
 */
typedef struct morton_job {
	void *b;
	morton_sort *sort;          /* the sort's bits set (the `bits` option) */
	team *team;
	uint32_t *threads;          /* set to morton_team_size() */
	const uint32_t *node_count; /* set by the phases */
	double *ms;                 /* member 0's clock (morton_now_ms) at the
	                             * team's start, [0], after the sort, [1], and
	                             * after phase k of `phases`, [k + 2] */
	uint32_t max_prims;         /* most primitives it builds over */
	uint32_t spare;             /* nodes of room past the tree for its scratch,
	                             * big_spare_nodes(), 0 for none */
	/* Its scratch placed (morton_scratch_place into s, which morton_build
	 * frees) and the rest of b set, with the threads and the output's room
	 * known; 0 or -ENOMEM. */
	int (*place)(void *b, bvhlab_build_output *out, morton_scratch *s);
	/* The sort phase's part (may be NULL): morton_sort_team's done, and
	 * sorted(b, t) by every member after the sort, before the barrier
	 * that ends the phase. */
	void (*bucket_done)(void *b, uint32_t first, uint32_t end);
	void (*sorted)(void *b, unsigned t);
	const morton_phase *phases; /* after the sort, in order, ended by one
	                             * with run NULL */
	const uint32_t *count;      /* in the debug line where not NULL, */
	const char *count_name;     /* as "<count> <count_name>" */
	/* Where not NULL: set to the build's team_host before place, for
	 * phases that start the SAH kernel (hlbvh). */
	const team_host **th;
	/* After the team ran (may be NULL): the rest of b's results (such as
	 * the node count), then 0, or the negative errno a phase failed with
	 * (its other members skipping the rest) after host->set_error. */
	int (*finish)(void *b, const bvhlab_host *host, bvhlab_build_ctx *ctx);
	/* Frees what the phases allocated (may be NULL), at the end of every
	 * build of two or more primitives, whether the team ran or not. */
	void (*cleanup)(void *b);
} morton_job;

/* The job's members in a builder's struct *p: members sort, team, threads,
 * node_count and phase_ms. */
#define MORTON_JOB(p)                                                               \
	.b = (p), .sort = &(p)->sort, .team = &(p)->team, .threads = &(p)->threads, \
	.node_count = &(p)->node_count, .ms = (p)->phase_ms

/*
 * The build() of a CPU Morton builder on morton_build (PLUGIN_BUILD_FN: its
 * struct `type`, with members in, n and those of MORTON_JOB, named b and
 * its options read first); the arguments after the type are the rest of
 * its job, designated initialisers of morton_job that may read b.
 */
#define MORTON_BUILD_FN(type, ...)                                       \
	PLUGIN_BUILD_FN(type, morton_job j = { MORTON_JOB(&b), __VA_ARGS__ }; \
	                return morton_build(&j, host, ctx, input, output);)

/*
 * The build of j (its options read by the caller): the count of primitives
 * checked, the output's room, the tree of a single primitive, else the
 * sort's input, the threads, the scratch, the team running the phases, and
 * the output's counts. 0, or a negative errno after host->set_error.
 */
int morton_build(const morton_job *j, const bvhlab_host *host, bvhlab_build_ctx *ctx,
                 const bvhlab_build_input *in, bvhlab_build_output *out);

#endif /* BVHLAB_MORTON_FRONT_H */
