/*
 * The callbacks Embree builds its tree through, the exact triangle split
 * behind quality "high", and the conversion into the standard layout.
 *
 * Boxes: Embree's spatial splits give a leaf only the box of the clipped
 * part of each triangle, but the core validator requires a leaf's box to
 * contain its primitives' whole boxes. So the output's boxes are recomputed
 * from input->prim_bounds (leaves) and children (inner nodes): identical to
 * Embree's for "low" and "medium", widened for "high", whose split choices
 * and duplicated references are kept.
 */
#include <errno.h>
#include <math.h>
#include <stdlib.h>
#include <string.h>

#include <bvhlab/aabb.h>

#include "embree_internal.h"

/* ---- callbacks (run on Embree's worker threads) --------------------------- */

static void *create_node(RTCThreadLocalAllocator alloc, unsigned int children, void *user)
{
	(void)user;
	tinner *n = rtcThreadLocalAlloc(alloc, sizeof(tinner), 16);
	n->head.count = 0;
	n->head.arity = children < 2 ? children : 2;
	n->child[0] = n->child[1] = NULL;
	return n;
}

static void set_children(void *node, void **children, unsigned int count, void *user)
{
	(void)user;
	tinner *n = node;
	for (unsigned int k = 0; k < count && k < 2; k++)
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
	for (size_t k = 0; k < count; k++)
		l->prim[k] = prims[k].primID;
	return l;
}

/* Clips to the reference's current box (already clipped by earlier splits). */
static void box_store(bvhlab_aabb *b, const struct RTCBuildPrimitive *p,
                      struct RTCBounds *out)
{
	const float lo[3] = {p->lower_x, p->lower_y, p->lower_z};
	const float hi[3] = {p->upper_x, p->upper_y, p->upper_z};
	for (int k = 0; k < 3; k++) {
		b->lo[k] = bvhlab_maxf(b->lo[k], lo[k]);
		b->hi[k] = bvhlab_minf(b->hi[k], hi[k]);
	}
	*out = (struct RTCBounds){b->lo[0], b->lo[1], b->lo[2], 0, b->hi[0], b->hi[1], b->hi[2], 0};
}

/*
 * Splits the triangle behind a reference at the plane x[dim] = pos: each
 * side's box holds that side's vertices and the points where edges cross
 * the plane (those lie on it exactly: their dim coordinate is pos itself).
 */
static void split_prim(const struct RTCBuildPrimitive *prim, unsigned int dim, float pos,
                       struct RTCBounds *left, struct RTCBounds *right, void *user)
{
	const embree_job *job = user;
	const uint32_t *tri = &job->input->indices[3 * (size_t)prim->primID];
	bvhlab_aabb l, r;
	bvhlab_aabb_empty(&l);
	bvhlab_aabb_empty(&r);
	for (int e = 0; e < 3; e++) {
		const float *a = &job->input->vertices[3 * (size_t)tri[e]];
		const float *b = &job->input->vertices[3 * (size_t)tri[(e + 1) % 3]];
		if (a[dim] <= pos)
			bvhlab_aabb_grow_point(&l, a);
		if (a[dim] >= pos)
			bvhlab_aabb_grow_point(&r, a);
		if ((a[dim] < pos && pos < b[dim]) || (b[dim] < pos && pos < a[dim])) {
			double t = ((double)pos - a[dim]) / ((double)b[dim] - a[dim]);
			float c[3];
			for (int k = 0; k < 3; k++)
				c[k] = (float)(a[k] + t * ((double)b[k] - a[k]));
			c[dim] = pos;
			bvhlab_aabb_grow_point(&l, c);
			bvhlab_aabb_grow_point(&r, c);
		}
	}
	box_store(&l, prim, left);
	box_store(&r, prim, right);
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
	o->nodes[slot].first = o->index_count;
	o->nodes[slot].count = l->head.count;
	memcpy(&o->prim_index[o->index_count], l->prim, l->head.count * sizeof(uint32_t));
	o->index_count += l->head.count;
	return 0;
}

static int write_inner(writer *w, const tinner *n, uint32_t slot)
{
	bvhlab_build_output *o = w->out;
	uint32_t first = o->node_count;
	int rc = ensure(w, first + 2, o->index_count);
	if (rc == 0) {
		o->nodes[slot].first = first;
		o->nodes[slot].count = 0;
		o->node_count += 2;
		rc = push(w, n->child[1], first + 1);
	}
	return rc < 0 ? rc : push(w, n->child[0], first);
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
		if (!t || (t->count == 0 && t->arity != 2)) {
			w->host->set_error(w->ctx, "Embree produced a malformed node");
			return -EPROTO;
		}
		rc = t->count ? write_leaf(w, (const tleaf *)t, p.slot)
		              : write_inner(w, (const tinner *)t, p.slot);
	}
	return rc;
}

/* Bottom-up is a reverse scan, since children follow their parents. */
static void compute_boxes(const bvhlab_build_input *in, bvhlab_build_output *o)
{
	for (uint32_t i = o->node_count; i-- > 0;) {
		bvhlab_node *n = &o->nodes[i];
		bvhlab_aabb box;
		bvhlab_aabb_empty(&box);
		if (n->count == 0) {
			bvhlab_aabb_grow_corners(&box, o->nodes[n->first].lo, o->nodes[n->first].hi);
			bvhlab_aabb_grow_corners(&box, o->nodes[n->first + 1].lo,
			                         o->nodes[n->first + 1].hi);
		}
		for (uint32_t s = n->first; n->count && s < n->first + n->count; s++)
			bvhlab_aabb_grow(&box, &in->prim_bounds[o->prim_index[s]]);
		memcpy(n->lo, box.lo, sizeof(n->lo));
		memcpy(n->hi, box.hi, sizeof(n->hi));
	}
}

int embree_write_tree(const bvhlab_host *host, bvhlab_build_ctx *ctx,
                      const bvhlab_build_input *input, const tnode *root,
                      bvhlab_build_output *out)
{
	writer w = {.host = host, .ctx = ctx, .out = out};
	int rc = write_nodes(&w, root);
	free(w.stack);
	if (rc == 0)
		compute_boxes(input, out);
	return rc;
}
