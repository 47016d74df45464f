/*
 * Measuring one built tree (harness_measure.c): validation, statistics and
 * end-point overlap, in that order and with the same seeds for a sweep's
 * run and for `bvhlab build`, so the two report the same tree alike.
 */
#ifndef BVHLAB_CORE_HARNESS_MEASURE_H
#define BVHLAB_CORE_HARNESS_MEASURE_H

#include <stdbool.h>
#include <stdint.h>

#include <bvhlab/bvhlab.h>

/* Sampled rays against brute force: the same rays for every builder. */
#define HARNESS_RAY_SEED 0x5eedULL

enum tree_verdict {
	TREE_OK,      /* valid: statistics and EPO measured */
	TREE_INVALID, /* broken structure, or rays that disagree with brute force */
	TREE_FAILED,  /* a check could not run (out of memory, say): no verdict */
};

struct tree_measure {
	bool valid;                 /* structure, and the sampled rays when checked */
	uint64_t rays_checked, mismatches;
	bool has_stats;             /* valid, or well-formed with rays that disagree */
	bvhlab_tree_stats stats;
	uint32_t width;             /* the tree's branching factor, 2 to 8 (with stats) */
	bool has_epo;
	double epo;                 /* end-point overlap (bvhlab_tree_epo) */
};

/*
 * Structure is always checked: the metrics are meaningless (and a cyclic
 * tree unsafe to walk) otherwise; then `rays` sampled rays (0: none)
 * against brute force, the statistics, and the EPO of a valid tree. err
 * says why when the verdict is not TREE_OK.
 */
enum tree_verdict harness_measure_tree(const bvhlab_tree *tree, const bvhlab_scene *scene,
                                       const bvhlab_build_input *input, bool spatial_splits,
                                       uint32_t rays, struct tree_measure *m,
                                       bvhlab_error *err);

#endif
