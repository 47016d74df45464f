/*
 * The SAH kernel's data: build parameters, jobs, the working primitive
 * records, the per-build state and the bins. Every kernel source and the
 * plugins see these; the functions are in sah_kernel.h (for plugins),
 * sah_bins.h, sah_nodes.h and sah_split.h (inside the kernel).
 */
#ifndef BVHLAB_SAH_TYPES_H
#define BVHLAB_SAH_TYPES_H

#include <stdatomic.h>
#include <stdbool.h>
#include <stdint.h>

#include <bvhlab/builder.h>

#include "team.h"

enum sah_method {
	SAH_SWEEP = 0,  /* exact SAH over presorted centroids */
	SAH_BINNED = 1, /* binned SAH */
};

enum sah_simd {
	SAH_SIMD_SSE = 0,  /* 4-lane vectors (SSE2, or plain C off x86) */
	SAH_SIMD_AVX2 = 1, /* 8-lane binning, where the CPU has AVX2 */
};

/*
 * How jobs of at most SAH_SMALL_MAX primitives are searched (larger ones
 * are the same either way). HIGH: exact SAH over all three axes, the
 * reference trees. FAST: exact SAH along the axis of the node's largest
 * centroid extent only (sah_small_fast.c), which needs no sorted order of
 * the other two axes.
 */
enum sah_quality {
	SAH_HIGH = 0,
	SAH_FAST = 1,
};

/* What option simd asks for: its choices auto|avx2|sse, in order. */
enum sah_simd_ask {
	SAH_ASK_AUTO = 0,
	SAH_ASK_AVX2 = 1,
	SAH_ASK_SSE = 2,
};

/* Build parameters, as read from the plugin options (the enums are their
 * choices' indices: sweep|binned, high|fast). */
typedef struct sah_options {
	int method;        /* enum sah_method */
	int simd_asked;    /* enum sah_simd_ask, as the option says */
	int simd;          /* enum sah_simd, resolved; same trees either way */
	int quality;       /* enum sah_quality */
	uint32_t bins;     /* bins per axis for SAH_BINNED, 2..SAH_MAX_BINS */
	uint32_t max_leaf; /* largest leaf, >= 1 (except coincident centroids) */
	float c_trav;      /* cost of visiting an inner node, > 0 */
	float c_isect;     /* cost of one primitive test, > 0 */
	uint32_t sample;   /* binned: nodes over 4 * sample primitives bin only
	                    * `sample` of them, evenly spaced; 0 bins all (the
	                    * only choice of the plugins without the option) */
} sah_options;

#define SAH_MAX_SAMPLE 1024

#define SAH_MAX_BINS 256

/*
 * One node to build: the slot it goes to, its primitives and their bounds.
 * Small and self-contained, so schedulers can copy it into queues.
 */
typedef struct sah_job {
	uint32_t node;     /* index of the node slot this job fills */
	uint32_t begin;    /* first position of its primitives in the working
	                    * arrays (and in output->prim_index) */
	uint32_t end;      /* one past the last position; end > begin */
	uint32_t depth;    /* root 0; for schedulers' cutoffs, not used by splits */
	uint32_t alt;      /* binned: 1 when its primitives are in the builder's
	                    * alt array, 0 when in prims[0] (sweep: always 0) */
	bvhlab_aabb box;   /* exact union of its primitives' boxes */
	bvhlab_aabb cbox;  /* bounds of its primitives' centroids */
} sah_job;

/*
 * A primitive's box and id, copied from the input into the kernel's working
 * arrays so that the split searches stream through memory instead of
 * gathering boxes by id. Its centroid is the box centre, 0.5f * (lo + hi),
 * computed the same way everywhere in the kernel (the core's
 * input->centroids hold the same values).
 */
typedef struct sah_prim {
	float lo[3];  /* box minimum */
	uint32_t id;  /* primitive id, index into input->prim_bounds */
	float hi[3];  /* box maximum */
	uint32_t pad; /* keeps the record 32 bytes and 16-byte aligned */
} sah_prim;

_Static_assert(sizeof(sah_prim) == 32, "sah_prim is 32 bytes");

/*
 * State shared by every job of one build. Set up by sah_builder_init; only
 * node_counter changes afterwards, and the arrays below are written only
 * at positions in [begin, end) of the job being processed or at ids of
 * primitives in that range.
 */
typedef struct sah_builder {
	sah_options opt;            /* copy of the build parameters */
	const team_host *th;        /* the build's thread layer (the input copy) */
	uint32_t prim_count;        /* primitives in the build, >= 1 */
	bvhlab_aabb root_box;       /* input->bounds */
	bvhlab_aabb root_cbox;      /* bounds of all centroids (computed) */
	bvhlab_node *nodes;         /* output->nodes, >= 2 * prim_count - 1 slots */
	atomic_uint node_counter;   /* node slots handed out; slot 0 is the root */
	/* output->prim_index: a leaf writes the ids of its range [begin, end)
	 * there, in its range's order in prims[0]. */
	uint32_t *ids;
	/* Working primitive arrays, by position; a job's primitives are at
	 * [begin, end). Sweep: prims[a] holds them sorted by centroid along
	 * axis a, ties by id (three arrays, same set per range). Binned:
	 * prims[0] and alt: a split reads its range from one and scatters
	 * it into the other, where its children then are (sah_job.alt);
	 * prims[1], prims[2] NULL. */
	sah_prim *prims[3];
	sah_prim *alt;
	sah_prim *temp;  /* sweep: [prim_count] stable-partition target, by position */
	float *area;     /* sweep: [prim_count] right-side areas, by position */
	uint8_t *side;   /* sweep: [prim_count] left(0)/right(1) mark, by primitive id */
	bool in_output;  /* the record arrays lie past the tree in the output
	                  * (not to be unmapped) */
} sah_builder;

/*
 * Binning, for the kernel's binned splits and for schedulers that bin one
 * node in parts (sah_tasks): the grid places centroids, the bins gather
 * counts and box unions. Unions are min/max and counts integers, so bins
 * filled in any parts and merged in any order are bit-identical, and the
 * choice below depends only on the node's set of primitives.
 */
typedef struct sah_grid {
	uint32_t nb;    /* bins per axis */
	float lo[3];    /* the node's centroid bounds' minimum */
	float scale[3]; /* bins per unit length; 0 when the axis is flat */
} sah_grid;

typedef struct sah_bins {
	uint32_t count[3][SAH_MAX_BINS]; /* primitives per bin */
	/* Union of their boxes: lanes 0-2 the minimum negated, 4-6 the
	 * maximum, so that one 8-lane max grows both (3 and 7 unused); all
	 * -inf when empty. Negation is exact, so this is min/max exactly. */
	float box[3][SAH_MAX_BINS][8];
} sah_bins;

/* The array job's primitives are in. */
static inline sah_prim *sah_job_prims(const sah_builder *b, const sah_job *job)
{
	return job->alt ? b->alt : b->prims[0];
}

/* Node slots used so far. */
static inline uint32_t sah_node_count(sah_builder *b)
{
	return atomic_load_explicit(&b->node_counter, memory_order_relaxed);
}

#endif /* BVHLAB_SAH_TYPES_H */
