/*
 * The refit plugin and the host's update (ABI 1.4). After the vertices
 * of a scene move, refitting a tree (lbvh's, whose inner nodes often have
 * their children before them; sah_seq's and sah_tasks', whose do not)
 * keeps its topology (node and reference counts, the same tree as
 * bvhlab_tree_compare judges it: shape, leaf contents), gives every node
 * exactly the union of its children's (a leaf: its primitives') new
 * boxes, bit for bit as a fresh computation on the tree before, passes
 * validation and brute-force rays on the moved scene, leaves the tree in
 * refit's layout (children after their parents, references in node
 * order), and is the same tree bit for bit, node order included, for 1, 2
 * and 3 threads asked for (2 started on the larger trees). Over frames,
 * the layout refit gave the tree is kept; trees broken out of it (a
 * node's children before it, subtrees out of pre-order, references out
 * of node order) are refitted as exactly. The host refuses an update over
 * another triangle count (fewer or more) naming both counts, refit
 * refuses a tree with a cycle, a refit-only plugin builds nothing and a
 * builder has no update. And refit then reinsert every frame of the
 * exploding horse (configs/animation.json's), as the harness runs the
 * strategy: every frame's tree valid (reinsert once left frame 4's with a
 * box smaller than its child's, when it took back a children move whose
 * place was an ancestor of the moved node).
 */
#include <errno.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include <bvhlab/aabb.h>
#include <bvhlab/bvhlab.h>

#include "scene/scene_anim.h"
#include "testutil.h"

static bvhlab_plugin *refit;

static void tree_dup(bvhlab_tree *dst, const bvhlab_tree *src)
{
	CHECK_INT(bvhlab_tree_init(dst, src->node_capacity, src->index_capacity), 0);
	memcpy(dst->nodes, src->nodes, src->node_count * sizeof(bvhlab_node));
	memcpy(dst->prim_index, src->prim_index, src->index_count * sizeof(uint32_t));
	dst->node_count = src->node_count;
	dst->index_count = src->index_count;
}

/* A smooth, non-rigid motion: every vertex displaced by its own amount. */
static void move(bvhlab_scene *s)
{
	for (uint32_t v = 0; v < s->vertex_count; v++) {
		float *p = s->vertices + 3 * (size_t)v;
		float x = p[0], y = p[1], z = p[2];
		p[0] = x + 0.3f * sinf(4 * y) + 0.1f;
		p[1] = y + 0.2f * cosf(5 * z);
		p[2] = z * 1.5f + 0.1f * sinf(7 * x);
	}
	bvhlab_scene_update(s);
}

/* The box a node must get: the union of its subtree's primitives' boxes. */
static void reference(const bvhlab_tree *t, const bvhlab_aabb *boxes, uint32_t i, float lo[3],
                      float hi[3])
{
	const bvhlab_node *n = &t->nodes[i];
	bvhlab_box_empty(lo, hi);
	if (n->count) {
		for (uint32_t k = n->first; k < n->first + n->count; k++)
			for (int a = 0; a < 3; a++) {
				lo[a] = bvhlab_minf(boxes[t->prim_index[k]].lo[a], lo[a]);
				hi[a] = bvhlab_maxf(boxes[t->prim_index[k]].hi[a], hi[a]);
			}
		return;
	}
	float l[2][3], h[2][3];
	reference(t, boxes, n->first, l[0], h[0]);
	reference(t, boxes, n->first + 1, l[1], h[1]);
	for (int a = 0; a < 3; a++) {
		lo[a] = bvhlab_minf(l[0][a], l[1][a]);
		hi[a] = bvhlab_maxf(h[0][a], h[1][a]);
	}
}

static int update(const bvhlab_build_input *in, uint32_t threads, bvhlab_tree *t,
                  bvhlab_error *err)
{
	bvhlab_options opts;
	int r = bvhlab_options_init(&opts, bvhlab_plugin_builder(refit));
	if (r == 0)
		r = bvhlab_update(refit, &opts, in, threads, t, err);
	bvhlab_options_finish(&opts);
	return r;
}

/* Whether every inner node's children come after it: refit's own layout
 * does, lbvh's does not (both kinds are refitted here). */
static bool children_after(const bvhlab_tree *t)
{
	for (uint32_t i = 0; i < t->node_count; i++)
		if (!t->nodes[i].count && t->nodes[i].first <= i)
			return false;
	return true;
}

/* Whether the leaves' references follow their nodes' order, each leaf's
 * starting where the previous leaf's end: refit's layout. */
static bool refs_in_order(const bvhlab_tree *t)
{
	uint32_t at = 0;
	for (uint32_t i = 0; i < t->node_count; i++) {
		if (t->nodes[i].count && t->nodes[i].first != at)
			return false;
		at += t->nodes[i].count;
	}
	return at == t->index_count;
}

/* What refitting `before` for `boxes` must give: its shape and leaves,
 * every node's box the union of its subtree's primitives' boxes, computed
 * here from scratch on before's own node order. */
static void expected_tree(bvhlab_tree *exp, const bvhlab_tree *before, const bvhlab_aabb *boxes)
{
	tree_dup(exp, before);
	for (uint32_t i = 0; i < exp->node_count; i++)
		reference(before, boxes, i, exp->nodes[i].lo, exp->nodes[i].hi);
}

/* A refitted tree against the tree it came from: the same counts, the
 * same tree as bvhlab_tree_compare judges it (shape, leaf contents,
 * boxes bit for bit) as the fresh union computation, every node in its
 * own order the exact union of its subtree's boxes, and refit's layout:
 * children after their parents, references in node order. */
static void check_refitted(const bvhlab_tree *before, const bvhlab_tree *t,
                           const bvhlab_build_input *in)
{
	bvhlab_tree exp = {0};
	bvhlab_error err = {{0}};
	int boxes = 0;
	CHECK_INT(t->node_count, before->node_count);
	CHECK_INT(t->index_count, before->index_count);
	CHECK(children_after(t));
	CHECK(refs_in_order(t));
	expected_tree(&exp, before, in->prim_bounds);
	int r = bvhlab_tree_compare(&exp, t, &err);
	if (r != 0)
		fprintf(stderr, "refitted tree differs: %s\n", err.message);
	CHECK_INT(r, 0);
	for (uint32_t i = 0; i < t->node_count; i++) {
		float lo[3], hi[3];
		reference(t, in->prim_bounds, i, lo, hi);
		boxes += memcmp(lo, t->nodes[i].lo, sizeof(lo)) || memcmp(hi, t->nodes[i].hi, sizeof(hi));
	}
	CHECK_INT(boxes, 0);
	bvhlab_tree_finish(&exp);
}

static void check_scene(const char *builder, const char *gen, const bvhlab_gen_params *gp,
                        bool ordered)
{
	bvhlab_scene *s = NULL;
	bvhlab_plugin *b = NULL;
	bvhlab_options opts;
	bvhlab_prims prims = {0}, moved = {0};
	bvhlab_tree t0 = {0}, first = {0};
	bvhlab_error err = {{0}};
	CHECK_INT(bvhlab_scene_generate(gen, gp, &s, &err), 0);
	CHECK_INT(bvhlab_plugin_open(builder, &b, &err), 0);
	if (!s || !b)
		return;
	CHECK_INT(bvhlab_options_init(&opts, bvhlab_plugin_builder(b)), 0);
	CHECK_INT(bvhlab_prims_init(&prims, s, &err), 0);
	CHECK_INT(bvhlab_build(b, &opts, &prims.input, 1, &t0, &err), 0);
	CHECK_INT(children_after(&t0), ordered);
	move(s);
	CHECK_INT(bvhlab_prims_init(&moved, s, &err), 0);
	/* The old tree no longer holds the moved triangles: the point of it. */
	CHECK(bvhlab_validate_tree(&t0, &moved.input, false, &err) < 0);
	for (uint32_t threads = 1; threads <= 3; threads++) {
		bvhlab_tree t = {0};
		uint64_t mismatches = 1;
		tree_dup(&t, &t0);
		CHECK_INT(update(&moved.input, threads, &t, &err), 0);
		CHECK_INT(bvhlab_validate_tree(&t, &moved.input, false, &err), 0);
		check_refitted(&t0, &t, &moved.input);
		CHECK_INT(bvhlab_validate_rays(&t, s, 64, 33, &mismatches, &err), 0);
		CHECK_INT(mismatches, 0);
		if (threads == 1) {
			tree_dup(&first, &t);
		} else {
			CHECK(!memcmp(first.nodes, t.nodes, t.node_count * sizeof(bvhlab_node)));
			CHECK(!memcmp(first.prim_index, t.prim_index, t.index_count * sizeof(uint32_t)));
		}
		bvhlab_tree_finish(&t);
	}
	bvhlab_tree_finish(&first);
	bvhlab_tree_finish(&t0);
	bvhlab_prims_finish(&moved);
	bvhlab_prims_finish(&prims);
	bvhlab_options_finish(&opts);
	bvhlab_plugin_close(b);
	bvhlab_scene_destroy(s);
}

/* Node i's slot and the slots of its children pair, swapped with j's:
 * the tree stays valid, its node order no longer refit's. */
static void swap_pairs(bvhlab_tree *t, uint32_t i, uint32_t j)
{
	uint32_t a = t->nodes[i].first, b = t->nodes[j].first;
	for (uint32_t k = 0; k < 2; k++) {
		bvhlab_node n = t->nodes[a + k];
		t->nodes[a + k] = t->nodes[b + k];
		t->nodes[b + k] = n;
	}
	t->nodes[i].first = b;
	t->nodes[j].first = a;
}

/* The leaves' references rewritten into node order (refit's), each leaf
 * keeping its primitives. */
static void renumber(bvhlab_tree *t)
{
	uint32_t *old = malloc(t->index_count * sizeof(*old)), at = 0;
	if (!old)
		return;
	memcpy(old, t->prim_index, t->index_count * sizeof(*old));
	for (uint32_t i = 0; i < t->node_count; i++) {
		bvhlab_node *n = &t->nodes[i];
		if (!n->count)
			continue;
		memcpy(t->prim_index + at, old + n->first, n->count * sizeof(*old));
		n->first = at;
		at += n->count;
	}
	free(old);
}

/* The last two inner nodes whose children are both leaves, j's pair
 * before i. */
static bool leaf_parents(const bvhlab_tree *t, uint32_t *i, uint32_t *j)
{
	uint32_t found = 0;
	for (uint32_t k = t->node_count; k-- > 0 && found < 2;) {
		const bvhlab_node *n = &t->nodes[k];
		if (!n->count && t->nodes[n->first].count && t->nodes[n->first + 1].count &&
		    (found == 0 || n->first < *i))
			*(found++ ? j : i) = k;
	}
	return found == 2;
}

/* Refits t for the scene moved once more and checks it against the tree
 * it was (fresh unions on that one's node order). */
static void refit_frame(bvhlab_scene *s, bvhlab_tree *t, uint32_t threads)
{
	bvhlab_prims moved = {0};
	bvhlab_tree before = {0};
	bvhlab_error err = {{0}};
	tree_dup(&before, t);
	move(s);
	CHECK_INT(bvhlab_prims_init(&moved, s, &err), 0);
	CHECK_INT(update(&moved.input, threads, t, &err), 0);
	CHECK_INT(bvhlab_validate_tree(t, &moved.input, false, &err), 0);
	check_refitted(&before, t, &moved.input);
	bvhlab_tree_finish(&before);
	bvhlab_prims_finish(&moved);
}

/* Five frames: the first update rewrites lbvh's tree into refit's layout,
 * the later ones sweep that layout and keep it (the same node order and
 * prim_index every frame). */
static void frames_keep_layout(bvhlab_scene *s, bvhlab_tree *t)
{
	bvhlab_tree kept = {0};
	CHECK(!children_after(t));
	for (uint32_t f = 1; f <= 5; f++) {
		refit_frame(s, t, 2);
		if (f == 1)
			tree_dup(&kept, t);
		for (uint32_t k = 0; k < t->node_count; k++)
			CHECK(t->nodes[k].first == kept.nodes[k].first &&
			      t->nodes[k].count == kept.nodes[k].count);
		CHECK(!memcmp(t->prim_index, kept.prim_index, t->index_count * sizeof(uint32_t)));
	}
	bvhlab_tree_finish(&kept);
}

/* The references of leaf i and of the last leaf (which end prim_index)
 * swapped, each leaf keeping its primitives. */
static void swap_refs(bvhlab_tree *t, uint32_t i)
{
	bvhlab_node *a = &t->nodes[i], *b = &t->nodes[t->node_count - 1];
	for (uint32_t k = 0; k < a->count; k++) {
		uint32_t p = t->prim_index[a->first + k];
		t->prim_index[a->first + k] = t->prim_index[b->first + k];
		t->prim_index[b->first + k] = p;
	}
	uint32_t first = a->first;
	a->first = b->first;
	b->first = first;
}

/* A tree in refit's layout but for two pairs of leaves swapped (a node's
 * children before it, the references renumbered into node order), then
 * for the root's children swapped (its subtrees out of pre-order), then
 * for two leaves' references swapped (which only a sweep sees): each
 * refitted exactly all the same, back into refit's layout. */
static void frames_broken_layout(bvhlab_scene *s, bvhlab_tree *t)
{
	uint32_t i = 0, j = 0;
	CHECK(leaf_parents(t, &i, &j));
	swap_pairs(t, i, j);
	renumber(t);
	CHECK(!children_after(t) && refs_in_order(t));
	refit_frame(s, t, 2);
	bvhlab_node left = t->nodes[1];
	t->nodes[1] = t->nodes[2];
	t->nodes[2] = left;
	CHECK(children_after(t));
	refit_frame(s, t, 2);
	for (i = 0; t->nodes[i].count != t->nodes[t->node_count - 1].count; i++)
		;
	swap_refs(t, i);
	CHECK(children_after(t) && !refs_in_order(t));
	refit_frame(s, t, 3);
}

/* lbvh's tree (half its inner nodes have their children before them)
 * refitted over frames, then in layouts broken on purpose. */
static void test_frames(void)
{
	bvhlab_gen_params gp;
	bvhlab_scene *s = NULL;
	bvhlab_plugin *lbvh = NULL;
	bvhlab_options opts;
	bvhlab_prims prims = {0};
	bvhlab_tree t = {0};
	bvhlab_error err = {{0}};
	bvhlab_gen_params_init(&gp);
	gp.frequency = 32;
	CHECK_INT(bvhlab_scene_generate("icosphere", &gp, &s, &err), 0);
	CHECK_INT(bvhlab_plugin_open("lbvh", &lbvh, &err), 0);
	if (!s || !lbvh)
		return;
	CHECK_INT(bvhlab_options_init(&opts, bvhlab_plugin_builder(lbvh)), 0);
	CHECK_INT(bvhlab_prims_init(&prims, s, &err), 0);
	CHECK_INT(bvhlab_build(lbvh, &opts, &prims.input, 2, &t, &err), 0);
	frames_keep_layout(s, &t);
	frames_broken_layout(s, &t);
	bvhlab_tree_finish(&t);
	bvhlab_prims_finish(&prims);
	bvhlab_options_finish(&opts);
	bvhlab_plugin_close(lbvh);
	bvhlab_scene_destroy(s);
}

/* An update over fewer or more triangles than the tree's is refused. */
static void test_counts(void)
{
	bvhlab_gen_params gp;
	bvhlab_scene *a = NULL, *fewer = NULL, *more = NULL;
	bvhlab_prims pa = {0}, pf = {0}, pm = {0};
	bvhlab_plugin *lbvh = NULL;
	bvhlab_options opts;
	bvhlab_tree t = {0};
	bvhlab_error err = {{0}};
	bvhlab_gen_params_init(&gp);
	gp.count = 500;
	CHECK_INT(bvhlab_scene_generate("soup", &gp, &a, &err), 0);
	gp.count = 499;
	CHECK_INT(bvhlab_scene_generate("soup", &gp, &fewer, &err), 0);
	gp.count = 501;
	CHECK_INT(bvhlab_scene_generate("soup", &gp, &more, &err), 0);
	CHECK_INT(bvhlab_plugin_open("lbvh", &lbvh, &err), 0);
	if (!a || !fewer || !more || !lbvh)
		return;
	CHECK_INT(bvhlab_options_init(&opts, bvhlab_plugin_builder(lbvh)), 0);
	CHECK_INT(bvhlab_prims_init(&pa, a, &err), 0);
	CHECK_INT(bvhlab_prims_init(&pf, fewer, &err), 0);
	CHECK_INT(bvhlab_prims_init(&pm, more, &err), 0);
	CHECK_INT(bvhlab_build(lbvh, &opts, &pa.input, 1, &t, &err), 0);
	CHECK_INT(update(&pf.input, 2, &t, &err), -EINVAL);
	CHECK_CONTAINS(err.message, "update 'refit': the tree holds 500 references");
	CHECK_CONTAINS(err.message, "the frame has 499 triangles");
	CHECK_INT(update(&pm.input, 2, &t, &err), -EINVAL);
	CHECK_CONTAINS(err.message, "the frame has 501 triangles");
	/* lbvh updates nothing; refit builds nothing. */
	CHECK_INT(bvhlab_update(lbvh, &opts, &pa.input, 1, &t, &err), -ENOTSUP);
	CHECK_CONTAINS(err.message, "plugin 'lbvh' has no update function (ABI 1.4 update)");
	bvhlab_options_finish(&opts);
	CHECK_INT(bvhlab_options_init(&opts, bvhlab_plugin_builder(refit)), 0);
	CHECK_INT(bvhlab_build(refit, &opts, &pa.input, 1, &t, &err), -ENOTSUP);
	CHECK_CONTAINS(err.message, "plugin 'refit' builds no trees");
	bvhlab_options_finish(&opts);
	bvhlab_tree_finish(&t);
	bvhlab_prims_finish(&pa);
	bvhlab_prims_finish(&pf);
	bvhlab_prims_finish(&pm);
	bvhlab_plugin_close(lbvh);
	bvhlab_scene_destroy(a);
	bvhlab_scene_destroy(fewer);
	bvhlab_scene_destroy(more);
}

/* A tree whose inner node points back up is refused, not walked forever. */
static void test_cycle(void)
{
	bvhlab_aabb boxes[2] = {{{0, 0, 0}, {1, 1, 1}}, {{1, 1, 1}, {2, 2, 2}}};
	float centroids[6] = {0.5f, 0.5f, 0.5f, 1.5f, 1.5f, 1.5f};
	bvhlab_build_input in = {.struct_size = sizeof(in), .prim_count = 2, .prim_bounds = boxes,
	                         .centroids = centroids, .threads = 1};
	bvhlab_tree t = {0};
	bvhlab_error err = {{0}};
	CHECK_INT(bvhlab_tree_init(&t, 3, 2), 0);
	t.nodes[0] = (bvhlab_node){.first = 1};
	t.nodes[1] = (bvhlab_node){.first = 0}; /* its children: the root and itself */
	t.nodes[2] = (bvhlab_node){.first = 0, .count = 2};
	t.prim_index[0] = 0;
	t.prim_index[1] = 1;
	t.node_count = 3;
	t.index_count = 2;
	CHECK_INT(update(&in, 1, &t, &err), -EINVAL);
	CHECK_CONTAINS(err.message, "cycle");
	bvhlab_tree_finish(&t);
}

/* The horse's explosion in configs/animation.json: its amplitude, frames
 * and the harness's seed for a scene's first mesh. */
#define EXPLODE_AMPLITUDE 0.15
#define EXPLODE_FRAMES 16
#define EXPLODE_SEED 0xe8910deULL
/* Frames checked: all of them, or under ASan up to frame 4, the one that
 * reinsert once left invalid. Not under TSan, where it took 158 s: the
 * fault was in reinsert's one-thread undo, not a race, and the stage's
 * threads are raced in test-refine. */
#define EXPLODE_CHECKED (UNDER_ASAN ? 5 : EXPLODE_FRAMES)

/* Frame f of the exploding horse, its primitives into *prims. */
static bvhlab_scene *explode_frame(const bvhlab_scene *rest, uint32_t f, bvhlab_prims *prims)
{
	struct scene_motion m = {.deform = SCENE_DEFORM_EXPLODE, .amplitude = EXPLODE_AMPLITUDE,
	                         .seed = EXPLODE_SEED, .scale = 1};
	bvhlab_scene *s = NULL;
	bvhlab_error err = {{0}};
	bvhlab_transform_init(&m.rest);
	CHECK_INT(scene_anim_pose(rest, &m, (double)f / (EXPLODE_FRAMES - 1), &s, &err), 0);
	if (s)
		CHECK_INT(bvhlab_prims_init(prims, s, &err), 0);
	return s;
}

/* lbvh's tree of frame 0, then per frame refit and reinsert (2 threads),
 * validated every frame and traced against brute force on the last one
 * checked. */
static void explode_frames(const bvhlab_scene *rest, bvhlab_plugin *lbvh, bvhlab_plugin *reinsert)
{
	bvhlab_options lo, ro;
	bvhlab_tree t = {0};
	bvhlab_error err = {{0}};
	CHECK_INT(bvhlab_options_init(&lo, bvhlab_plugin_builder(lbvh)), 0);
	CHECK_INT(bvhlab_options_init(&ro, bvhlab_plugin_builder(reinsert)), 0);
	for (uint32_t f = 0; f < EXPLODE_CHECKED; f++) {
		bvhlab_prims prims = {0};
		bvhlab_scene *s = explode_frame(rest, f, &prims);
		int r = !s ? -1
		        : f == 0 ? bvhlab_build(lbvh, &lo, &prims.input, 2, &t, &err)
		                 : update(&prims.input, 2, &t, &err);
		CHECK_INT(r, 0);
		if (r == 0 && f > 0)
			CHECK_INT(r = bvhlab_refine(reinsert, &ro, &prims.input, 2, &t, &err), 0);
		if (r == 0 && (r = bvhlab_validate_tree(&t, &prims.input, false, &err)) < 0)
			fprintf(stderr, "frame %u: %s\n", f, err.message);
		CHECK_INT(r, 0);
		if (r == 0 && f == EXPLODE_CHECKED - 1) {
			uint64_t mismatches = 1;
			CHECK_INT(bvhlab_validate_rays(&t, s, 64, 33, &mismatches, &err), 0);
			CHECK_INT(mismatches, 0);
		}
		bvhlab_prims_finish(&prims);
		bvhlab_scene_destroy(s);
		if (r < 0)
			break;
	}
	bvhlab_tree_finish(&t);
	bvhlab_options_finish(&lo);
	bvhlab_options_finish(&ro);
}

static void test_explode_reinsert(void)
{
	bvhlab_scene *mesh = NULL, *rest = NULL;
	bvhlab_plugin *lbvh = NULL, *reinsert = NULL;
	bvhlab_error err = {{0}};
	if (UNDER_TSAN) {
		printf("ThreadSanitizer: the exploding horse skipped (release and ASan run it)\n");
		return;
	}
	if (bvhlab_scene_load(BVHLAB_SHARED_SCENES "/horse.ply", &mesh, &err) < 0) {
		printf("no %s/horse.ply: the exploding horse skipped\n", BVHLAB_SHARED_SCENES);
		return;
	}
	CHECK_INT(scene_anim_unshare(mesh, &rest, &err), 0);
	CHECK_INT(bvhlab_plugin_open("lbvh", &lbvh, &err), 0);
	CHECK_INT(bvhlab_plugin_open("reinsert", &reinsert, &err), 0);
	if (rest && lbvh && reinsert)
		explode_frames(rest, lbvh, reinsert);
	bvhlab_plugin_close(reinsert);
	bvhlab_plugin_close(lbvh);
	bvhlab_scene_destroy(rest);
	bvhlab_scene_destroy(mesh);
}

int main(void)
{
	bvhlab_gen_params gp;
	bvhlab_error err = {{0}};
	CHECK_INT(bvhlab_plugin_open("refit", &refit, &err), 0);
	if (!refit)
		return test_finish();
	CHECK(bvhlab_plugin_builder(refit)->flags & BVHLAB_BUILDER_DETERMINISTIC);
	bvhlab_gen_params_init(&gp);
	/* 20,480 triangles: about 41,000 nodes, enough for 2 threads (refit
	 * starts one per 32,768 nodes; 3 asked for). */
	gp.frequency = 32;
	check_scene("lbvh", "icosphere", &gp, false);
	check_scene("sah_tasks", "icosphere", &gp, true);
	gp.frequency = 12;
	check_scene("sah_seq", "icosphere", &gp, true);
	gp.count = 3000;
	check_scene("lbvh", "soup", &gp, false);
	gp.size = 12;
	check_scene("lbvh", "terrain", &gp, false);
	test_frames();
	test_counts();
	test_cycle();
	test_explode_reinsert();
	bvhlab_plugin_close(refit);
	return test_finish();
}
