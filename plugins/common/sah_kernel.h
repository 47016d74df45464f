/*
 * The SAH split kernel shared by every SAH plugin (sah_seq, sah_even,
 * sah_uneven, sah_queue). The plugins differ only in how they schedule node
 * jobs; the kernel decides every split, so with the same options they all
 * build the same tree, up to the order of the nodes in the array.
 *
 * Use:
 *     sah_options opt;  sah_builder b;  sah_job root;
 *     sah_options_read(host, ctx, &opt);
 *     sah_builder_init(&b, &opt, input, output);    (allocates, presorts)
 *     sah_builder_root(&b, &root);
 *     ... sah_split_job() on jobs, from any threads, and/or
 *         sah_build_subtree() on jobs below a scheduler's cutoff ...
 *     sah_builder_finish(&b, output);  (after every job is done)
 *     sah_builder_free(&b);
 *
 * Split rule (both methods). With A the node's surface area, N its
 * primitive count and A_L, N_L, A_R, N_R those of a candidate split,
 *     split cost = c_trav + c_isect * (A_L * N_L + A_R * N_R) / A
 *     leaf cost  = c_isect * N
 * The best split is the one of lowest cost; ties go to the lower axis
 * (x, y, z), then to the lower position. Only splits that separate
 * centroids are candidates (a plane strictly between two centroid values).
 * A node becomes a leaf when N == 1, or when N <= max_leaf and leaf cost <=
 * best split cost (or no candidate exists). When N > max_leaf and there is
 * no candidate (every centroid equal along every axis), the range is split
 * in the middle of its current order (object median), so leaves larger
 * than max_leaf never occur.
 * Jobs of at most 64 primitives (SAH_SMALL_MAX) are built whole at once
 * with exact SAH whatever the method (sah_small.c); above that:
 *   "sweep":  exact SAH, every position between consecutive distinct
 *             centroids along each axis, from a presort done once per build.
 *   "binned": `bins` equal bins per axis over the node's centroid bounds,
 *             cost at each bin boundary.
 * Node boxes are exact unions of input->prim_bounds (the root's is
 * input->bounds), so they do not depend on the method's bookkeeping.
 *
 * Thread safety — the invariant every scheduler relies on:
 *   All scratch memory is indexed either by position inside the job's
 *   primitive range [begin, end) or by the id of a primitive inside that
 *   range. Jobs on disjoint ranges (any two jobs that are not ancestor and
 *   descendant) therefore never write the same location, and the kernel
 *   keeps no per-thread or per-builder mutable scratch besides the atomic
 *   node counter. Any number of threads may call sah_split_job or
 *   sah_build_subtree concurrently on disjoint jobs without locking. A job
 *   must only be processed after its parent's sah_split_job returned (the
 *   scheduler's hand-over, e.g. a thread start or a locked queue, provides
 *   the needed happens-before). Per job the kernel writes only
 *   nodes[job->node], and for a leaf or a small job (built whole) the nodes
 *   it allocates and output->prim_index[begin, end).
 * Determinism: a split depends only on the primitives in the range and
 * their order there, which itself depends only on the ancestors' splits;
 * never on the thread or the order in which jobs run. The SIMD and plain
 * C code paths (sah_simd.h) give bit-identical trees too.
 *
 * Cost: sweep keeps 4 primitive arrays of 32 bytes plus 5 bytes of
 * scratch per primitive (~133 MB for 1M triangles) and presorts in
 * sah_builder_init (single-threaded, O(N)); binned keeps two 32-byte
 * arrays (~69 MB for 1M). sah_split_job needs about 60 KB of stack for
 * binned (bins live there) and 6 KB for a small job; size thread stacks
 * accordingly.
 */
#ifndef BVHLAB_SAH_KERNEL_H
#define BVHLAB_SAH_KERNEL_H

#include <stdatomic.h>
#include <stdint.h>

#include <bvhlab/builder.h>

enum sah_method {
	SAH_SWEEP = 0,  /* exact SAH over presorted centroids */
	SAH_BINNED = 1, /* binned SAH */
};

enum sah_simd {
	SAH_SIMD_SSE = 0,  /* 4-lane vectors (SSE2, or plain C off x86) */
	SAH_SIMD_AVX2 = 1, /* 8-lane binning, where the CPU has AVX2 */
};

/* Build parameters, as read from the plugin options. */
typedef struct sah_options {
	int method;        /* enum sah_method */
	int simd;          /* enum sah_simd; same trees either way */
	uint32_t bins;     /* bins per axis for SAH_BINNED, 2..SAH_MAX_BINS */
	uint32_t max_leaf; /* largest leaf, >= 1 (except coincident centroids) */
	float c_trav;      /* cost of visiting an inner node, > 0 */
	float c_isect;     /* cost of one primitive test, > 0 */
} sah_options;

#define SAH_MAX_BINS 256

/*
 * The option declarations of the kernel, to put first into a plugin's
 * option array: static const bvhlab_option_decl o[] = { SAH_OPTION_DECLS,
 * { ...the plugin's own... } }; SAH_OPTION_COUNT of them.
 */
#define SAH_OPTION_DECLS \
	{ .name = "method", .type = BVHLAB_OPTION_STRING, \
	  .help = "split search: sweep (exact SAH, presorted) or binned", \
	  .def_string = "sweep", .choices = "sweep|binned" }, \
	{ .name = "bins", .type = BVHLAB_OPTION_INT, \
	  .help = "bins per axis for method binned", \
	  .def_int = 32, .min = 2, .max = SAH_MAX_BINS }, \
	{ .name = "max_leaf", .type = BVHLAB_OPTION_INT, \
	  .help = "most primitives in a leaf (unless all their centroids coincide)", \
	  .def_int = 8, .min = 1, .max = 64 }, \
	{ .name = "c_trav", .type = BVHLAB_OPTION_FLOAT, \
	  .help = "SAH cost of traversing an inner node (> 0)", \
	  .def_float = 1.0, .min = 1e-6, .max = 1e6 }, \
	{ .name = "c_isect", .type = BVHLAB_OPTION_FLOAT, \
	  .help = "SAH cost of intersecting one primitive (> 0)", \
	  .def_float = 1.0, .min = 1e-6, .max = 1e6 }, \
	SAH_SIMD_DECL
#define SAH_OPTION_COUNT 6
/* Last, so that plugins with their own copy of the others can add it. */
#define SAH_SIMD_DECL \
	{ .name = "simd", .type = BVHLAB_OPTION_STRING, \
	  .help = "binning vectors: auto (avx2 where the CPU has it), avx2 or sse; " \
	          "the tree is the same", \
	  .def_string = "auto", .choices = "auto|avx2|sse" }

/*
 * Reads the SAH_OPTION_DECLS options through the host's getters and checks
 * them. 0, or a negative errno after host->set_error.
 */
int sah_options_read(const bvhlab_host *host, bvhlab_build_ctx *ctx, sah_options *opt);

/*
 * One node to build: the slot it goes to, its primitives and their bounds.
 * Small and self-contained, so schedulers can copy it into queues.
 */
typedef struct sah_job {
	uint32_t node;     /* index of the node slot this job fills */
	uint32_t begin;    /* first position of its primitives in the working
	                    * arrays (and in output->prim_index) */
	uint32_t end;      /* one past the last position; end > begin */
	uint32_t depth;    /* root 0; for schedulers' cutoffs, not used by splits */
	uint32_t alt;      /* binned: 1 when its primitives are in the builder's
	                    * alt array, 0 when in prims[0] (sweep: always 0) */
	bvhlab_aabb box;   /* exact union of its primitives' boxes */
	bvhlab_aabb cbox;  /* bounds of its primitives' centroids */
} sah_job;

/*
 * A primitive's box and id, copied from the input into the kernel's working
 * arrays so that the split searches stream through memory instead of
 * gathering boxes by id. Its centroid is the box centre, 0.5f * (lo + hi),
 * computed the same way everywhere in the kernel (the core's
 * input->centroids hold the same values).
 */
typedef struct sah_prim {
	float lo[3];  /* box minimum */
	uint32_t id;  /* primitive id, index into input->prim_bounds */
	float hi[3];  /* box maximum */
	uint32_t pad; /* keeps the record 32 bytes and 16-byte aligned */
} sah_prim;

_Static_assert(sizeof(sah_prim) == 32, "sah_prim is 32 bytes");

/*
 * State shared by every job of one build. Set up by sah_builder_init; only
 * node_counter changes afterwards, and the arrays below are written only
 * at positions in [begin, end) of the job being processed or at ids of
 * primitives in that range.
 */
typedef struct sah_builder {
	sah_options opt;            /* copy of the build parameters */
	uint32_t prim_count;        /* primitives in the build, >= 1 */
	bvhlab_aabb root_box;       /* input->bounds */
	bvhlab_aabb root_cbox;      /* bounds of all centroids (computed) */
	bvhlab_node *nodes;         /* output->nodes, >= 2 * prim_count - 1 slots */
	atomic_uint node_counter;   /* node slots handed out; slot 0 is the root */
	/* output->prim_index: a leaf writes the ids of its range [begin, end)
	 * there, in its range's order in prims[0]. */
	uint32_t *ids;
	/* Working primitive arrays, by position; a job's primitives are at
	 * [begin, end). Sweep: prims[a] holds them sorted by centroid along
	 * axis a, ties by id (three arrays, same set per range). Binned:
	 * prims[0] and alt: a split reads its range from one and scatters
	 * it into the other, where its children then are (sah_job.alt);
	 * prims[1], prims[2] NULL. */
	sah_prim *prims[3];
	sah_prim *alt;
	sah_prim *temp;  /* sweep: [prim_count] stable-partition target, by position */
	float *area;     /* sweep: [prim_count] right-side areas, by position */
	uint8_t *side;   /* sweep: [prim_count] left(0)/right(1) mark, by primitive id */
} sah_builder;

/*
 * Binning, for the kernel's binned splits and for schedulers that bin one
 * node in parts (sah_tasks): the grid places centroids, the bins gather
 * counts and box unions. Unions are min/max and counts integers, so bins
 * filled in any parts and merged in any order are bit-identical, and the
 * choice below depends only on the node's set of primitives.
 */
typedef struct sah_grid {
	uint32_t nb;    /* bins per axis */
	float lo[3];    /* the node's centroid bounds' minimum */
	float scale[3]; /* bins per unit length; 0 when the axis is flat */
} sah_grid;

typedef struct sah_bins {
	uint32_t count[3][SAH_MAX_BINS]; /* primitives per bin */
	/* Union of their boxes: lanes 0-2 the minimum negated, 4-6 the
	 * maximum, so that one 8-lane max grows both (3 and 7 unused); all
	 * -inf when empty. Negation is exact, so this is min/max exactly. */
	float box[3][SAH_MAX_BINS][8];
} sah_bins;

/* The grid of nb bins over job's centroid bounds. */
void sah_grid_init(sah_grid *g, const sah_job *job, uint32_t nb);

/* A centroid's bin along axis a. sah_bins_fill computes the same, with
 * the same operations, for three axes at once. */
static inline uint32_t sah_grid_bin(const sah_grid *g, int a, const sah_prim *p)
{
	float f = (0.5f * (p->lo[a] + p->hi[a]) - g->lo[a]) * g->scale[a];
	float top = (float)(g->nb - 1);

	f = f < top ? f : top;
	return f > 0 ? (uint32_t)f : 0;
}

/* Overwrites the grid's bins in out with prims[begin, end), with 8-lane
 * vectors when simd is SAH_SIMD_AVX2 (which sah_options_read only picks
 * where the CPU has AVX2). */
void sah_bins_fill(sah_bins *out, const sah_grid *g, const sah_prim *prims, uint32_t begin,
                   uint32_t end, int simd);

/* Adds src's bins into dst. */
void sah_bins_merge(sah_bins *dst, const sah_bins *src, uint32_t nb);

/*
 * The split of lowest cost A_L * N_L + A_R * N_R over every bin boundary
 * of the three axes (ties: lower axis, then lower boundary); candidate
 * boundaries separate two non-empty bins. Returns the axis (-1: none) and
 * sets *split (left = bins below it) and *cost.
 */
int sah_bins_choose(const sah_bins *g, const sah_grid *grid, uint32_t *split, float *cost);

/* The union of axis a's bins in [from, to). */
void sah_bins_box(const sah_bins *g, int a, uint32_t from, uint32_t to, bvhlab_aabb *box);

/*
 * Prepares a build of input into output (prim_index needs prim_count
 * slots, nodes 2 * prim_count - 1): copies the primitives into the working
 * arrays and, for sweep, presorts them along each axis (LSD radix sort,
 * stable) and allocates the partition scratch.
 * Reserves node slot 0 for the root. 0, -EINVAL (bad input or too small
 * output) or -ENOMEM; on failure nothing is left allocated.
 */
int sah_builder_init(sah_builder *b, const sah_options *opt,
                     const bvhlab_build_input *input, bvhlab_build_output *output);

/* The job that builds the whole tree into node 0. */
void sah_builder_root(const sah_builder *b, sah_job *root);

/*
 * Processes one node: writes nodes[job->node] and returns 0 if it became a
 * leaf or, being small, was built with its whole subtree; or allocates two
 * adjacent node slots (the node's children, first and first + 1), fills
 * child[0] (left) and child[1] (right) and returns 2.
 * Never fails, never allocates. Thread-safe on disjoint jobs (see above).
 */
unsigned sah_split_job(sah_builder *b, const sah_job *job, sah_job child[2]);

/*
 * Builds the whole subtree of job on the calling thread (explicit stack of
 * O(log N) depth: the larger child waits, the smaller is processed first).
 */
void sah_build_subtree(sah_builder *b, const sah_job *job);

/* The array job's primitives are in. */
static inline sah_prim *sah_job_prims(const sah_builder *b, const sah_job *job)
{
	return job->alt ? b->alt : b->prims[0];
}

/* Node slots used so far. */
static inline uint32_t sah_node_count(sah_builder *b)
{
	return atomic_load_explicit(&b->node_counter, memory_order_relaxed);
}

/*
 * Reports the finished tree: output->node_count from the node counter,
 * output->index_count = prim_count. Call once every job is done.
 */
void sah_builder_finish(sah_builder *b, bvhlab_build_output *output);

/* Frees the scratch; the output stays. Safe after a failed init. */
void sah_builder_free(sah_builder *b);

#endif /* BVHLAB_SAH_KERNEL_H */
