/*
 * The callbacks Embree builds its tree through, the exact triangle split
 * behind quality "high", and the conversion into the standard layout.
 *
 * Boxes: a leaf's box is the union of the boxes Embree hands create_leaf,
 * which for "high" hold only the clipped part of each triangle (the
 * validator checks such trees by coverage, since the plugin declares
 * spatial splits); inner boxes are the union of their children's.
 */
#include <errno.h>
#include <math.h>
#include <stdlib.h>
#include <string.h>

#include <bvhlab/aabb.h>

#include "embree_internal.h"
#include "tri_clip.h"

/* ---- callbacks (run on Embree's worker threads) --------------------------- */

static void *create_node(RTCThreadLocalAllocator alloc, unsigned int children, void *user)
{
	(void)user;
	tinner *n = rtcThreadLocalAlloc(alloc, sizeof(tinner), 16);
	n->head.count = 0;
	n->head.arity = children < BVHLAB_MAX_WIDTH ? children : BVHLAB_MAX_WIDTH;
	memset(n->child, 0, sizeof(n->child));
	return n;
}

static void set_children(void *node, void **children, unsigned int count, void *user)
{
	(void)user;
	tinner *n = node;
	for (unsigned int k = 0; k < count && k < BVHLAB_MAX_WIDTH; k++)
		n->child[k] = children[k];
}

/* Output boxes come from the primitives (see the top of this file). */
static void set_bounds(void *node, const struct RTCBounds **bounds, unsigned int count,
                       void *user)
{
	(void)node, (void)bounds, (void)count, (void)user;
}

static void *create_leaf(RTCThreadLocalAllocator alloc, const struct RTCBuildPrimitive *prims,
                         size_t count, void *user)
{
	(void)user;
	tleaf *l = rtcThreadLocalAlloc(alloc, sizeof(tleaf) + count * sizeof(uint32_t), 16);
	l->head.count = (uint32_t)count;
	l->head.arity = 0;
	bvhlab_box_empty(l->lo, l->hi);
	for (size_t k = 0; k < count; k++) {
		const struct RTCBuildPrimitive *p = &prims[k];
		l->prim[k] = p->primID;
		l->lo[0] = p->lower_x < l->lo[0] ? p->lower_x : l->lo[0];
		l->lo[1] = p->lower_y < l->lo[1] ? p->lower_y : l->lo[1];
		l->lo[2] = p->lower_z < l->lo[2] ? p->lower_z : l->lo[2];
		l->hi[0] = p->upper_x > l->hi[0] ? p->upper_x : l->hi[0];
		l->hi[1] = p->upper_y > l->hi[1] ? p->upper_y : l->hi[1];
		l->hi[2] = p->upper_z > l->hi[2] ? p->upper_z : l->hi[2];
	}
	return l;
}

/*
 * Splits a reference at the plane x[dim] = pos: each side gets the box of
 * the part of the triangle that lies in the reference's box and on that
 * side (tri_clip.c), so a box never holds space its triangle does not
 * reach. Embree's own triangle splitter instead cuts the whole triangle
 * and intersects the halves' boxes with the reference's box, which can
 * leave a side a box that misses the triangle altogether.
 */
static void split_prim(const struct RTCBuildPrimitive *prim, unsigned int dim, float pos,
                       struct RTCBounds *left, struct RTCBounds *right, void *user)
{
	const embree_job *job = user;
	const bvhlab_aabb box = {{prim->lower_x, prim->lower_y, prim->lower_z},
	                         {prim->upper_x, prim->upper_y, prim->upper_z}};
	bvhlab_aabb l, r;
	tri_clip_split(job->input->vertices, &job->input->indices[3 * (size_t)prim->primID], &box,
	               (int)dim, pos, &l, &r);
	*left = (struct RTCBounds){l.lo[0], l.lo[1], l.lo[2], 0, l.hi[0], l.hi[1], l.hi[2], 0};
	*right = (struct RTCBounds){r.lo[0], r.lo[1], r.lo[2], 0, r.hi[0], r.hi[1], r.hi[2], 0};
}

void embree_set_callbacks(struct RTCBuildArguments *args, bool spatial)
{
	args->createNode = create_node;
	args->setNodeChildren = set_children;
	args->setNodeBounds = set_bounds;
	args->createLeaf = create_leaf;
	args->splitPrimitive = spatial ? split_prim : NULL;
}

/* ---- conversion (one thread, after the build) ----------------------------- */

typedef struct pending {
	const tnode *t;
	uint32_t slot; /* output node index */
} pending;

typedef struct writer {
	const bvhlab_host *host;
	bvhlab_build_ctx *ctx;
	bvhlab_build_output *out;
	pending *stack;
	uint32_t sp, cap;
} writer;

/* Doubling, so spatial-split trees grow the output O(log) times. */
static int ensure(writer *w, uint32_t nodes, uint32_t indices)
{
	bvhlab_build_output *o = w->out;
	if (nodes <= o->node_capacity && indices <= o->index_capacity)
		return 0;
	uint64_t n = nodes > o->node_capacity ? 2 * (uint64_t)nodes : o->node_capacity;
	uint64_t i = indices > o->index_capacity ? 2 * (uint64_t)indices : o->index_capacity;
	if (n > UINT32_MAX || i > UINT32_MAX || w->host->grow_output(w->ctx, o, (uint32_t)n,
	                                                             (uint32_t)i) < 0) {
		w->host->set_error(w->ctx, "cannot grow the output to %llu nodes, %llu references",
		                   (unsigned long long)n, (unsigned long long)i);
		return -ENOMEM;
	}
	return 0;
}

static int push(writer *w, const tnode *t, uint32_t slot)
{
	if (w->sp == w->cap) {
		uint32_t cap = w->cap ? 2 * w->cap : 128;
		pending *s = realloc(w->stack, cap * sizeof(*s));
		if (!s) {
			w->host->set_error(w->ctx, "out of memory converting the tree");
			return -ENOMEM;
		}
		w->stack = s;
		w->cap = cap;
	}
	w->stack[w->sp++] = (pending){t, slot};
	return 0;
}

static int write_leaf(writer *w, const tleaf *l, uint32_t slot)
{
	bvhlab_build_output *o = w->out;
	int rc = ensure(w, o->node_count, o->index_count + l->head.count);
	if (rc < 0)
		return rc;
	memcpy(o->nodes[slot].lo, l->lo, sizeof(l->lo));
	memcpy(o->nodes[slot].hi, l->hi, sizeof(l->hi));
	o->nodes[slot].first = o->index_count;
	o->nodes[slot].count = l->head.count;
	memcpy(&o->prim_index[o->index_count], l->prim, l->head.count * sizeof(uint32_t));
	o->index_count += l->head.count;
	return 0;
}

static int write_inner(writer *w, const tinner *n, uint32_t slot)
{
	bvhlab_build_output *o = w->out;
	uint32_t first = o->node_count, k = n->head.arity;
	int rc = ensure(w, first + k, o->index_count);
	if (rc == 0) {
		o->nodes[slot].first = first;
		o->nodes[slot].count = k == 2 ? 0 : BVHLAB_NODE_INNER | k;
		o->node_count += k;
	}
	for (uint32_t c = k; rc == 0 && c-- > 0;)
		rc = push(w, n->child[c], first + c);
	return rc;
}

/* Depth first, children as adjacent pairs: each child's index exceeds its parent's. */
static int write_nodes(writer *w, const tnode *root)
{
	int rc = push(w, root, 0);
	w->out->node_count = 1;
	w->out->index_count = 0;
	while (rc == 0 && w->sp > 0) {
		pending p = w->stack[--w->sp];
		const tnode *t = p.t;
		while (t && t->count == 0 && t->arity == 1)
			t = ((const tinner *)t)->child[0];
		if (!t || (t->count == 0 && (t->arity < 2 || t->arity > BVHLAB_MAX_WIDTH))) {
			w->host->set_error(w->ctx, "Embree produced a malformed node");
			return -EPROTO;
		}
		rc = t->count ? write_leaf(w, (const tleaf *)t, p.slot)
		              : write_inner(w, (const tinner *)t, p.slot);
	}
	return rc;
}

/* Inner boxes bottom-up (leaf boxes are written with the leaves); a
 * reverse scan, since children follow their parents. */
static void compute_boxes(bvhlab_build_output *o)
{
	for (uint32_t i = o->node_count; i-- > 0;) {
		bvhlab_node *n = &o->nodes[i];
		bvhlab_aabb box;
		if (n->count != 0 && !(n->count & BVHLAB_NODE_INNER))
			continue;
		uint32_t k = n->count ? n->count & ~BVHLAB_NODE_INNER : 2;
		bvhlab_aabb_empty(&box);
		for (uint32_t c = 0; c < k; c++)
			bvhlab_aabb_grow_corners(&box, o->nodes[n->first + c].lo, o->nodes[n->first + c].hi);
		memcpy(n->lo, box.lo, sizeof(n->lo));
		memcpy(n->hi, box.hi, sizeof(n->hi));
	}
}

int embree_write_tree(const bvhlab_host *host, bvhlab_build_ctx *ctx, const tnode *root,
                      bvhlab_build_output *out)
{
	writer w = {.host = host, .ctx = ctx, .out = out};
	int rc = write_nodes(&w, root);
	free(w.stack);
	if (rc == 0)
		compute_boxes(out);
	return rc;
}
