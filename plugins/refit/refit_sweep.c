/*
 * refit's sweep of one span (refit.h): every node once, children before
 * their parents, in chunks of REFIT_CHUNK nodes from the span's end. Per
 * chunk, three passes, none with a branch on the kind of node:
 *   1. split: the chunk's nodes listed by kind, leaves and inner nodes,
 *      by branch-free stores, as the nodes stream in;
 *   2. the leaves, from the last: one of one or two references (98 % of
 *      lbvh's leaves on igea) is the union of its first and last
 *      reference's boxes, read in place, the boxes BOX_AHEAD references
 *      further fetched meanwhile: the one read that does not stream (the
 *      boxes are in file order, the leaves in the tree's);
 *   3. the inner nodes, from the last: their children, after them, are
 *      done.
 * One pass branching on the kind flushed the pipeline every other node
 * (the kind is a coin toss), one computing both unions and keeping one
 * ran twice the instructions: about 8.5 ms a thread on igea subdivided
 * once against 6.5 for the three passes (docs/animation.md).
 *
 * The leaves' references must follow their nodes: each leaf's end where
 * the next leaf's in the array begin. A span whose do not, or whose inner
 * node has a child before it or outside the span, is not in the streamed
 * layout; such a node reads a safe place instead (the span's last pair),
 * and the span's result is thrown away. Either way the sweep never reads
 * or writes a node outside its span.
 */
#include <math.h>
#include <string.h>

#include <bvhlab/aabb.h>

#include "refit.h"

/* What a sweep met: a child outside the span or before its parent, or
 * references out of node order; a reference past the primitives. */
#define BAD_LAYOUT 1u
#define BAD_PRIM 2u

#if defined(__SSE2__) && !defined(REFIT_NO_SIMD)
#include <emmintrin.h>

typedef __m128 v4;

static inline v4 load4(const float *p)
{
	return _mm_loadu_ps(p);
}

static inline void store4(float *p, v4 v)
{
	_mm_storeu_ps(p, v);
}

/* Lanewise bvhlab_minf(a, b) and bvhlab_maxf(a, b): b when equal. */
static inline v4 min4(v4 a, v4 b)
{
	return _mm_min_ps(a, b);
}

static inline v4 max4(v4 a, v4 b)
{
	return _mm_max_ps(a, b);
}

/* Lanes 0-2 of v, lane 3 (a node's first or count) of keep. */
static inline v4 keep_fourth(v4 v, v4 keep)
{
	__m128 t = _mm_shuffle_ps(v, keep, _MM_SHUFFLE(3, 3, 2, 2));
	return _mm_shuffle_ps(v, t, _MM_SHUFFLE(2, 0, 1, 0));
}

/* Lanes 1-3 of v moved down to 0-2. */
static inline v4 down4(v4 v)
{
	return _mm_shuffle_ps(v, v, _MM_SHUFFLE(3, 3, 2, 1));
}

#else /* the same operations, a float at a time */

typedef struct {
	float f[4];
} v4;

static inline v4 load4(const float *p)
{
	v4 v;
	memcpy(v.f, p, sizeof(v.f));
	return v;
}

static inline void store4(float *p, v4 v)
{
	memcpy(p, v.f, sizeof(v.f));
}

static inline v4 min4(v4 a, v4 b)
{
	for (int k = 0; k < 4; k++)
		a.f[k] = bvhlab_minf(a.f[k], b.f[k]);
	return a;
}

static inline v4 max4(v4 a, v4 b)
{
	for (int k = 0; k < 4; k++)
		a.f[k] = bvhlab_maxf(a.f[k], b.f[k]);
	return a;
}

static inline v4 keep_fourth(v4 v, v4 keep)
{
	v.f[3] = keep.f[3];
	return v;
}

static inline v4 down4(v4 v)
{
	v4 d = {{v.f[1], v.f[2], v.f[3], v.f[3]}};
	return d;
}

#endif

/* a when which is 1, b when it is 0, by masks: the compiler keeps them
 * (a ?: on a node's kind became a branch on it). */
static inline uint32_t pick(uint32_t which, uint32_t a, uint32_t b)
{
	return (a & -which) | (b & (which - 1u));
}

/* Primitive p's box as 6 floats, lo then hi. */
static inline const float *box_floats(const refit *r, uint32_t p)
{
	return (const float *)(const void *)&r->boxes[p];
}

/* How many references ahead of a leaf its primitives' boxes are fetched
 * (the leaves' references run backwards with the sweep). */
#define BOX_AHEAD 256

/* A leaf of any size, its boxes read in place; operands in the order of a
 * box grown from empty (the box first), for the same bits. */
bool refit_leaf(const refit *r, bvhlab_node *n)
{
	v4 lo = load4((const float[4]){INFINITY, INFINITY, INFINITY, INFINITY});
	v4 hi = load4((const float[4]){-INFINITY, -INFINITY, -INFINITY, -INFINITY});
	if (n->first > r->index_count || n->count > r->index_count - n->first)
		return false;
	for (uint32_t k = n->first; k < n->first + n->count; k++) {
		if (r->prim_index[k] >= r->prim_count)
			return false;
		const float *b = box_floats(r, r->prim_index[k]);
		lo = min4(load4(b), lo);
		hi = max4(down4(load4(b + 2)), hi);
	}
	store4(n->lo, keep_fourth(lo, load4(n->lo)));
	store4(n->hi, keep_fourth(hi, load4(n->hi)));
	return true;
}

/* n's box the union of the pair c[0], c[1], first child first; n's first
 * and count kept. */
static inline void union_pair(bvhlab_node *n, const bvhlab_node *c)
{
	store4(n->lo, keep_fourth(min4(load4(c[0].lo), load4(c[1].lo)), load4(n->lo)));
	store4(n->hi, keep_fourth(max4(load4(c[0].hi), load4(c[1].hi)), load4(n->hi)));
}

/* An inner node's box from its two (refitted) children. */
void refit_inner(const refit *r, bvhlab_node *n)
{
	union_pair(n, &r->nodes[n->first]);
}

/* Nodes [a, b) of a span sorted by kind, from the end: the leaves to the
 * front of idx, the inner nodes to its back, each where a branch-free
 * store puts it (the other store lands in a free slot, or in this one).
 * Returns the leaf count. */
static uint32_t split(const refit *r, uint32_t a, uint32_t b, uint32_t *idx)
{
	uint32_t leaves = 0, inner = b - a;
	for (uint32_t i = b; i-- > a;) {
		uint32_t leaf = r->nodes[i].count != 0;
		idx[leaves] = i;
		idx[inner - 1] = i;
		leaves += leaf;
		inner -= leaf ^ 1u;
	}
	return leaves;
}

/* A leaf of three references or more, or one out of turn (the cursor,
 * never past index_count, then stays where it was). */
static unsigned slow_leaf(const refit *r, bvhlab_node *n, uint32_t *cursor)
{
	if ((uint64_t)n->first + n->count != *cursor)
		return BAD_LAYOUT;
	*cursor = n->first;
	return refit_leaf(r, n) ? 0 : BAD_PRIM;
}

/* The leaves' turn, in the order of the array from its end: each leaf's
 * references must end where the previous one's began (*cursor); a leaf of
 * three or more, or one out of turn, takes the slow way. The boxes of one
 * or two references come from their first and last: the second first, as
 * a box grown from empty has it. */
static unsigned leaves(const refit *r, const uint32_t *idx, uint32_t count, uint32_t *end)
{
	const uint32_t *prim_index = r->prim_index, prims = r->prim_count;
	uint32_t cursor = *end;
	unsigned bad = 0;
	for (uint32_t j = 0; j < count; j++) {
		bvhlab_node *n = &r->nodes[idx[j]];
		uint32_t first = n->first, size = n->count, ahead = first > BOX_AHEAD ? first - BOX_AHEAD : 0;
		uint32_t p = prim_index[ahead < cursor ? ahead : 0];
		uint32_t q = prim_index[ahead + 1 < cursor ? ahead + 1 : 0];
		__builtin_prefetch(box_floats(r, p < prims ? p : 0));
		__builtin_prefetch(box_floats(r, q < prims ? q : 0));
		if (size > 2 || (uint64_t)first + size != cursor) {
			bad |= slow_leaf(r, n, &cursor);
			continue;
		}
		cursor = first;
		uint32_t p0 = prim_index[first], p1 = prim_index[first + size - 1];
		bad |= ((p0 >= prims) | (p1 >= prims)) * BAD_PRIM;
		const float *a = box_floats(r, pick(p1 < prims, p1, 0));
		const float *b = box_floats(r, pick(p0 < prims, p0, 0));
		store4(n->lo, keep_fourth(min4(load4(a), load4(b)), load4(n->lo)));
		store4(n->hi, keep_fourth(max4(down4(load4(a + 2)), down4(load4(b + 2))), load4(n->hi)));
	}
	*end = cursor;
	return bad;
}

/* The inner nodes' turn, from the last: their children, after them in
 * the span, are done (leaves first, then inner nodes with larger
 * indices). A child out of place reads the span's last pair instead. */
static unsigned inner(const refit *r, const uint32_t *idx, uint32_t from, uint32_t to,
                      struct span s)
{
	unsigned bad = 0;
	for (uint32_t j = to; j-- > from;) {
		uint32_t i = idx[j];
		bvhlab_node *n = &r->nodes[i];
		uint32_t first = n->first, ok = (first > i) & (first <= s.hi - 2);
		bad |= ok ^ 1u;
		union_pair(n, &r->nodes[pick(ok, first, s.hi - 2)]);
	}
	return bad;
}

enum refit_fault refit_sweep(const refit *r, struct span s, struct refit_scratch *w)
{
	/* A span ends with a pair of leaves (the last pair handed out below
	 * its root): the last one's references end the span's. */
	const bvhlab_node *last = &r->nodes[s.hi - 1];
	if (!last->count || (uint64_t)last->first + last->count > r->index_count)
		return FAULT_LAYOUT;
	uint32_t cursor = last->first + last->count;
	unsigned bad = 0;
	for (uint32_t b = s.hi; b > s.lo;) {
		uint32_t a = b - s.lo > REFIT_CHUNK ? b - REFIT_CHUNK : s.lo;
		uint32_t count = split(r, a, b, w->idx);
		bad |= leaves(r, w->idx, count, &cursor);
		bad |= inner(r, w->idx, count, b - a, s);
		b = a;
	}
	return bad & BAD_LAYOUT ? FAULT_LAYOUT : bad ? FAULT_PRIM : FAULT_NONE;
}
