/*
 * The copy of the input boxes into the kernel's working arrays, which a
 * parallel build shares out among a team of threads (a serial copy of a
 * million records would cap its speedup).
 */
#include "sah_box.h"
#include "sah_split.h"

/* Most parts the copy is cut into, and fewest records each. */
#define COPY_PARTS 16
#define COPY_MIN 65536

struct copy_part {
	const bvhlab_aabb *src;
	sah_prim *dst;
	uint32_t from, to;
	bvhlab_aabb cbox; /* centroid bounds of the part */
};

struct copy {
	team tm;
	struct copy_part part[COPY_PARTS];
	uint32_t parts;
};

/* Copies records [from, to) in id order and gathers their centroid
 * bounds (the kernel's centroids, see sah_prim). */
static void copy_part(struct copy_part *c)
{
	bvhlab_aabb_empty(&c->cbox);
	for (uint32_t i = c->from; i < c->to; i++) {
		sah_prim *p = &c->dst[i];
		for (int k = 0; k < 3; k++) {
			p->lo[k] = c->src[i].lo[k];
			p->hi[k] = c->src[i].hi[k];
		}
		p->id = i;
		p->pad = 0;
		box_grow_centroid(&c->cbox, p);
	}
}

/* Member t copies parts t, t + T, ...: a team smaller than asked (a thread
 * that could not start) still copies every part. */
static void copy_member(void *arg, unsigned t)
{
	struct copy *c = arg;

	for (uint32_t p = t; p < c->parts; p += c->tm.threads)
		copy_part(&c->part[p]);
}

/* Min/max of the parts' bounds, in part order: the same whatever the parts. */
static void merge_parts(sah_builder *b, const struct copy *c)
{
	bvhlab_aabb_empty(&b->root_cbox);
	for (uint32_t t = 0; t < c->parts; t++)
		bvhlab_aabb_grow(&b->root_cbox, &c->part[t].cbox);
}

void sah_copy_prims(sah_builder *b, const bvhlab_build_input *input, sah_prim *dst)
{
	uint32_t n = b->prim_count, parts = input->threads ? input->threads : 1;
	struct copy c;

	if (parts > COPY_PARTS)
		parts = COPY_PARTS;
	if (parts > n / COPY_MIN)
		parts = n / COPY_MIN ? n / COPY_MIN : 1;
	c.parts = parts;
	for (uint32_t t = 0; t < parts; t++)
		c.part[t] = (struct copy_part){ .src = input->prim_bounds, .dst = dst,
		                                .from = (uint32_t)((uint64_t)n * t / parts),
		                                .to = (uint32_t)((uint64_t)n * (t + 1) / parts) };
	/* One part, or no barrier to be had: this thread copies them all. */
	if (parts == 1 || team_run_on(&c.tm, b->th, parts, copy_member, &c) < 0) {
		for (uint32_t t = 0; t < parts; t++)
			copy_part(&c.part[t]);
	}
	merge_parts(b, &c);
}
