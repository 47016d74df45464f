/*
 * reinsert: the search for each candidate's best new place (read-only on
 * the tree, so the threads share it without locks; each candidate's
 * result goes to its own entry).
 *
 * A subtree move (node N out of its parent P, put beside node X) is
 * searched off N's path (best_path_place): a place inside the sibling
 * subtree of N's ancestor A_k saves P's area and the shrinking of A_2 ..
 * A_k, not of A_{k+1} and above, which keep N inside them. Each of those
 * subtrees is searched best first (Bittner et al. 2013's branch and
 * bound) by the growth of X's ancestors inside it; no place below a node
 * can cost less than that growth plus SA(N), which prunes. Before, one
 * search from the root took every ancestor's shrinking as gained, which
 * overrated moves close to N: on sponza subdivided twice after sah_tasks
 * high (measure area, 3 iterations) the SAH went to 76.134 and now goes to
 * 75.934 in the same time; without children moves, 3 iterations reach
 * 77.07 in a third of the time.
 *
 * The children move (best_place, from the root) searches the tree as it
 * will be without N and P: N's ancestors with their boxes refitted
 * without N (removal_path), P passed through to its other child.
 */
#include <string.h>

#include "reinsert.h"

/* The queue: a binary min-heap on induced cost, of bounded size (a full
 * queue drops what it cannot take: the search then only sees less). */
#define QUEUE_SIZE 1024

struct entry {
	double induced;
	uint32_t node;
};

struct queue {
	struct entry e[QUEUE_SIZE];
	uint32_t size;
};

static void push(struct queue *q, double induced, uint32_t node)
{
	uint32_t k;

	if (q->size == QUEUE_SIZE)
		return;
	for (k = q->size++; k > 0 && q->e[(k - 1) / 2].induced > induced; k = (k - 1) / 2)
		q->e[k] = q->e[(k - 1) / 2];
	q->e[k] = (struct entry){ induced, node };
}

static struct entry pop(struct queue *q)
{
	struct entry top = q->e[0], last = q->e[--q->size];
	uint32_t k = 0;

	for (;;) {
		uint32_t c = 2 * k + 1;

		if (c >= q->size)
			break;
		if (c + 1 < q->size && q->e[c + 1].induced < q->e[c].induced)
			c++;
		if (!(q->e[c].induced < last.induced))
			break;
		q->e[k] = q->e[c];
		k = c;
	}
	q->e[k] = last;
	return top;
}

/*
 * Node x's ancestors above its parent P, each with its box as it will
 * be once x and P are out; a children move's searches see those boxes
 * (found through a small hash set of the path's nodes, so the subtree
 * moves' queue stays as it was). With x's own boxes, putting a child back
 * anywhere under x's old ancestors looked free, though it grows them
 * again from what x's removal left: after sah_tasks high on sponza
 * subdivided twice (measure area, 2 threads), 82 % of the children moves
 * so predicted raised the SAH when carried out and were undone, against
 * 63 % now, and 3 iterations reach 75.724 instead of 75.934 in 219 ms
 * instead of 242. A path deeper than PATH_DEPTH is not
 * kept: the searches then see x's boxes, as before, and the exact
 * bookkeeping settles it.
 */
#define PATH_DEPTH 96

#define PATH_HASH 256 /* slots of the set of the path's nodes, > 2 x PATH_DEPTH */

struct path {
	bool kept;
	uint32_t count;
	uint32_t node[PATH_DEPTH];
	float lo[PATH_DEPTH][3], hi[PATH_DEPTH][3];
	uint32_t key[PATH_HASH]; /* a node, NO_NODE for none */
	uint8_t at[PATH_HASH];   /* its index in node[] */
};

static uint32_t path_slot(uint32_t node)
{
	return (node * 2654435761u) >> 24; /* 8 bits: PATH_HASH */
}

/* Node's index on the path, or NO_NODE. */
static uint32_t path_index(const struct path *path, uint32_t node)
{
	for (uint32_t h = path_slot(node);; h = (h + 1) % PATH_HASH) {
		if (path->key[h] == node)
			return path->at[h];
		if (path->key[h] == NO_NODE)
			return NO_NODE;
	}
}

/* Takes the path's nodes out of the set: a run of slots holding keys is
 * cleared whole from each node's slot on, which takes every key of the
 * run (keys go into the first free slot from their own). */
static void path_forget(struct path *path)
{
	for (uint32_t i = 0; i < path->count; i++)
		for (uint32_t h = path_slot(path->node[i]); path->key[h] != NO_NODE;
		     h = (h + 1) % PATH_HASH)
			path->key[h] = NO_NODE;
}

static void path_remember(struct path *path)
{
	for (uint32_t i = 0; i < path->count; i++) {
		uint32_t h = path_slot(path->node[i]);

		while (path->key[h] != NO_NODE)
			h = (h + 1) % PATH_HASH;
		path->key[h] = path->node[i];
		path->at[h] = (uint8_t)i;
	}
}

/* What taking node x out saves: its parent's area and the shrinking of
 * the parent's ancestors, refitted without it; *path gets those
 * ancestors (in any order) with their boxes so refitted. */
static double removal_path(const reinsert *r, uint32_t x, struct path *path)
{
	uint32_t p = r->parent[x], from = p, depth = 0;
	double gain = node_area(&r->nodes[p]);
	bvhlab_node box = r->nodes[sibling_of(r, x)];
	bool shrinking = true;

	path_forget(path);
	for (uint32_t a = r->parent[p]; a != NO_NODE; from = a, a = r->parent[a], depth++) {
		const bvhlab_node *n = &r->nodes[a];
		const bvhlab_node *other = &r->nodes[n->first == from ? n->first + 1 : n->first];
		double before = node_area(n), after;

		if (shrinking) {
			box_union(&box, other, box.lo, box.hi);
			after = area_of(box.lo, box.hi);
			shrinking = after != before; /* else the boxes above keep theirs */
			gain += before - after;
		}
		if (depth < PATH_DEPTH) {
			const bvhlab_node *b = shrinking ? &box : n;

			path->node[depth] = a;
			memcpy(path->lo[depth], b->lo, sizeof(b->lo));
			memcpy(path->hi[depth], b->hi, sizeof(b->hi));
		}
	}
	path->kept = depth <= PATH_DEPTH;
	path->count = path->kept ? depth : 0;
	path_remember(path);
	return gain;
}

/*
 * The cheapest place beside which to put node c, below *cost (which gets
 * the cost found), in the tree without node x and its parent p; NO_NODE
 * if none. The nodes of `path` are seen with its boxes, p is passed
 * through to its other child.
 */
static uint32_t best_place(const reinsert *r, uint32_t c, uint32_t x, uint32_t p,
                           const struct path *path, double *cost, struct queue *q)
{
	const bvhlab_node *n = &r->nodes[c];
	uint32_t best = NO_NODE, visits = 0;
	double least = *cost, own = node_area(n);

	q->size = 0;
	push(q, 0, 0);
	while (q->size && visits++ < r->max_visits) {
		struct entry e = pop(q);
		const bvhlab_node *at = &r->nodes[e.node];
		bvhlab_node shrunk;
		float lo[3], hi[3];
		double direct, grown;
		uint32_t on;

		if (e.induced + own >= least)
			break; /* the rest of the queue costs at least as much */
		if (e.node == x)
			continue;
		if (path->kept && e.node == p) {
			push(q, e.induced, at->first == x ? at->first + 1 : at->first);
			continue;
		}
		if (path->kept && (on = path_index(path, e.node)) != NO_NODE) {
			shrunk = *at;
			memcpy(shrunk.lo, path->lo[on], sizeof(shrunk.lo));
			memcpy(shrunk.hi, path->hi[on], sizeof(shrunk.hi));
			at = &shrunk;
		}
		box_union(n, at, lo, hi);
		direct = area_of(lo, hi);
		if (e.induced + direct < least && e.node != p) {
			least = e.induced + direct;
			best = e.node;
		}
		grown = e.induced + direct - node_area(at);
		if (at->count == 0 && grown + own < least) {
			/* Fetched while the queue works, not when they are popped
			 * (a pair from slot 1 on straddles two cache lines). */
			__builtin_prefetch(&r->nodes[at->first]);
			__builtin_prefetch(&r->nodes[at->first + 1]);
			push(q, grown, at->first);
			push(q, grown, at->first + 1);
		}
	}
	*cost = least;
	return best;
}

/* Node x (an inner node) out with its parent, its children put back
 * apart, the larger first (Bittner et al. 2013): the move that can
 * rebuild x's top where moving x whole keeps it. Both children's places
 * are searched in the tree without x and its parent (`path`), each on its
 * own: where both go under the same node, its growth is counted twice,
 * which only underrates the move. */
static struct move children_move(const reinsert *r, uint32_t x, double gain,
                                 const struct path *path, struct queue *q)
{
	const bvhlab_node *n = &r->nodes[x];
	uint32_t p = r->parent[x], a = n->first, b = n->first + 1;
	double saved = gain + node_area(n), cost_a = saved, cost_b;
	struct move m = { x, NO_NODE, NO_NODE, 0 };

	if (node_area(&r->nodes[b]) > node_area(&r->nodes[a])) {
		a = b;
		b = n->first;
	}
	m.dest = best_place(r, a, x, p, path, &cost_a, q);
	if (m.dest == NO_NODE)
		return m;
	cost_b = saved - cost_a;
	m.dest2 = best_place(r, b, x, p, path, &cost_b, q);
	if (m.dest2 != NO_NODE)
		m.gain = saved - cost_a - cost_b;
	return m;
}

/*
 * One sibling subtree's part of best_path_place: the places below node s,
 * best first by the growth of their ancestors inside it, each gaining
 * `budget` less that growth and SA(N u X); the best gain above *gain goes
 * there with its place in *best. `no` is no place (x's sibling: the move
 * that changes nothing).
 */
static void search_below(const reinsert *r, const bvhlab_node *n, uint32_t s, double budget,
                         uint32_t no, double *gain, uint32_t *best, uint32_t *visits,
                         struct queue *q)
{
	double own = node_area(n);

	q->size = 0;
	push(q, 0, s);
	while (q->size && (*visits)++ < r->max_visits) {
		struct entry e = pop(q);
		const bvhlab_node *at = &r->nodes[e.node];
		float lo[3], hi[3];
		double direct, grown;

		if (budget - e.induced - own <= *gain)
			break; /* no place left in the queue gains more */
		box_union(n, at, lo, hi);
		direct = area_of(lo, hi);
		if (budget - e.induced - direct > *gain && e.node != no) {
			*gain = budget - e.induced - direct;
			*best = e.node;
		}
		grown = e.induced + direct - node_area(at);
		if (at->count == 0 && budget - grown - own > *gain) {
			__builtin_prefetch(&r->nodes[at->first]);
			__builtin_prefetch(&r->nodes[at->first + 1]);
			push(q, grown, at->first);
			push(q, grown, at->first + 1);
		}
	}
}

/*
 * Node x's subtree move with exact gains (the walk of madmann91/bvh's
 * reinsertion optimiser): a place inside the sibling subtree of x's
 * ancestor A_k (A_1 its parent P) leaves A_{k+1} and everything above as
 * it is, since x stays inside them; it gains P's area and the shrinking of
 * A_2 .. A_k. The subtrees off x's path are searched level by level from
 * the bottom, each with that level's budget. Returns the place or NO_NODE,
 * its predicted gain in *gain (0 when none).
 */
static uint32_t best_path_place(const reinsert *r, uint32_t x, double *gain, struct queue *q)
{
	const bvhlab_node *n = &r->nodes[x];
	uint32_t a = r->parent[x], s = sibling_of(r, x), best = NO_NODE, visits = 0;
	double budget = node_area(&r->nodes[a]);
	bvhlab_node pivot = r->nodes[s];

	*gain = 0;
	search_below(r, n, s, budget, s, gain, &best, &visits, q);
	for (uint32_t up = r->parent[a]; up != NO_NODE; a = up, up = r->parent[up]) {
		s = sibling_of(r, a);
		search_below(r, n, s, budget, NO_NODE, gain, &best, &visits, q);
		box_union(&pivot, &r->nodes[s], pivot.lo, pivot.hi);
		budget += node_area(&r->nodes[up]) - area_of(pivot.lo, pivot.hi);
	}
	return best;
}

void reinsert_search(reinsert *r)
{
	struct queue q;
	struct path path = { .count = 0 };
	uint32_t lo, hi;

	memset(path.key, 0xff, sizeof(path.key));
	while (team_next_block(&r->next, r->cand_count, 64, &lo, &hi))
		for (uint32_t k = lo; k < hi; k++) {
			uint32_t x = r->cand[k];
			double moved;
			uint32_t dest = best_path_place(r, x, &moved, &q);
			struct move m = { x, dest, NO_NODE, moved };

			if (r->children && r->nodes[x].count == 0) {
				double gain = removal_path(r, x, &path);
				struct move c = children_move(r, x, gain, &path, &q);
				m = c.dest2 != NO_NODE && c.gain > m.gain ? c : m;
			}
			r->moves[k] = m;
		}
}
