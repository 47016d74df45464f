/*
 * Measuring one built tree: what a sweep's run child and `bvhlab build`
 * both do after the builds, so the two never drift apart.
 */
#include <errno.h>
#include <string.h>

#include <bvhlab/epo.h>

#include "harness/harness_measure.h"
#include "tree/tree_view.h"
#include "util/util.h"

/* EPO points: a relative standard error of a few per mille on the scenes
 * tried, in tens of milliseconds. Fixed seed: reruns give the same value. */
#define EPO_SAMPLES 16384
#define EPO_SEED 0xe90ULL

static enum tree_verdict validate(const bvhlab_tree *tree, const bvhlab_scene *scene,
                                  const bvhlab_build_input *input, bool spatial_splits,
                                  uint32_t rays, struct tree_measure *m, bvhlab_error *err)
{
	int r = bvhlab_validate_tree(tree, input, spatial_splits, err);
	m->valid = r == 0;
	/* No memory to check the tree says nothing about the tree. */
	if (r == -ENOMEM)
		return TREE_FAILED;
	if (!m->valid)
		return TREE_INVALID;
	if (rays == 0)
		return TREE_OK;
	m->rays_checked = rays;
	if (bvhlab_validate_rays(tree, scene, rays, HARNESS_RAY_SEED, &m->mismatches, err) < 0)
		return TREE_FAILED;
	if (!m->mismatches)
		return TREE_OK;
	m->valid = false;
	error_set(err, "%llu of %llu sampled rays disagree with brute force",
	          (unsigned long long)m->mismatches, (unsigned long long)m->rays_checked);
	return TREE_INVALID;
}

enum tree_verdict harness_measure_tree(const bvhlab_tree *tree, const bvhlab_scene *scene,
                                       const bvhlab_build_input *input, bool spatial_splits,
                                       uint32_t rays, struct tree_measure *m,
                                       bvhlab_error *err)
{
	memset(m, 0, sizeof(*m));
	enum tree_verdict v = validate(tree, scene, input, spatial_splits, rays, m, err);
	/* A tree whose only fault is rays that disagree is still well-formed:
	 * its statistics say what it is. */
	m->has_stats = m->valid || (m->mismatches && m->rays_checked);
	if (m->has_stats)
		bvhlab_tree_stats_compute(tree, &m->stats);
	m->width = tree_width(tree);
	if (v == TREE_OK)
		m->has_epo = bvhlab_tree_epo(tree, scene, EPO_SAMPLES, EPO_SEED, &m->epo) == 0;
	return v;
}
