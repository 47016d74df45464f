/*
 * bvhlab — canonical comparison of two trees, whatever order their nodes
 * and children were written in: same shape, bit-identical boxes, the same
 * primitive multiset in each leaf. The SAH plugins differ only in scheduling,
 * so with the same options their trees must compare equal here.
 *
 * Every subtree gets a 64-bit hash, bottom-up, symmetric in the order of
 * its children and in the order of a leaf's primitives. The two roots are then walked in
 * parallel: at each inner node the children are paired by hash (a child
 * whose hash has an equal on the other side is the same subtree, so its
 * sibling holds the difference), else by a total order on (box bits,
 * subtree size, smallest primitive). Hashes only steer the walk; equality is
 * decided by comparing everything, so a collision cannot hide a difference.
 * Paths in messages name tree a's children: in a binary node L is the first
 * child, R the second; in a wider one, 0 to 7 by position.
 *
 * A malformed tree (child or leaf range out of bounds, a node reached twice)
 * is -EINVAL with the reason: the walk must not loop or read out of bounds.
 */
#include <errno.h>
#include <inttypes.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include <bvhlab/tree.h>

#include "tree/tree_view.h"

#define PATH_SHOWN 150 /* levels spelled out in a message */

typedef struct canon {
	const bvhlab_tree *tree;
	char name;         /* 'a' or 'b', for messages */
	uint32_t reached;  /* nodes in order[] */
	uint32_t *order;   /* breadth-first: parents before children */
	uint64_t *hash;
	uint32_t *size;    /* nodes in the subtree; 0 while unreached */
	uint32_t *minprim; /* smallest primitive id in the subtree */
	uint32_t max_leaf;
} canon;

typedef struct pair {
	uint32_t a, b, depth;
	char side;
} pair;

typedef struct walk {
	const canon *ca, *cb;
	pair *stack;
	uint32_t sp;
	char *path; /* path[d]: side taken at depth d (1-based) */
	uint32_t *sort_a, *sort_b;
	bvhlab_error *err;
} walk;

static uint64_t mix64(uint64_t z)
{
	z = (z ^ (z >> 30)) * 0xbf58476d1ce4e5b9u;
	z = (z ^ (z >> 27)) * 0x94d049bb133111ebu;
	return z ^ (z >> 31);
}

static uint64_t box_hash(const bvhlab_node *n, uint64_t tag)
{
	uint32_t bits[6];
	uint64_t h = mix64(tag);
	int k;

	memcpy(bits, n->lo, sizeof(n->lo));
	memcpy(bits + 3, n->hi, sizeof(n->hi));
	for (k = 0; k < 6; k++)
		h = mix64(h ^ bits[k]);
	return h;
}

static int fail(bvhlab_error *err, int rc, const char *what, char name, uint32_t node)
{
	snprintf(err->message, sizeof(err->message), "tree %c: node %" PRIu32 ": %s", name,
	         node, what);
	return rc;
}

/* Queues the children of an inner node, refusing a node seen before. */
static int enqueue_children(canon *c, uint32_t node, bvhlab_error *err)
{
	const bvhlab_node *n = &c->tree->nodes[node];
	uint32_t count = tree_child_count(n);

	if (tree_children_end(n) > c->tree->node_count || count > BVHLAB_MAX_WIDTH)
		return fail(err, -EINVAL, "child index out of range", c->name, node);
	for (uint32_t i = 0; i < count; i++) {
		uint32_t k = tree_child(n, i);

		if (c->size[k]) {
			snprintf(err->message, sizeof(err->message), "tree %c: node %" PRIu32
			         ": child %" PRIu32 " reached twice (cycle or shared child)",
			         c->name, node, k);
			return -EINVAL;
		}
		c->size[k] = 1;
		c->order[c->reached++] = k;
	}
	return 0;
}

/* Breadth-first order of the reachable nodes, checking what the walk and
 * the hashing will rely on. */
static int canon_order(canon *c, bvhlab_error *err)
{
	const bvhlab_tree *t = c->tree;
	uint32_t head;
	int rc = 0;

	c->order[0] = 0;
	c->size[0] = 1;
	c->reached = 1;
	for (head = 0; rc == 0 && head < c->reached; head++) {
		uint32_t node = c->order[head];
		const bvhlab_node *n = &t->nodes[node];

		if (!tree_is_leaf(n)) {
			rc = enqueue_children(c, node, err);
		} else if ((uint64_t)tree_leaf_first(n) + tree_leaf_count(n) > t->index_count) {
			rc = fail(err, -EINVAL, "leaf range past index_count", c->name, node);
		} else if (tree_leaf_count(n) > c->max_leaf) {
			c->max_leaf = tree_leaf_count(n);
		}
	}
	return rc;
}

static void hash_leaf(canon *c, uint32_t node)
{
	const bvhlab_node *n = &c->tree->nodes[node];
	uint64_t sum = 0;
	uint32_t i, least = UINT32_MAX;

	uint32_t first = tree_leaf_first(n), count = tree_leaf_count(n);

	for (i = first; i < first + count; i++) {
		uint32_t p = c->tree->prim_index[i];

		sum += mix64(p + 0x632be59bd9b4e019u); /* a sum ignores the order */
		least = p < least ? p : least;
	}
	c->hash[node] = mix64(box_hash(n, 1) ^ mix64(sum + count));
	c->size[node] = 1;
	c->minprim[node] = least;
}

/* Symmetric in the order of the children: their hashes are sorted first
 * (for two, the smaller one is folded in first, as it always was). */
static void hash_inner(canon *c, uint32_t node)
{
	const bvhlab_node *n = &c->tree->nodes[node];
	uint32_t count = tree_child_count(n), size = 1, least = UINT32_MAX;
	uint64_t hs[BVHLAB_MAX_WIDTH];

	for (uint32_t i = 0; i < count; i++) {
		uint32_t k = tree_child(n, i), j = i;

		for (; j > 0 && hs[j - 1] > c->hash[k]; j--)
			hs[j] = hs[j - 1];
		hs[j] = c->hash[k];
		size += c->size[k];
		least = c->minprim[k] < least ? c->minprim[k] : least;
	}
	uint64_t h = mix64(box_hash(n, 2) ^ hs[0]);
	for (uint32_t i = 1; i < count; i++)
		h = mix64(h + hs[i]);
	c->hash[node] = h;
	c->size[node] = size;
	c->minprim[node] = least;
}

static int canon_build(canon *c, const bvhlab_tree *tree, char name, bvhlab_error *err)
{
	size_t n = tree->node_count;
	uint32_t i;
	int rc;

	c->tree = tree;
	c->name = name;
	c->order = malloc(n * sizeof(uint32_t));
	c->hash = malloc(n * sizeof(uint64_t));
	c->size = calloc(n, sizeof(uint32_t));
	c->minprim = malloc(n * sizeof(uint32_t));
	if (!c->order || !c->hash || !c->size || !c->minprim) {
		snprintf(err->message, sizeof(err->message), "out of memory comparing trees");
		return -ENOMEM;
	}
	rc = canon_order(c, err);
	if (rc < 0)
		return rc;
	for (i = c->reached; i-- > 0;) { /* children before parents */
		if (tree_is_leaf(&tree->nodes[c->order[i]]))
			hash_leaf(c, c->order[i]);
		else
			hash_inner(c, c->order[i]);
	}
	return 0;
}

static void canon_free(canon *c)
{
	free(c->order);
	free(c->hash);
	free(c->size);
	free(c->minprim);
}

static int differ(walk *w, const char *what, uint32_t depth, const char *detail)
{
	int len = snprintf(w->err->message, sizeof(w->err->message), "%s at root", what);
	uint32_t d, shown = depth < PATH_SHOWN ? depth : PATH_SHOWN;

	for (d = 1; d <= shown && len > 0 && (size_t)len + 3 < sizeof(w->err->message); d++)
		len += snprintf(w->err->message + len, sizeof(w->err->message) - len, ".%c",
		                w->path[d]);
	if (depth > shown && len > 0 && (size_t)len < sizeof(w->err->message))
		len += snprintf(w->err->message + len, sizeof(w->err->message) - len,
		                "... (depth %" PRIu32 ")", depth);
	if (detail[0] && len > 0 && (size_t)len < sizeof(w->err->message))
		snprintf(w->err->message + len, sizeof(w->err->message) - len, " (%s)", detail);
	return 1;
}

/* Total order on subtrees: box bits, then subtree size, then smallest primitive. */
static int key_cmp(const canon *c, uint32_t x, uint32_t y)
{
	const bvhlab_node *nx = &c->tree->nodes[x], *ny = &c->tree->nodes[y];
	int r = memcmp(nx->lo, ny->lo, sizeof(nx->lo));

	if (r == 0)
		r = memcmp(nx->hi, ny->hi, sizeof(nx->hi));
	if (r == 0 && c->size[x] != c->size[y])
		r = c->size[x] < c->size[y] ? -1 : 1;
	if (r == 0 && c->minprim[x] != c->minprim[y])
		r = c->minprim[x] < c->minprim[y] ? -1 : 1;
	return r;
}

static void sort_prims(uint32_t *v, uint32_t n)
{
	uint32_t i, j;

	for (i = 1; i < n; i++) {
		uint32_t x = v[i];

		for (j = i; j > 0 && v[j - 1] > x; j--)
			v[j] = v[j - 1];
		v[j] = x;
	}
}

static int cmp_u32(const void *x, const void *y)
{
	uint32_t a = *(const uint32_t *)x, b = *(const uint32_t *)y;

	return a < b ? -1 : a > b;
}

static int compare_leaves(walk *w, const pair *p)
{
	const bvhlab_tree *ta = w->ca->tree, *tb = w->cb->tree;
	const bvhlab_node *na = &ta->nodes[p->a], *nb = &tb->nodes[p->b];
	uint32_t count = tree_leaf_count(na), i;
	char detail[128];

	if (count != tree_leaf_count(nb)) {
		snprintf(detail, sizeof(detail), "%" PRIu32 " vs %" PRIu32 " primitives",
		         count, tree_leaf_count(nb));
		return differ(w, "leaf primitive sets differ", p->depth, detail);
	}
	memcpy(w->sort_a, ta->prim_index + tree_leaf_first(na), count * sizeof(uint32_t));
	memcpy(w->sort_b, tb->prim_index + tree_leaf_first(nb), count * sizeof(uint32_t));
	if (count <= 32) {
		sort_prims(w->sort_a, count);
		sort_prims(w->sort_b, count);
	} else {
		qsort(w->sort_a, count, sizeof(uint32_t), cmp_u32);
		qsort(w->sort_b, count, sizeof(uint32_t), cmp_u32);
	}
	for (i = 0; i < count; i++) {
		if (w->sort_a[i] != w->sort_b[i]) {
			snprintf(detail, sizeof(detail), "primitive %" PRIu32 " vs %" PRIu32,
			         w->sort_a[i], w->sort_b[i]);
			return differ(w, "leaf primitive sets differ", p->depth, detail);
		}
	}
	return 0;
}

/* Pairs the children of two inner nodes and pushes them, the pair whose
 * hashes differ last, so it is examined first. */
static void push_children(walk *w, const pair *p)
{
	const canon *ca = w->ca, *cb = w->cb;
	const bvhlab_node *na = &ca->tree->nodes[p->a], *nb = &cb->tree->nodes[p->b];
	uint32_t a0 = tree_child(na, 0), a1 = tree_child(na, 1);
	uint32_t b0 = tree_child(nb, 0), b1 = tree_child(nb, 1);
	int same = (ca->hash[a0] == cb->hash[b0]) + (ca->hash[a1] == cb->hash[b1]);
	int crossed = (ca->hash[a0] == cb->hash[b1]) + (ca->hash[a1] == cb->hash[b0]);
	bool straight, first_equal;
	pair x, y;

	if (same != crossed)
		straight = same > crossed;
	else if (same > 0)
		straight = true; /* equal siblings: either pairing */
	else
		straight = (key_cmp(ca, a0, a1) > 0) == (key_cmp(cb, b0, b1) > 0);
	x = (pair){ a0, straight ? b0 : b1, p->depth + 1, 'L' };
	y = (pair){ a1, straight ? b1 : b0, p->depth + 1, 'R' };
	first_equal = ca->hash[x.a] == cb->hash[x.b];
	w->stack[w->sp++] = first_equal ? x : y;
	w->stack[w->sp++] = first_equal ? y : x;
}

/* Children in the order key_cmp gives them. */
static uint32_t sorted_children(const canon *c, const bvhlab_node *n, uint32_t *out)
{
	uint32_t count = tree_child_count(n);

	for (uint32_t i = 0; i < count; i++) {
		uint32_t k = tree_child(n, i), j = i;

		for (; j > 0 && key_cmp(c, out[j - 1], k) > 0; j--)
			out[j] = out[j - 1];
		out[j] = k;
	}
	return count;
}

/* A wider node's children: paired by equal hash first, the rest in key
 * order; the pairs with equal hashes are pushed first, examined last. */
static void push_wide(walk *w, const pair *p)
{
	uint32_t a[BVHLAB_MAX_WIDTH], b[BVHLAB_MAX_WIDTH], to[BVHLAB_MAX_WIDTH];
	bool used[BVHLAB_MAX_WIDTH] = { false };
	uint32_t count = sorted_children(w->ca, &w->ca->tree->nodes[p->a], a), i, j;
	uint32_t first = tree_child(&w->ca->tree->nodes[p->a], 0);

	sorted_children(w->cb, &w->cb->tree->nodes[p->b], b);
	for (i = 0; i < count; i++) {
		to[i] = BVHLAB_MAX_WIDTH;
		for (j = 0; j < count && to[i] == BVHLAB_MAX_WIDTH; j++)
			if (!used[j] && w->ca->hash[a[i]] == w->cb->hash[b[j]])
				used[j] = true, to[i] = j;
	}
	for (i = 0, j = 0; i < count; i++) {
		for (; to[i] == BVHLAB_MAX_WIDTH && used[j]; j++)
			;
		if (to[i] == BVHLAB_MAX_WIDTH)
			used[j] = true, to[i] = j;
	}
	for (int equal = 1; equal >= 0; equal--)
		for (i = 0; i < count; i++)
			if ((w->ca->hash[a[i]] == w->cb->hash[b[to[i]]]) == equal)
				w->stack[w->sp++] = (pair){ a[i], b[to[i]], p->depth + 1,
				                            (char)('0' + (a[i] - first)) };
}

static int compare_pair(walk *w, const pair *p)
{
	const bvhlab_node *na = &w->ca->tree->nodes[p->a], *nb = &w->cb->tree->nodes[p->b];
	char detail[256];

	w->path[p->depth] = p->side;
	if (tree_is_leaf(na) != tree_is_leaf(nb))
		return differ(w, !tree_is_leaf(na) ? "inner node vs leaf" : "leaf vs inner node",
		              p->depth, "");
	if (tree_child_count(na) != tree_child_count(nb)) {
		snprintf(detail, sizeof(detail), "%" PRIu32 " vs %" PRIu32 " children",
		         tree_child_count(na), tree_child_count(nb));
		return differ(w, "inner nodes differ", p->depth, detail);
	}
	if (memcmp(na->lo, nb->lo, sizeof(na->lo)) || memcmp(na->hi, nb->hi, sizeof(na->hi))) {
		snprintf(detail, sizeof(detail), "[%.9g %.9g %.9g]-[%.9g %.9g %.9g] vs "
		         "[%.9g %.9g %.9g]-[%.9g %.9g %.9g]", na->lo[0], na->lo[1], na->lo[2],
		         na->hi[0], na->hi[1], na->hi[2], nb->lo[0], nb->lo[1], nb->lo[2],
		         nb->hi[0], nb->hi[1], nb->hi[2]);
		return differ(w, "boxes differ", p->depth, detail);
	}
	if (tree_is_leaf(na))
		return compare_leaves(w, p);
	if (tree_child_count(na) == 2)
		push_children(w, p);
	else
		push_wide(w, p);
	return 0;
}

static int walk_trees(const canon *ca, const canon *cb, bvhlab_error *err)
{
	uint32_t leaf = ca->max_leaf > cb->max_leaf ? ca->max_leaf : cb->max_leaf;
	walk w = { ca, cb, NULL, 0, NULL, NULL, NULL, err };
	int rc = -ENOMEM;

	/* Each pair holds a distinct node of a, and a pop pushes at most a
	 * node's children. */
	w.stack = malloc(((size_t)ca->reached + BVHLAB_MAX_WIDTH) * sizeof(pair));
	w.path = malloc((size_t)ca->reached + 1);
	w.sort_a = malloc(((size_t)leaf + 1) * sizeof(uint32_t));
	w.sort_b = malloc(((size_t)leaf + 1) * sizeof(uint32_t));
	if (!w.stack || !w.path || !w.sort_a || !w.sort_b) {
		snprintf(err->message, sizeof(err->message), "out of memory comparing trees");
		goto out;
	}
	w.stack[w.sp++] = (pair){ 0, 0, 0, '-' };
	rc = 0;
	while (rc == 0 && w.sp > 0) {
		pair p = w.stack[--w.sp];

		rc = compare_pair(&w, &p);
	}
out:
	free(w.stack);
	free(w.path);
	free(w.sort_a);
	free(w.sort_b);
	return rc;
}

int bvhlab_tree_compare(const bvhlab_tree *a, const bvhlab_tree *b, bvhlab_error *err)
{
	canon ca = { 0 }, cb = { 0 };
	bvhlab_error scratch;
	int rc;

	if (!err)
		err = &scratch;
	err->message[0] = '\0';
	if (a->node_count == 0 || b->node_count == 0) {
		if (a->node_count == b->node_count)
			return 0;
		snprintf(err->message, sizeof(err->message), "tree %c is empty",
		         a->node_count == 0 ? 'a' : 'b');
		return 1;
	}
	rc = canon_build(&ca, a, 'a', err);
	if (rc == 0)
		rc = canon_build(&cb, b, 'b', err);
	if (rc == 0)
		rc = walk_trees(&ca, &cb, err);
	canon_free(&ca);
	canon_free(&cb);
	return rc;
}
