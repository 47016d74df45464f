/*
 * Test fixture for the tree modules: small scenes built in code (no loader),
 * the build input computed by hand, and a simple recursive median-split
 * reference builder that emits a valid tree in the standard layout.
 * Everything aborts on allocation failure: these are tests.
 */
#ifndef BVHLAB_TREE_FIXTURE_H
#define BVHLAB_TREE_FIXTURE_H

#include <math.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include <bvhlab/aabb.h>
#include <bvhlab/tree.h>

typedef struct fixture {
	bvhlab_scene scene;
	bvhlab_build_input input;
	bvhlab_aabb *boxes;
	float *centroids;
	bvhlab_tree tree;
} fixture;

static inline void *fx_alloc(size_t bytes)
{
	void *p = calloc(bytes ? bytes : 1, 1);

	if (!p) {
		fprintf(stderr, "fixture: out of memory\n");
		exit(1);
	}
	return p;
}

static inline uint64_t fx_rand(uint64_t *state)
{
	uint64_t z = (*state += 0x9e3779b97f4a7c15u);

	z = (z ^ (z >> 30)) * 0xbf58476d1ce4e5b9u;
	z = (z ^ (z >> 27)) * 0x94d049bb133111ebu;
	return z ^ (z >> 31);
}

/* Uniform in [0, 1). */
static inline float fx_unit(uint64_t *state)
{
	return (float)(fx_rand(state) >> 40) * 0x1p-24f;
}

static inline void fixture_alloc(fixture *f, uint32_t vertex_count, uint32_t tri_count)
{
	memset(f, 0, sizeof(*f));
	f->scene.vertices = fx_alloc((size_t)vertex_count * 3 * sizeof(float));
	f->scene.vertex_count = vertex_count;
	f->scene.indices = fx_alloc((size_t)tri_count * 3 * sizeof(uint32_t));
	f->scene.triangle_count = tri_count;
}

/* Primitive boxes, centroids, bounds and the build input, from the mesh. */
static inline void fixture_prepare(fixture *f)
{
	uint32_t n = f->scene.triangle_count, i, j;
	bvhlab_build_input *in = &f->input;

	free(f->boxes);
	free(f->centroids);
	f->boxes = fx_alloc((size_t)n * sizeof(bvhlab_aabb));
	f->centroids = fx_alloc((size_t)n * 3 * sizeof(float));
	memset(in, 0, sizeof(*in));
	bvhlab_aabb_empty(&in->bounds);
	bvhlab_aabb_empty(&in->centroid_bounds);
	for (i = 0; i < n; i++) {
		bvhlab_aabb_empty(&f->boxes[i]);
		for (j = 0; j < 3; j++) {
			const float *v = f->scene.vertices + 3 * (size_t)f->scene.indices[3 * i + j];

			bvhlab_aabb_grow_point(&f->boxes[i], v);
		}
		for (j = 0; j < 3; j++)
			f->centroids[3 * i + j] = bvhlab_aabb_center(&f->boxes[i], (int)j);
		bvhlab_aabb_grow(&in->bounds, &f->boxes[i]);
		bvhlab_aabb_grow_point(&in->centroid_bounds, f->centroids + 3 * i);
	}
	in->struct_size = sizeof(*in);
	in->prim_count = n;
	in->prim_bounds = f->boxes;
	in->centroids = f->centroids;
	in->vertices = f->scene.vertices;
	in->vertex_count = f->scene.vertex_count;
	in->indices = f->scene.indices;
	in->threads = 1;
	f->scene.bounds = in->bounds;
}

/* `count` random triangles of edge up to `size` in the cube [0, extent)^3. */
static inline void fixture_soup(fixture *f, uint32_t count, uint64_t seed, float extent,
                                float size)
{
	uint32_t i, k;

	fixture_alloc(f, 3 * count, count);
	for (i = 0; i < count; i++) {
		float c[3];

		for (k = 0; k < 3; k++)
			c[k] = fx_unit(&seed) * extent;
		for (k = 0; k < 9; k++)
			f->scene.vertices[9 * i + k] = c[k % 3] + (fx_unit(&seed) - 0.5f) * size;
		for (k = 0; k < 3; k++)
			f->scene.indices[3 * i + k] = 3 * i + k;
	}
	fixture_prepare(f);
}

/*
 * A grid of nx * ny unit cells in the plane z = 0, two triangles per cell.
 * gap 0: neighbouring triangles share edges (vertices repeated, with
 * bit-identical coordinates). gap > 0: every triangle is shrunk towards its
 * right-angle corner so no two touch.
 */
static inline void fixture_grid(fixture *f, uint32_t nx, uint32_t ny, float gap)
{
	uint32_t x, y, i = 0, t = 0;

	fixture_alloc(f, 6 * nx * ny, 2 * nx * ny);
	for (y = 0; y < ny; y++) {
		for (x = 0; x < nx; x++) {
			static const float corner[6][2] = { { 0, 0 }, { 1, 0 }, { 0, 1 },
			                                    { 1, 1 }, { 0, 1 }, { 1, 0 } };
			uint32_t k;

			for (k = 0; k < 6; k++) {
				/* Shrink towards the triangle's right-angle corner. */
				float ox = corner[k < 3 ? 0 : 3][0], oy = corner[k < 3 ? 0 : 3][1];
				float *v = f->scene.vertices + 3 * (size_t)(i + k);

				v[0] = (float)x + ox + (corner[k][0] - ox) * (1.0f - gap);
				v[1] = (float)y + oy + (corner[k][1] - oy) * (1.0f - gap);
				v[2] = 0.0f;
				f->scene.indices[3 * t + k] = i + k;
			}
			i += 6;
			t += 2;
		}
	}
	fixture_prepare(f);
}

/* ---- the reference builder ------------------------------------------------ */

typedef struct fx_build {
	fixture *f;
	uint32_t max_leaf;
	uint32_t next; /* next free node pair */
	int axis;
} fx_build;

static fx_build *fx_sort_ctx; /* qsort has no context argument in C11 */

static inline int fx_cmp(const void *pa, const void *pb)
{
	uint32_t a = *(const uint32_t *)pa, b = *(const uint32_t *)pb;
	const float *c = fx_sort_ctx->f->centroids;
	int k = fx_sort_ctx->axis;

	if (c[3 * a + k] != c[3 * b + k])
		return c[3 * a + k] < c[3 * b + k] ? -1 : 1;
	return a < b ? -1 : a > b;
}

static inline void fx_build_node(fx_build *b, uint32_t node, uint32_t begin, uint32_t end)
{
	bvhlab_tree *t = &b->f->tree;
	bvhlab_node *n = &t->nodes[node];
	bvhlab_aabb box, cbox;
	uint32_t i, first;
	int k;

	bvhlab_aabb_empty(&box);
	bvhlab_aabb_empty(&cbox);
	for (i = begin; i < end; i++) {
		const float *c = b->f->centroids + 3 * (size_t)t->prim_index[i];

		bvhlab_aabb_grow(&box, &b->f->boxes[t->prim_index[i]]);
		bvhlab_aabb_grow_point(&cbox, c);
	}
	memcpy(n->lo, box.lo, sizeof(n->lo));
	memcpy(n->hi, box.hi, sizeof(n->hi));
	if (end - begin <= b->max_leaf) {
		n->first = begin;
		n->count = end - begin;
		return;
	}
	b->axis = 0;
	for (k = 1; k < 3; k++)
		if (cbox.hi[k] - cbox.lo[k] > cbox.hi[b->axis] - cbox.lo[b->axis])
			b->axis = k;
	fx_sort_ctx = b;
	qsort(t->prim_index + begin, end - begin, sizeof(uint32_t), fx_cmp);
	first = b->next;
	b->next += 2;
	n->first = first;
	n->count = 0;
	fx_build_node(b, first, begin, begin + (end - begin) / 2);
	fx_build_node(b, first + 1, begin + (end - begin) / 2, end);
}

/* Builds f->tree over every triangle, leaves of at most max_leaf (>= 1). */
static inline void fixture_build(fixture *f, uint32_t max_leaf)
{
	uint32_t n = f->input.prim_count, i;
	fx_build b = { f, max_leaf, 1, 0 };

	bvhlab_tree_finish(&f->tree);
	if (bvhlab_tree_init(&f->tree, 2 * n - 1, n) < 0) {
		fprintf(stderr, "fixture: out of memory\n");
		exit(1);
	}
	for (i = 0; i < n; i++)
		f->tree.prim_index[i] = i;
	fx_build_node(&b, 0, 0, n);
	f->tree.node_count = b.next;
	f->tree.index_count = n;
}

/* Recomputes every box below `node` (recursive: fixture trees are shallow). */
static inline void fixture_refit_node(bvhlab_tree *t, const bvhlab_build_input *in,
                                      uint32_t node)
{
	bvhlab_node *n = &t->nodes[node];
	bvhlab_aabb box;
	uint32_t i;

	bvhlab_aabb_empty(&box);
	if (n->count) {
		for (i = n->first; i < n->first + n->count; i++)
			bvhlab_aabb_grow(&box, &in->prim_bounds[t->prim_index[i]]);
	} else {
		for (i = n->first; i < n->first + 2; i++) {
			fixture_refit_node(t, in, i);
			bvhlab_aabb_grow_corners(&box, t->nodes[i].lo, t->nodes[i].hi);
		}
	}
	memcpy(n->lo, box.lo, sizeof(n->lo));
	memcpy(n->hi, box.hi, sizeof(n->hi));
}

/* A deep copy, with room for `extra` more nodes and indices. */
static inline void tree_copy(bvhlab_tree *dst, const bvhlab_tree *src, uint32_t extra)
{
	if (bvhlab_tree_init(dst, src->node_capacity + extra, src->index_capacity + extra) < 0) {
		fprintf(stderr, "fixture: out of memory\n");
		exit(1);
	}
	memcpy(dst->nodes, src->nodes, (size_t)src->node_count * sizeof(bvhlab_node));
	memcpy(dst->prim_index, src->prim_index, (size_t)src->index_count * sizeof(uint32_t));
	dst->node_count = src->node_count;
	dst->index_count = src->index_count;
}

/*
 * `count` large triangles stacked at z = 0, 1, ..., count - 1 and a
 * degenerate hand-built tree over them: node 2i+1 is the leaf of triangle
 * i and node 2i+2 the chain over triangles i+1.. . Depth count - 1, far
 * beyond any fixed traversal stack.
 */
static inline void fixture_chain(fixture *f, uint32_t count)
{
	static const float tri[3][2] = { { -10, -10 }, { 10, -10 }, { 0, 10 } };
	bvhlab_tree *t = &f->tree;
	uint32_t i, k;

	fixture_alloc(f, 3 * count, count);
	for (i = 0; i < count; i++) {
		for (k = 0; k < 3; k++) {
			f->scene.vertices[9 * i + 3 * k] = tri[k][0];
			f->scene.vertices[9 * i + 3 * k + 1] = tri[k][1];
			f->scene.vertices[9 * i + 3 * k + 2] = (float)i;
			f->scene.indices[3 * i + k] = 3 * i + k;
		}
	}
	fixture_prepare(f);
	if (bvhlab_tree_init(t, 2 * count - 1, count) < 0)
		exit(1);
	for (i = 0; i < count; i++) {
		uint32_t chain = i == 0 ? 0 : 2 * i, leaf = i + 1 < count ? 2 * i + 1 : 2 * i;

		t->prim_index[i] = i;
		t->nodes[leaf] = (bvhlab_node){ .first = i, .count = 1 };
		if (leaf != chain)
			t->nodes[chain] = (bvhlab_node){ .first = 2 * i + 1, .count = 0 };
	}
	t->node_count = 2 * count - 1;
	t->index_count = count;
	fixture_refit_node(t, &f->input, 0);
}

/* Uniform in [0, n). */
static inline uint32_t fx_below(uint64_t *state, uint32_t n)
{
	return (uint32_t)(fx_rand(state) % n);
}

static inline void fx_shuffle(uint32_t *v, uint32_t n, uint64_t *seed)
{
	uint32_t i;

	for (i = n; i > 1; i--) {
		uint32_t k = fx_below(seed, i), x = v[i - 1];

		v[i - 1] = v[k];
		v[k] = x;
	}
}

/* Moves sibling pairs to shuffled slots and swaps children at random;
 * map[old] = new. Leaves keep their prim_index ranges. */
static inline void fx_permute_nodes(bvhlab_tree *dst, const bvhlab_tree *src, uint64_t *seed,
                                    uint32_t *map)
{
	uint32_t pairs = (src->node_count - 1) / 2, i;
	uint32_t *perm = fx_alloc((pairs + 1) * sizeof(uint32_t));

	for (i = 0; i < pairs; i++)
		perm[i] = i;
	fx_shuffle(perm, pairs, seed);
	map[0] = 0;
	for (i = 0; i < pairs; i++) {
		uint32_t swap = (uint32_t)(fx_rand(seed) & 1), to = 1 + 2 * perm[i];

		map[1 + 2 * i] = to + swap;
		map[2 + 2 * i] = to + 1 - swap;
	}
	for (i = 0; i < src->node_count; i++) {
		bvhlab_node node = src->nodes[i];

		if (node.count == 0)
			node.first = 1 + 2 * perm[(node.first - 1) / 2];
		dst->nodes[map[i]] = node;
	}
	free(perm);
}

/* Lays the leaves' ranges out in shuffled order, each leaf shuffled too. */
static inline void fx_shuffle_leaves(bvhlab_tree *dst, const bvhlab_tree *src, uint64_t *seed)
{
	uint32_t *leaves = fx_alloc(dst->node_count * sizeof(uint32_t)), count = 0, slot = 0, i;

	for (i = 0; i < dst->node_count; i++)
		if (dst->nodes[i].count)
			leaves[count++] = i;
	fx_shuffle(leaves, count, seed);
	for (i = 0; i < count; i++) {
		bvhlab_node *l = &dst->nodes[leaves[i]];

		memcpy(dst->prim_index + slot, src->prim_index + l->first, l->count * sizeof(uint32_t));
		fx_shuffle(dst->prim_index + slot, l->count, seed);
		l->first = slot;
		slot += l->count;
	}
	free(leaves);
}

/*
 * The same tree in another memory order: sibling pairs shuffled, the two
 * children of each pair swapped at random, leaf ranges shuffled in
 * prim_index and each leaf's primitives shuffled. Needs a tree whose nodes
 * 1.. are all sibling pairs (as fixture_build makes). map[old] = new if
 * map_out is not NULL (node_count entries).
 */
static inline void tree_permute(bvhlab_tree *dst, const bvhlab_tree *src, uint64_t seed,
                                uint32_t *map_out)
{
	uint32_t *map = fx_alloc(src->node_count * sizeof(uint32_t));

	tree_copy(dst, src, 0);
	fx_permute_nodes(dst, src, &seed, map);
	fx_shuffle_leaves(dst, src, &seed);
	if (map_out)
		memcpy(map_out, map, src->node_count * sizeof(uint32_t));
	free(map);
}

static inline void fixture_free(fixture *f)
{
	free(f->scene.vertices);
	free(f->scene.indices);
	free(f->boxes);
	free(f->centroids);
	bvhlab_tree_finish(&f->tree);
	memset(f, 0, sizeof(*f));
}

#endif /* BVHLAB_TREE_FIXTURE_H */
