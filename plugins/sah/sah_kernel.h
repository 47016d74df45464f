/*
 * The SAH split kernel shared by every SAH plugin (sah_seq, sah_even,
 * sah_uneven, sah_queue). The plugins differ only in how they schedule node
 * jobs; the kernel decides every split, so with the same options they all
 * build the same tree, up to the order of the nodes in the array.
 *
 * Use:
 *     sah_options opt;  sah_builder b;  sah_job root;
 *     PLUGIN_OPTIONS_GET(..., &opt);  (a table holding SAH_OPTIONS, and
 *     sah_options_resolve(host, ctx, &opt.sah) its PLUGIN_DECLS check)
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

#include "plugin_options.h"
#include "sah_bins.h"
#include "sah_types.h"

/*
 * The kernel's options (plugin_options.h), each with its field in the
 * sah_options member `sah` of a plugin's option struct `owner`, to put
 * first into the plugin's table:
 *     static const plugin_option o[] = { SAH_OPTIONS(owner), ...the plugin's own... };
 * A plugin with its own `method` (sah_tasks) takes the groups below it.
 */
#define SAH_OPTIONS(owner)                                                            \
	PLUGIN_OPTION(owner, sah.method, CHOICE, .name = "method",                    \
	              .help = "split search: sweep (exact SAH, presorted) or binned", \
	              .def_string = "sweep", .choices = "sweep|binned"),              \
	SAH_SPLIT_OPTIONS(owner), SAH_SIMD_OPTION(owner), SAH_QUALITY_OPTION(owner)

/* The split rule's parameters. */
#define SAH_SPLIT_OPTIONS(owner)                                                                 \
	PLUGIN_OPTION(owner, sah.bins, U32, .name = "bins",                                      \
	              .help = "bins per axis for method binned",                                 \
	              .def_int = 32, .min = 2, .max = SAH_MAX_BINS),                             \
	PLUGIN_MAX_LEAF(owner, sah.max_leaf, U32, 64,                                            \
	                "most primitives in a leaf (unless all their centroids coincide)"),      \
	PLUGIN_C_TRAV(owner, sah.c_trav, FLOAT, 1e-6,                                            \
	              "SAH cost of traversing an inner node (> 0)"),                             \
	PLUGIN_C_ISECT(owner, sah.c_isect, FLOAT, "SAH cost of intersecting one primitive (> 0)")

#define SAH_SIMD_OPTION(owner)                                                                   \
	PLUGIN_OPTION(owner, sah.simd_asked, CHOICE, .name = "simd",                             \
	              .help = "binning vectors: auto (avx2 where the CPU has it), avx2 or sse; " \
	                      "the tree is the same",                                            \
	              .def_string = "auto", .choices = "auto|avx2|sse")

#define SAH_QUALITY_OPTION(owner)                                                                \
	PLUGIN_OPTION(owner, sah.quality, CHOICE, .name = "quality",                             \
	              .help = "high (every axis, exact SAH on small jobs) or fast (the longest " \
	                      "centroid axis only: a cheaper search, a slightly worse tree)",    \
	              .def_string = "high", .choices = "high|fast")

/*
 * Decides opt->simd from opt->simd_asked, the one thing about the options
 * their declarations cannot say (whether this CPU has AVX2). 0, or a
 * negative errno after host->set_error.
 */
int sah_options_resolve(const bvhlab_host *host, bvhlab_build_ctx *ctx, sah_options *opt);

/*
 * Prepares a build of input into output (prim_index needs prim_count
 * slots, nodes 2 * prim_count - 1): copies the primitives into the working
 * arrays (with up to input->threads threads of th's build)
 * arrays and, for sweep, presorts them along each axis (LSD radix sort,
 * stable) and allocates the partition scratch.
 * Reserves node slot 0 for the root. 0, -EINVAL (bad input or too small
 * output) or -ENOMEM; on failure nothing is left allocated.
 */
int sah_builder_init(sah_builder *b, const sah_options *opt,
                     const bvhlab_build_input *input, bvhlab_build_output *output,
                     const team_host *th);

/*
 * Nodes past a tree of n primitives (2n - 1 nodes) that hold the record
 * arrays of a build with `method`, when the output has that room: ask the
 * host for it before sah_builder_init (fine if refused; the arrays are
 * then mapped for the build). 0 when it would not fit a count
 * (big_spare_nodes).
 */
uint32_t sah_scratch_nodes(int method, uint32_t n);

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

/*
 * Reports the finished tree: output->node_count from the node counter,
 * output->index_count = prim_count. Call once every job is done.
 */
void sah_builder_finish(sah_builder *b, bvhlab_build_output *output);

/* Frees the scratch; the output stays. Safe after a failed init. */
void sah_builder_free(sah_builder *b);

#endif /* BVHLAB_SAH_KERNEL_H */
