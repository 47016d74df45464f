/*
 * Morton codes of primitive centroids and their parallel sort, shared by
 * lbvh and ploc (a static library linked into each).
 *
 * Each (code, primitive) pair travels packed as one word, (code >> base)
 * << id_bits | id: the code's upper bits above the primitive id, so that
 * ordering the words orders the pairs, and a pass moves 8 bytes per pair.
 * base is 0 when the whole code fits beside the id (30-bit codes, few
 * primitives), else the lowest code bits are left out and only runs of
 * words whose code bits are equal are put in order by the full codes
 * afterwards; on a real scene such runs are rare and short.
 *
 * The sort: one MSD pass on the codes' top MORTON_TOP_BITS bits scatters
 * the words into buckets (thread t's share of each bucket after the shares
 * of lower chunks, so each bucket is in id order), then each bucket is
 * sorted on its own by LSD passes while it sits in cache: one pass over
 * memory instead of up to eight, and the buckets are shared out among the
 * threads as they come free. Nothing depends on the thread count: the
 * result is the (code, id) order.
 *
 * Use, by every member t of a team of T threads, with a barrier (all
 * writes visible) between the steps:
 *   morton_codes(s, T, t); sync; morton_scatter(s, T, t); sync;
 *   morton_sort_buckets(s, done, arg); sync;
 * after which keys[0] holds the sorted words (morton_id() reads the ids).
 */
#ifndef BVHLAB_MORTON_H
#define BVHLAB_MORTON_H

#include <stdatomic.h>
#include <stdint.h>

#include <bvhlab/types.h>

/* The sort's first digit: the top bits of the codes. */
#define MORTON_TOP_BITS 11
#define MORTON_TOP_RADIX (1u << MORTON_TOP_BITS)

typedef struct morton_sort {
	/* set by the caller before morton_sort_init() */
	uint32_t n;               /* primitives, >= 2 */
	unsigned bits;            /* code length: 30 or 63 */
	const float *centroids;   /* [3 n] */
	bvhlab_aabb centroid_bounds;

	/* buffers, placed by the caller */
	uint64_t *codes;          /* [n] Morton code of each primitive, by id */
	uint64_t *keys[2];        /* [n] packed words: sorted in keys[0]; keys[1]
	                           * is scratch */
	uint32_t (*hist)[MORTON_TOP_RADIX]; /* [T] top digit counts of each chunk */
	uint32_t *bucket;         /* [MORTON_TOP_RADIX + 1] first sorted position
	                           * of each top digit, n at the end */
	atomic_uint next_bucket;  /* blocks of buckets handed out; zero it */

	/* the packing, set by morton_sort_init(): words hold the code from
	 * bit `base` up, shifted above `id_bits` bits of primitive id */
	unsigned base, id_bits;
	unsigned top_shift;       /* position of the top digit in the words */
} morton_sort;

/* The packing for s->n and s->bits; every member may call it. */
void morton_sort_init(morton_sort *s);

/* Centroid bounds to cells, per axis: the cell of c is (c - lo) * scale,
 * clamped to 0 .. top (a flat axis has scale 0: every centroid in cell 0).
 * The device sort (plugins/common/cl) takes the same. */
typedef struct morton_cells {
	float lo[3], scale[3], top;
} morton_cells;

/* The cells of codes of `bits` (30 or 63) over the centroid bounds cb. */
void morton_cells_init(morton_cells *q, const bvhlab_aabb *cb, unsigned bits);

/* The codes of member t's chunk of the primitives, and its digit counts. */
void morton_codes(morton_sort *s, unsigned threads, unsigned t);

/* Member t's chunk scattered into the buckets (after morton_codes). */
void morton_scatter(morton_sort *s, unsigned threads, unsigned t);

/*
 * Sorts the buckets, handed out to whichever member asks; after each
 * non-empty bucket [first, end) is sorted, done(arg, first, end) runs on
 * the same thread while it is in cache (done may be NULL).
 */
void morton_sort_buckets(morton_sort *s, void (*done)(void *arg, uint32_t first, uint32_t end),
                         void *arg);

/* The primitive at sorted position k (after the sort). */
static inline uint32_t morton_id(const morton_sort *s, uint32_t k)
{
	return (uint32_t)(s->keys[0][k] & ((1ull << s->id_bits) - 1));
}

/*
 * 1 + the common prefix length of the sorted keys at positions i < j,
 * extended by the positions where the codes are equal (Karras's k_i ++ i),
 * so that no two keys are equal: 1 + the leading zeros of the codes' XOR
 * (64 bits), else 65 + those of i ^ j (32 bits). The words hold the codes'
 * upper bits; only where those agree are the full codes looked up. (lbvh's
 * hierarchy, hploc's climb; the device kernels compute the same from the
 * full codes.)
 */
static inline uint8_t morton_common_prefix(const morton_sort *s, uint32_t i, uint32_t j)
{
	uint64_t wi = s->keys[0][i], wj = s->keys[0][j];
	uint64_t x = (wi ^ wj) >> s->id_bits;
	uint64_t id_mask = (1ull << s->id_bits) - 1;

	if (x)
		return (uint8_t)(1 + __builtin_clzll(x) - s->base);
	if (s->base)
		x = s->codes[wi & id_mask] ^ s->codes[wj & id_mask];
	if (x)
		return (uint8_t)(1 + __builtin_clzll(x));
	return (uint8_t)(1 + 64 + __builtin_clz(i ^ j));
}

#endif /* BVHLAB_MORTON_H */
