/*
 * bvhlab — a built tree, and everything the core judges it by: structural
 * validation, a brute-force ray check, quality metrics and a canonical
 * comparison of two trees. Every builder is judged by this code. Tracing
 * rays through a tree is trace.h.
 */
#ifndef BVHLAB_TREE_H
#define BVHLAB_TREE_H

#include <stdbool.h>
#include <stdint.h>

#include "builder.h"
#include "scene.h"
#include "types.h"

BVHLAB_BEGIN_DECLS

/*
 * A tree in the standard layout (see bvhlab_node). Owns its arrays, which
 * only bvhlab_tree_init/reserve allocate and bvhlab_tree_finish frees (large
 * ones are page mappings, not malloc blocks): a tree over arrays of your own
 * is fine to read, validate and trace, but not to reserve or finish.
 */
/* One named phase of a build, as the builder reported it (host->phase). */
typedef struct bvhlab_phase {
	char name[BVHLAB_PHASE_NAME_MAX]; /* [a-z0-9_]+ */
	double ms;                        /* milliseconds, summed over the calls */
} bvhlab_phase;

typedef struct bvhlab_tree {
	bvhlab_node *nodes;
	uint32_t node_count;
	uint32_t node_capacity;
	uint32_t *prim_index;
	uint32_t index_count;
	uint32_t index_capacity;
	/* Branching factor (ABI 1.5 bvhlab_build_output.width): 2 to
	 * BVHLAB_MAX_WIDTH; 0, as in a zeroed struct, reads as 2. */
	uint32_t width;
	/* The phases the last bvhlab_build or bvhlab_refine into this tree
	 * reported (ABI 1.3), in the order first reported; 0 when none. */
	uint32_t phase_count;
	bvhlab_phase phases[BVHLAB_MAX_PHASES];
} bvhlab_tree;

/* Allocates capacities (2n - 1 nodes, n indices for n primitives). */
int bvhlab_tree_init(bvhlab_tree *tree, uint32_t node_capacity, uint32_t index_capacity);
/* Grows to at least the given capacities, keeping contents. */
int bvhlab_tree_reserve(bvhlab_tree *tree, uint32_t node_capacity, uint32_t index_capacity);
void bvhlab_tree_finish(bvhlab_tree *tree);

/* ---- validation --------------------------------------------------------- */

/*
 * Structural checks: node and index counts within capacity, every node
 * reachable from the root exactly once (no cycle, no shared child, no orphan),
 * no empty leaf, leaf ranges inside index_count, every prim_index slot used by
 * exactly one leaf, every primitive referenced exactly once (at least once
 * when allow_duplicates, for spatial-split builders), every node's box
 * containing its children's boxes, and every leaf's box its primitives'
 * boxes. With allow_duplicates (spatial splits) a leaf's box may hold only
 * the part of a triangle inside it: then every reference's box must overlap
 * its triangle and the triangle clipped to its references' leaf boxes must
 * cover the whole triangle (uncovered area at most 1e-5 of it, boxes
 * widened by a few float ulps for rounding).
 * 0, or -EINVAL with the first problem found in err (node index included).
 */
int bvhlab_validate_tree(const bvhlab_tree *tree, const bvhlab_build_input *input,
                         bool allow_duplicates, bvhlab_error *err);

/*
 * Sampled rays (seeded, reproducible) traced through the tree and by brute
 * force over every triangle; a mismatch is a hit/miss disagreement or a hit
 * distance that differs by more than a relative 1e-4. A large check runs
 * on the process's executor, on as many threads as the calling thread's
 * CPU set has physical cores (bvhlab_hardware_threads), pinned one a core
 * when pinning is on, as a build's threads are. Returns 0 and fills
 * *mismatches (may be non-zero), or a negative errno on allocation failure.
 */
int bvhlab_validate_rays(const bvhlab_tree *tree, const bvhlab_scene *scene,
                         uint32_t ray_count, uint64_t seed, uint64_t *mismatches,
                         bvhlab_error *err);

/* ---- metrics ------------------------------------------------------------ */

#define BVHLAB_LEAF_HISTOGRAM 17 /* leaf sizes 1..16, then "more than 16" */

/*
 * SAH cost with c_isect = 1 and c_trav(n) = k(n) / 2 for an inner node of
 * k(n) children (one half per child box tested: 1 for every binary node, as
 * in the binary SAH; 2 for a full 4-wide node, 4 for a full 8-wide one),
 * normalised by the root's surface area:
 *   cost = (sum over inner nodes n of SA(n) * k(n) / 2
 *           + sum over leaves l of SA(l) * count(l)) / SA(root)
 * Memory counts node_count * 32 + index_count * 4 bytes.
 */
typedef struct bvhlab_tree_stats {
	uint32_t nodes;
	uint32_t leaves;
	uint32_t max_depth;      /* root has depth 0 */
	double avg_leaf_size;    /* primitive references per leaf */
	uint64_t refs;           /* primitive references in all leaves: the primitive
	                          * count, more with spatial splits' duplicates */
	double sah_cost;
	uint64_t memory_bytes;
	uint32_t leaf_histogram[BVHLAB_LEAF_HISTOGRAM]; /* [k] leaves of size k + 1 */
} bvhlab_tree_stats;

/* Requires a tree that passed bvhlab_validate_tree. */
void bvhlab_tree_stats_compute(const bvhlab_tree *tree, bvhlab_tree_stats *stats);

/* ---- canonical comparison ------------------------------------------------ */

/*
 * Compares two trees regardless of node order: same shape, same boxes (bit
 * for bit), same primitive set in each leaf. 0 when equal; 1 with the first
 * difference described in err; -EINVAL for a malformed tree (cycle, index
 * out of range: validate first); -ENOMEM on allocation failure.
 */
int bvhlab_tree_compare(const bvhlab_tree *a, const bvhlab_tree *b, bvhlab_error *err);

BVHLAB_END_DECLS

#endif /* BVHLAB_TREE_H */
