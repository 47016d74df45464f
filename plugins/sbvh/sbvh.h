/*
 * sbvh plugin internals: a top-down SAH builder with object and spatial
 * splits (Stich, Friedrich & Dietrich 2009).
 *
 * References. A reference is a triangle id and a box that holds the part
 * of the triangle it stands for; a spatial split cuts a reference in two
 * at a plane, each half's box being the exact box of the triangle's part
 * on that side (tri_clip.c). The references of a node lie in one of two
 * buffers, and its children's are written into the other one ("ping-pong"),
 * so no split copies back.
 *
 * The budget. Each buffer holds ceil(split_factor * N) references. A job
 * owns a region [rbegin, rend) of both buffers and keeps its references
 * at [begin, end) inside it; the room left over is what its subtree may
 * still duplicate. A split hands each child a part of the region in
 * proportion to its reference count, so regions stay disjoint and no
 * subtree can take another's room. A spatial split that would not fit is
 * not taken (the object split is used instead).
 *
 * Determinism. A split depends only on the node's references as a set
 * (binning is a union of boxes and a sum of counts), and partitions keep
 * the references' order, so the tree is the same whatever the thread
 * count; only the order of nodes and leaf slots in the output differs.
 */
#ifndef BVHLAB_SBVH_H
#define BVHLAB_SBVH_H

#include <stdatomic.h>
#include <stdbool.h>
#include <stdint.h>

#include <bvhlab/aabb.h>
#include <bvhlab/builder.h>

#include "team.h"

#define SBVH_MAX_BINS 64
#define SBVH_MAX_LEAF 64 /* max_leaf's upper bound */

/* A reference: 32 bytes. */
typedef struct sbvh_ref {
	float lo[3];
	uint32_t prim;
	float hi[3];
	uint32_t cuts; /* pre-splitting: cuts that made this piece */
} sbvh_ref;

typedef struct sbvh_options {
	double split_factor; /* reference budget, in triangles */
	double alpha;        /* try spatial splits when children overlap > alpha * SA(root) */
	double overlap;      /* ... and >= overlap * SA(node) */
	uint32_t bins;       /* object and spatial bins per axis */
	uint32_t max_leaf;
	uint32_t parallel_min; /* jobs of at least this many references use every thread */
	double presplit;     /* share of the budget's room spent on pre-splitting */
	uint32_t lookahead;  /* jobs of at least this many references: sbvh_lookahead */
} sbvh_options;

/* A node to build: its references and region (see the top). */
typedef struct sbvh_job {
	uint32_t begin, end;   /* references, in buffer `buf` */
	uint32_t rbegin, rend; /* its region of the budget */
	uint32_t node;         /* output node to fill */
	uint32_t buf;          /* 0 or 1 */
	float lo[3], hi[3];    /* box of the references */
	float clo[3], chi[3];  /* bounds of their box centres */
} sbvh_job;

/* No references yet: empty box and centre bounds. */
static inline void sbvh_job_empty(sbvh_job *j)
{
	bvhlab_box_empty(j->lo, j->hi);
	bvhlab_box_empty(j->clo, j->chi);
}

/* Whether a job's region has room for a reference more than it holds:
 * the room a spatial split needs. */
static inline bool sbvh_job_has_room(const sbvh_job *j)
{
	return j->rend - j->rbegin > j->end - j->begin;
}

/* Adds a reference to a job's box and centre bounds. */
static inline void sbvh_job_grow(sbvh_job *j, const sbvh_ref *r)
{
	for (int k = 0; k < 3; k++) {
		float c = 0.5f * (r->lo[k] + r->hi[k]);
		j->lo[k] = bvhlab_minf(j->lo[k], r->lo[k]);
		j->hi[k] = bvhlab_maxf(j->hi[k], r->hi[k]);
		j->clo[k] = bvhlab_minf(j->clo[k], c);
		j->chi[k] = bvhlab_maxf(j->chi[k], c);
	}
}

/* What a build shares between its threads. */
typedef struct sbvh_build {
	const bvhlab_build_input *in;
	bvhlab_build_output *out;
	sbvh_options opt;
	sbvh_ref *refs[2];        /* the two buffers */
	uint32_t capacity;        /* references each buffer holds */
	double root_area;         /* SA of the root box, for the alpha test */
	uint32_t threads;
	team_host th;                /* where the phases' threads pin themselves */
	_Atomic uint32_t next_node;  /* output nodes handed out */
	_Atomic uint32_t next_slot;  /* prim_index slots handed out */
	_Atomic uint64_t spatial;    /* spatial splits taken (diagnostics) */
} sbvh_build;

/* The best split of a job, found by sbvh_find_split. */
typedef struct sbvh_split {
	int kind;           /* SPLIT_LEAF, _OBJECT, _SPATIAL or _MEDIAN */
	int axis;
	uint32_t bin;       /* object: left takes centroid bins <= bin; spatial: planes */
	float pos;          /* spatial: the plane x[axis] = pos */
	double cost;        /* SAH of the split, in units of the node's area */
	float llo[3], lhi[3], rlo[3], rhi[3]; /* children's boxes (spatial: binned) */
	uint32_t nl, nr;    /* binned reference counts */
	float clo[3], chi[3]; /* object: centroid bounds the bins span */
} sbvh_split;

enum { SPLIT_LEAF = 0, SPLIT_OBJECT = 1, SPLIT_SPATIAL = 2, SPLIT_MEDIAN = 3 };

/* Per-thread scratch for binning (bins of one chunk). A bin's box takes
 * four floats, of which the first three count, so that it is grown with
 * one vector min and max (sah_simd.h); the fourth is never read. */
typedef struct sbvh_bins {
	float lo[3][SBVH_MAX_BINS][4], hi[3][SBVH_MAX_BINS][4];
	uint32_t count[3][SBVH_MAX_BINS];  /* object: refs; spatial: entries */
	uint32_t exits[3][SBVH_MAX_BINS];  /* spatial: refs ending in the bin */
} sbvh_bins;

/* ---- sbvh_split.c: choosing and applying splits ------------------------- */

/* Bins refs [begin, end) of the job's buffer into b (cleared first). */
void sbvh_bin_object(const sbvh_build *B, const sbvh_job *job, const float clo[3],
                     const float chi[3], uint32_t begin, uint32_t end, sbvh_bins *b);
/* The same over refs[begin, end) of any array. */
void sbvh_bin_object_refs(const sbvh_ref *refs, uint32_t bins, const float clo[3],
                          const float chi[3], uint32_t begin, uint32_t end, sbvh_bins *b);
void sbvh_bin_spatial(const sbvh_build *B, const sbvh_job *job, uint32_t begin,
                      uint32_t end, sbvh_bins *b);
/* Adds `from` into `to` (box unions and count sums: order does not matter). */
void sbvh_bins_merge(sbvh_bins *to, const sbvh_bins *from, uint32_t bins);
void sbvh_bins_clear(sbvh_bins *b, uint32_t bins);

/* Centroid bounds of refs [begin, end) of the job's buffer. */
void sbvh_centroid_bounds(const sbvh_build *B, const sbvh_job *job, uint32_t begin,
                          uint32_t end, float clo[3], float chi[3]);

/* The best object split from object bins, the best spatial split from
 * spatial bins (s->kind stays as is when none beats s->cost). */
void sbvh_best_object(const sbvh_build *B, const sbvh_job *job, const sbvh_bins *b,
                      const float clo[3], const float chi[3], sbvh_split *s);
void sbvh_best_spatial(const sbvh_build *B, const sbvh_job *job, const sbvh_bins *b,
                       sbvh_split *s);
/* Whether the object split's children overlap enough to try spatial splits. */
bool sbvh_try_spatial(const sbvh_build *B, const sbvh_job *job, const sbvh_split *s);

/*
 * Where reference i of the job goes under split s: bit 0 left, bit 1
 * right (both: it is cut in two; *l and *r then get the halves' boxes).
 */
unsigned sbvh_place(const sbvh_build *B, const sbvh_split *s, const sbvh_ref *ref,
                    sbvh_ref *l, sbvh_ref *r);

/* ---- sbvh_build.c: one thread's subtrees ---------------------------------- */

/*
 * A job's split, in steps (the parallel top nodes bin with every thread in
 * between): the best object split from object bins; whether spatial bins
 * are worth making (Stich's alpha test, room in the budget); the best
 * split of both; then the leaf test (n == 1, or n <= max_leaf and a leaf
 * no dearer than the split), with an order median (SPLIT_MEDIAN) when no
 * plane separates more than max_leaf references.
 */
void sbvh_choose_object(const sbvh_build *B, const sbvh_job *job, const sbvh_bins *bins,
                        sbvh_split *obj);
bool sbvh_want_spatial(const sbvh_build *B, const sbvh_job *job, const sbvh_split *obj);
void sbvh_choose_spatial(const sbvh_build *B, const sbvh_job *job, const sbvh_bins *bins,
                         sbvh_split *best);
void sbvh_choose_final(const sbvh_build *B, const sbvh_job *job, sbvh_split *best);
/* Writes the job as a leaf. */
void sbvh_write_leaf(sbvh_build *B, const sbvh_job *job);
/* Gives the job's node two children; their jobs (boxes and references still
 * to be filled in) get the node numbers and regions for nl and nr refs. */
void sbvh_make_children(sbvh_build *B, const sbvh_job *job, uint32_t nl, uint32_t nr,
                        sbvh_job *left, sbvh_job *right);
/* Builds the whole subtree of job on the calling thread. 0 or -ENOMEM. */
int sbvh_build_subtree(sbvh_build *B, const sbvh_job *job, sbvh_bins *scratch);

/* ---- sbvh_lookahead.c ----------------------------------------------------- */

/*
 * Of an object split obj and a spatial split sp of a large job: sp when
 * its greedy cost is lower, or when its children, split once more, cost
 * less than obj's (see the file); else obj. bins is scratch. Without
 * memory for the sample, the greedy cost alone decides.
 */
const sbvh_split *sbvh_lookahead(const sbvh_build *B, const sbvh_job *job,
                                 const sbvh_split *obj, const sbvh_split *sp, sbvh_bins *bins);

/* ---- sbvh_presplit.c ------------------------------------------------------ */

/*
 * Cuts the references refs[0][0 .. count) with the largest boxes in two
 * until there are `target` (or none can be cut); *out_count gets the new
 * count. One thread. 0 or -ENOMEM.
 */
int sbvh_presplit(const sbvh_build *B, uint32_t count, uint32_t target, uint32_t *out_count);

/* ---- sbvh_par.c: the top nodes with every thread, then tasks --------------- */

/* Builds the tree under the root job with B->threads threads. 0 or -errno. */
int sbvh_build_all(sbvh_build *B, const sbvh_job *root);

#endif /* BVHLAB_SBVH_H */
