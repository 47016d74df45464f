/*
 * Ray timings in interleaved rounds. A shared machine has stretches, from a
 * fraction of a second to a few seconds, in which everything traced runs
 * 25-45 % slower (measured on the project's VM); a run whose batches were
 * timed inside one got a low figure in one run of a config and not in the
 * next. So with "rays.rounds" > 1 each run's child leaves its validated
 * tree in a temporary file, and once every run of the scene is done one
 * child loads them all and gives each tree's batches a slice of min_ms /
 * rounds per round, the trees in turn: each tree's passes are spread over
 * the whole phase, and a slow stretch costs every tree a few slices rather
 * than one tree its figure. The figures over all slices replace the short
 * provisional ones each run's child measured (those keep their counters,
 * images and hits).
 */
#ifndef BVHLAB_CORE_HARNESS_ROUNDS_H
#define BVHLAB_CORE_HARNESS_ROUNDS_H

#include <stdbool.h>
#include <stddef.h>
#include <stdint.h>

#include <bvhlab/scene.h>
#include <bvhlab/tree.h>

#include "config/config.h"
#include "output/results.h"

/* One run waiting for the rounds. */
struct rounds_entry {
	char *path;            /* its tree file */
	const struct run_identity *run; /* from the sweep's run list */
	bool duplicates;       /* spatial splits: validated as such */
	struct ray_metrics rays; /* the run's own; timings replaced by the rounds */
	bool timed;            /* rays now hold the rounds' timings */
};

struct harness_rounds {
	struct rounds_entry *entries;
	size_t count, cap;
};

/* Whether a scene gets interleaved rounds: cfg->ray_rounds > 1 and one
 * of its trees with its tracing copies fits in half of this machine's
 * memory (the rounds take as many trees at once as fit); when it does
 * not, says so on stderr (tty: after the progress line). */
bool harness_rounds_start(const struct config *cfg, const bvhlab_scene *scene, bool tty);

/* After the scene's runs: the rounds (in a forked child unless
 * cfg->isolate is false; trees that would not fit in half of the
 * machine's memory together go in groups, a child each), the timings of
 * the trees timed into res (its files rewritten), a failure said on
 * stderr, and the entries and their tree files cleared. */
void harness_rounds_end(struct harness_rounds *r, struct results *res,
                        const struct config *cfg, const bvhlab_scene *scene,
                        const bvhlab_prims *prims, bool tty);

/* The temporary tree file of a run (a dot file in the output folder). */
int harness_rounds_path(char *buf, size_t size, const char *dir, size_t scene, uint32_t run);

/* Deletes the tree files an interrupted sweep left in dir (they can be
 * large: a tree of a 1M-triangle scene takes about 70 MB), and its heat
 * and shade data: images are drawn only from the runs of the sweep that
 * draws them. Safe under the folder's lock only. */
void harness_rounds_sweep(const char *dir);

/* In the run's child: the tree to path. 0 or a negative errno. */
int harness_rounds_write_tree(const char *path, const bvhlab_tree *tree);

/* A run whose tree is in path; its rays were measured in its child. */
int harness_rounds_add(struct harness_rounds *r, const char *path,
                       const struct run_identity *run, bool duplicates,
                       const struct ray_metrics *rays);

void harness_rounds_finish(struct harness_rounds *r);

#endif
