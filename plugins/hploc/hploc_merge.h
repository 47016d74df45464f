/*
 * A node's merging in H-PLOC, one definition for the CPU builder
 * (hploc_climb.c) and the device kernel (cl_hploc.cl, whose program the
 * build starts with this file, after morton_sort.cl), so both make the
 * same merges with the same float operations in the same order: the
 * clusters and records, PLOC's rounds over a node's list (candidate keys
 * with ploc's tie order, ploc_cluster.c), the union and lbvh's SAH
 * collapse decision. The C that OpenCL C also is: the pointers are
 * private memory there (the kernel works on copies), and only the 32-bit
 * type and the float's bits are named apart.
 */
#ifndef BVHLAB_HPLOC_MERGE_H
#define BVHLAB_HPLOC_MERGE_H

#ifdef __OPENCL_VERSION__
typedef uint hploc_u32;
#define hploc_float_bits(f) as_uint(f)
#else
#include <stdbool.h>
#include <stdint.h>
#include <string.h>
typedef uint32_t hploc_u32;
static inline hploc_u32 hploc_float_bits(float f)
{
	hploc_u32 bits;

	memcpy(&bits, &f, sizeof(bits));
	return bits;
}
#endif

#define HPLOC_LEAF 0x80000000u      /* a node word naming a primitive */
#define HPLOC_COLLAPSED 0x40000000u /* in info: the SAH made the subtree one leaf */
#define HPLOC_PRIMS 0x3fffffffu     /* in info: primitives below */
#define HPLOC_MAX_RADIUS 32
#define HPLOC_MAX_THRESHOLD 32
/* The most clusters a node merges: two children's, at most threshold each. */
#define HPLOC_MAX_LIST (2 * HPLOC_MAX_THRESHOLD)
/* ploc's candidate keys: the distance's float bits with the lowest 8
 * given up for how far apart the pair is (6 bits), the parity of its
 * earlier cluster, and 1 when seen from the earlier one. */
#define HPLOC_TIE_MASK 0xffu

/* An inner record of the merge tree (40 bytes; node words: hploc_tree.h). */
typedef struct hploc_rec {
	float lo[3];
	hploc_u32 left;  /* node word of the left (earlier) child */
	float hi[3];
	hploc_u32 right; /* node word of the right child */
	hploc_u32 info;  /* HPLOC_COLLAPSED | primitives */
	hploc_u32 desc;  /* output nodes below this one's own (0 when collapsed) */
} hploc_rec;

/* A cluster (40 bytes), kept by its representative (hploc_tree.h). */
typedef struct hploc_cluster {
	float lo[3];
	hploc_u32 node; /* its node word */
	float hi[3];
	hploc_u32 info; /* HPLOC_COLLAPSED | primitives */
	float cost;     /* the subtree's SAH cost, area-weighted */
	hploc_u32 desc; /* output nodes below the cluster's own */
} hploc_cluster;

/* A build's merging parameters. */
typedef struct hploc_params {
	hploc_u32 radius;
	hploc_u32 collapse; /* 0 or 1 */
	hploc_u32 max_leaf;
	float c_trav, c_isect;
} hploc_params;

/* Half the surface area of a box, as bvhlab_half_area. */
static inline float hploc_half_area(const float *lo, const float *hi)
{
	float dx = hi[0] - lo[0], dy = hi[1] - lo[1], dz = hi[2] - lo[2];
	return dx * dy + dy * dz + dz * dx;
}

/* The key of the pair e (at list position e_at) and l, k + 1 positions
 * later, as l sees it: the distance is the union's half area. */
static inline hploc_u32 hploc_pair_key(const hploc_cluster *e, const hploc_cluster *l,
                                       hploc_u32 k, hploc_u32 e_at)
{
	float lo[3], hi[3];
	for (int a = 0; a < 3; a++) {
		hi[a] = l->hi[a] > e->hi[a] ? l->hi[a] : e->hi[a];
		lo[a] = l->lo[a] < e->lo[a] ? l->lo[a] : e->lo[a];
	}
	float d = hploc_half_area(lo, hi);
	d = d > 0 ? d : 0; /* -0 and NaN as 0 */
	return (hploc_float_bits(d) & ~HPLOC_TIE_MASK) | k << 2 | (e_at & 1) << 1;
}

/* Each list position's nearest neighbour, into nn[]: every pair's key
 * once, offered to both. */
static inline void hploc_nearest(const hploc_cluster *c, hploc_u32 m, hploc_u32 radius,
                                 hploc_u32 *nn)
{
	hploc_u32 best[HPLOC_MAX_LIST];
	for (hploc_u32 i = 0; i < m; i++)
		best[i] = 0xffffffffu;
	for (hploc_u32 i = 0; i < m; i++) {
		hploc_u32 count = m - 1 - i < radius ? m - 1 - i : radius;
		for (hploc_u32 k = 0; k < count; k++) {
			hploc_u32 key = hploc_pair_key(c + i, c + i + 1 + k, k, i);
			best[i + 1 + k] = key < best[i + 1 + k] ? key : best[i + 1 + k];
			best[i] = (key | 1) < best[i] ? key | 1 : best[i];
		}
	}
	for (hploc_u32 i = 0; i < m; i++) {
		hploc_u32 apart = 1 + ((best[i] & HPLOC_TIE_MASK) >> 2);
		nn[i] = best[i] & 1 ? i + apart : i - apart;
	}
}

/* Clusters x (earlier) and y merge into x, which becomes the node at
 * `slot`; its record into *r. The SAH decision is ploc_cluster.c's
 * merge_cost: at most max_leaf primitives become one leaf when
 * c_isect * N * A is no more than c_trav * A plus the children's costs. */
static inline void hploc_merge(hploc_cluster *x, const hploc_cluster *y, hploc_u32 slot,
                               const hploc_params *p, hploc_rec *r)
{
	hploc_u32 prims = (x->info & HPLOC_PRIMS) + (y->info & HPLOC_PRIMS);
	for (int a = 0; a < 3; a++) {
		r->lo[a] = x->lo[a] < y->lo[a] ? x->lo[a] : y->lo[a];
		r->hi[a] = x->hi[a] > y->hi[a] ? x->hi[a] : y->hi[a];
	}
	float area = hploc_half_area(r->lo, r->hi);
	float split = p->c_trav * area + x->cost + y->cost;
	float leaf = p->c_isect * (float)prims * area;
	bool collapsed = p->collapse && prims <= p->max_leaf && leaf <= split;
	r->left = x->node;
	r->right = y->node;
	r->info = prims | (collapsed ? HPLOC_COLLAPSED : 0);
	r->desc = collapsed ? 0 : 2 + x->desc + y->desc;
	for (int a = 0; a < 3; a++) {
		x->lo[a] = r->lo[a];
		x->hi[a] = r->hi[a];
	}
	x->node = slot;
	x->info = r->info;
	x->cost = collapsed ? leaf : split;
	x->desc = r->desc;
}

/*
 * A node's list: m clusters c[] (copies, in order) with representatives
 * list[], merged by PLOC rounds (mutual nearest neighbours merge, the
 * survivors stay in order; each round merges at least its least pair)
 * until at most cap are left; returns how many. Each merge's record goes
 * to the slot of the later cluster's representative: into rec[] and
 * slot[], *records of them.
 */
static inline hploc_u32 hploc_merge_list(hploc_cluster *c, hploc_u32 *list, hploc_u32 m,
                                         hploc_u32 cap, const hploc_params *p,
                                         hploc_rec *rec, hploc_u32 *slot,
                                         hploc_u32 *records)
{
	hploc_u32 nn[HPLOC_MAX_LIST];
	*records = 0;
	while (m > cap) {
		hploc_u32 left = 0;
		hploc_nearest(c, m, p->radius, nn);
		for (hploc_u32 i = 0; i < m; i++) {
			hploc_u32 j = nn[i];
			if (nn[j] != i || i < j) {
				if (nn[j] == i) {
					slot[*records] = list[j];
					hploc_merge(c + i, c + j, list[j], p, rec + (*records)++);
				}
				c[left] = c[i];
				list[left++] = list[i];
			}
		}
		m = left;
	}
	return m;
}

#endif /* BVHLAB_HPLOC_MERGE_H */
