/*
 * bvhlab — a built tree, and everything the core judges it by: structural
 * validation, a brute-force ray check, quality metrics, traversal and a
 * canonical comparison of two trees. Every builder is judged by this code.
 */
#ifndef BVHLAB_TREE_H
#define BVHLAB_TREE_H

#include <stdbool.h>
#include <stdint.h>

#include "scene.h"
#include "types.h"

/* A tree in the standard layout (see bvhlab_node). Owns its arrays. */
typedef struct bvhlab_tree {
	bvhlab_node *nodes;
	uint32_t node_count;
	uint32_t node_capacity;
	uint32_t *prim_index;
	uint32_t index_count;
	uint32_t index_capacity;
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
 * distance that differs by more than a relative 1e-4. Returns 0 and fills
 * *mismatches (may be non-zero), or a negative errno on allocation failure.
 */
int bvhlab_validate_rays(const bvhlab_tree *tree, const bvhlab_scene *scene,
                         uint32_t ray_count, uint64_t seed, uint64_t *mismatches,
                         bvhlab_error *err);

/* ---- metrics ------------------------------------------------------------ */

#define BVHLAB_LEAF_HISTOGRAM 17 /* leaf sizes 1..16, then "more than 16" */

/*
 * SAH cost with c_trav = c_isect = 1, normalised by the root's surface area:
 *   cost = (sum over inner nodes n of SA(n) + sum over leaves l of SA(l) * count(l))
 *          / SA(root)
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

/* ---- traversal ---------------------------------------------------------- */

/* Counters a traversal adds to (may be NULL). */
typedef struct bvhlab_trace_stats {
	uint64_t rays;
	uint64_t nodes_visited;
	uint64_t tris_tested;
} bvhlab_trace_stats;

/*
 * Watertight ray/triangle test (Woop, Benthin, Wald 2013), two-sided. Uses
 * the caller's hit->t as the upper bound (initialise it to ray->tmax) and
 * reports hits with tmin < t < hit->t; u and v weight vertices 1 and 2.
 */
bool bvhlab_intersect_triangle(const bvhlab_ray *ray, const bvhlab_scene *scene,
                               uint32_t prim, bvhlab_hit *hit);

/* Closest hit through the tree (stack-based, near child first). Initialises
 * *hit (t = tmax, prim = BVHLAB_NO_HIT); nodes_visited counts nodes entered. */
void bvhlab_trace_closest(const bvhlab_tree *tree, const bvhlab_scene *scene,
                          const bvhlab_ray *ray, bvhlab_hit *hit, bvhlab_trace_stats *stats);

/*
 * Any hit (occlusion): true when some triangle is hit with tmin < t < tmax.
 * Stops at the first hit found, which fills *hit but need not be the
 * closest; *hit is initialised like bvhlab_trace_closest's. Same counters.
 */
bool bvhlab_trace_any(const bvhlab_tree *tree, const bvhlab_scene *scene,
                      const bvhlab_ray *ray, bvhlab_hit *hit, bvhlab_trace_stats *stats);

/* Closest hit by testing every triangle; initialises *hit like the above. */
void bvhlab_trace_brute(const bvhlab_scene *scene, const bvhlab_ray *ray, bvhlab_hit *hit);

/* ---- canonical comparison ------------------------------------------------ */

/*
 * Compares two trees regardless of node order: same shape, same boxes (bit
 * for bit), same primitive set in each leaf. 0 when equal; 1 with the first
 * difference described in err; -EINVAL for a malformed tree (cycle, index
 * out of range: validate first); -ENOMEM on allocation failure.
 */
int bvhlab_tree_compare(const bvhlab_tree *a, const bvhlab_tree *b, bvhlab_error *err);

#endif /* BVHLAB_TREE_H */
