/*
 * reinsert: a refinement stage (ABI 1.2 refine) that improves a finished
 * tree's SAH by moving subtrees to better places, after Bittner, Hapala &
 * Havran 2013 (insertion-based optimisation) and the batched parallel form
 * of Meister & Bittner 2018. Each iteration:
 *
 *   1. candidates  the `batch` fraction of nodes that hold their children
 *                  worst: area x area / mean child area x area / least
 *                  child area (Bittner et al.), a leaf's cost for a leaf
 *                  (reinsert_choose.c, on the team)
 *   2. search      for every candidate, in parallel over the threads, the
 *                  node beside which it would cost least: what taking it
 *                  out saves (exactly) against what putting it back costs,
 *                  by branch and bound from the root (reinsert_search.c);
 *                  with `children`, also what taking it and its parent
 *                  out and putting its two children back apart would
 *                  save, as Bittner et al. move nodes, and the better of
 *                  the two
 *   3. apply       on one thread, the moves by decreasing predicted gain:
 *                  each is carried out and refitted while the exact change
 *                  of the inner nodes' summed area is added up, and taken
 *                  back (the inverse move restores the same boxes) unless
 *                  that change is negative (reinsert_move.c)
 *
 * So the SAH never rises, every kept move lowers it, the tree stays a
 * valid tree in the standard layout (a move reuses the freed pair of
 * slots) and the result depends on nothing but the tree and the options:
 * the same for every thread count. The loop stops after `iterations`, or
 * when an iteration lowers the SAH by less than `min_gain` of it.
 */
#ifndef BVHLAB_REINSERT_H
#define BVHLAB_REINSERT_H

#include <stdatomic.h>
#include <stdbool.h>
#include <stdint.h>

#include <bvhlab/aabb.h>
#include <bvhlab/builder.h>

#include "team.h"

#define NO_NODE UINT32_MAX

/* Keys a member of the candidates' choice takes at a time (reinsert_choose.c) */
#define CHOOSE_BLOCK 65536u

/* A candidate's best move, saving `gain` (area units): the node beside
 * `dest`; or, when dest2 is a node, the node out and its children put
 * back apart, the one of larger area beside dest, the other beside dest2. */
struct move {
	uint32_t node, dest, dest2;
	double gain;
};

/* A slot's node and parent as they were before a move wrote them; a
 * children move writes fewer than UNDO_MAX (boxes refitted above are not
 * logged: refitting again after the undo restores them). */
#define UNDO_MAX 32

struct undo {
	uint32_t slot, parent;
	bvhlab_node node;
};

/* Option measure's choices, in order. */
enum reinsert_measure { MEASURE_BITTNER = 0, MEASURE_AREA = 1 };

typedef struct reinsert {
	bvhlab_node *nodes;
	uint32_t node_count;
	uint32_t *parent;       /* [node_count] parent slot, NO_NODE at the root */
	uint32_t *cand;         /* [node_count] this iteration's candidates */
	uint32_t cand_count;
	struct move *moves;     /* [node_count] one per candidate */
	uint64_t *keys;         /* [node_count] scratch of the selection */
	uint32_t *hist;         /* [65536 x threads] the members' histograms of keys */
	uint32_t *above, *equal; /* per block of keys: how many above the split bucket, in it */
	uint32_t split;         /* the bucket of the batch's smallest key */
	uint32_t max_visits;    /* nodes a search may take from its queue */
	bool children;          /* children moves searched too */
	int measure;            /* enum reinsert_measure: how the batch is chosen */
	struct undo log[UNDO_MAX]; /* what a children move wrote, to take it back */
	uint32_t log_count;
	atomic_uint next;       /* blocks of keys, then candidates, handed out to the team */
	team team;
} reinsert;

/* The surface area as the core's SAH metric computes it, so that the
 * bookkeeping adds up to the reported cost. */
static inline double area_of(const float lo[3], const float hi[3])
{
	return bvhlab_box_area(lo, hi);
}

static inline double node_area(const bvhlab_node *n)
{
	return area_of(n->lo, n->hi);
}

/* A node's cost: what it adds to the SAH, area times primitives for a leaf. */
static inline double node_cost(const bvhlab_node *n)
{
	return node_area(n) * (n->count ? n->count : 1);
}

static inline void box_union(const bvhlab_node *a, const bvhlab_node *b, float lo[3],
                             float hi[3])
{
	for (int k = 0; k < 3; k++) {
		lo[k] = bvhlab_minf(a->lo[k], b->lo[k]);
		hi[k] = bvhlab_maxf(a->hi[k], b->hi[k]);
	}
}

/* Whether slot d lies in the subtree of slot x (x itself included). */
static inline bool in_subtree(const reinsert *r, uint32_t d, uint32_t x)
{
	for (; d != NO_NODE; d = r->parent[d])
		if (d == x)
			return true;
	return false;
}

static inline uint32_t sibling_of(const reinsert *r, uint32_t x)
{
	uint32_t first = r->nodes[r->parent[x]].first;

	return x == first ? first + 1 : first;
}

/* The batch's candidates into cand[0 .. cand_count), on the team: 0 or a
 * negative errno (no thread could run). hist must hold 65536 x threads. */
int reinsert_choose(reinsert *r, double batch, unsigned threads, const team_host *th);

/* Member t's share of the candidates: their best moves (reinsert_search.c). */
void reinsert_search(reinsert *r);

/* Carries out the move if it lowers the summed area; the change (negative)
 * or 0 when the move was refused or taken back (reinsert_move.c). */
double reinsert_try(reinsert *r, uint32_t node, uint32_t dest);
/* The same for a children move (see struct move). */
double reinsert_try_children(reinsert *r, uint32_t node, uint32_t dest, uint32_t dest2);

#endif /* BVHLAB_REINSERT_H */
