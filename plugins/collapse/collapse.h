/*
 * collapse: a refinement stage that turns a binary tree into a 4- or
 * 8-wide one (ABI 1.5 open tree), as wide-BVH ray tracers do before they
 * trace. Two ways to choose which binary nodes become wide nodes:
 *
 *   sah     the SAH-optimal conversion by dynamic programming over the
 *           binary tree (Ylitie, Karras and Laine, HPG 2017, section 4):
 *           for every binary node n and j = 1..width the cheapest way to
 *           stand for n's subtree by a forest of exactly j wide subtrees,
 *           a wide leaf being any subtree of at most max_leaf references
 *           (collapse_sah.c);
 *   greedy  each wide node takes its binary node's two children and keeps
 *           opening the inner child of largest surface area until it has
 *           `width` children (Embree's and tinybvh's collapse); binary
 *           leaves stay leaves.
 *
 * The cost both are judged by (and sah minimises) is tree.h's wide SAH with
 * the stage's constants: a wide inner node n of k children costs
 * SA(n) * (c_node + c_trav * k / 2), a leaf l SA(l) * c_isect * count(l),
 * normalised by SA(root); the defaults (0, 1, 1) are bvhlab_tree_stats's
 * sah_cost exactly, so `sah` gives the lowest sah_cost of any wide tree
 * made of the binary tree's nodes. Every reference of the binary tree's
 * leaves is kept, in exactly one wide leaf (spatial splits' references
 * stay as they are; none is added).
 */
#ifndef BVHLAB_COLLAPSE_H
#define BVHLAB_COLLAPSE_H

#include <stdbool.h>
#include <stdint.h>

#include <bvhlab/builder.h>

enum collapse_method { COLLAPSE_SAH = 0, COLLAPSE_GREEDY = 1 };

struct collapse_params {
	int64_t width;
	int method; /* enum collapse_method */
	uint32_t max_leaf;
	double c_node, c_trav, c_isect;
};

/* The binary tree (a copy of its nodes) and what the chosen method decided
 * for each binary node that becomes a wide one. */
struct collapse {
	const bvhlab_node *bin; /* the binary tree's nodes, root 0 */
	uint32_t count;         /* binary nodes */
	uint32_t width;         /* 4 or 8 */
	/* sah: per binary node, width entries: [0] 0 when n becomes a leaf,
	 * else its children count j; [j - 1] for j >= 2 the roots that the
	 * left child gives of a forest of j. */
	uint8_t *choice;
};

/* The children (binary node ids, in left-to-right order) of the wide node
 * that binary inner node n becomes: how many, at most width. */
uint32_t collapse_children(const struct collapse *c, uint32_t n, uint32_t *list);

/* Whether binary node n becomes a wide leaf (a binary leaf, or with sah a
 * subtree merged into one). */
bool collapse_is_leaf(const struct collapse *c, uint32_t n);

/* sah's decisions into c->choice (allocated here): 0, or -ENOMEM. */
int collapse_sah_plan(struct collapse *c, const struct collapse_params *p);

/* The forest of j roots that binary node n stands for under sah, into list. */
uint32_t collapse_sah_forest(const struct collapse *c, uint32_t n, uint32_t j, uint32_t *list);

#endif /* BVHLAB_COLLAPSE_H */
