/*
 * The copy of the input boxes into the kernel's working arrays, which a
 * parallel build shares out among its threads (a serial copy of a million
 * records would cap its speedup).
 */
#include <pthread.h>
#include <stdbool.h>

#include "sah_box.h"
#include "sah_split.h"

/* Most threads the copy uses, and fewest records each. */
#define COPY_PARTS 16
#define COPY_MIN 65536

struct copy_part {
	const bvhlab_aabb *src;
	sah_prim *dst;
	uint32_t from, to;
	bvhlab_aabb cbox; /* centroid bounds of the part */
	pthread_t tid;
	bool started;
};

/* Copies records [from, to) in id order and gathers their centroid
 * bounds (the kernel's centroids, see sah_prim). */
static void *copy_part(void *arg)
{
	struct copy_part *c = arg;

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
	return NULL;
}

/* Min/max of the parts' bounds: the same whatever the parts. */
static void merge_parts(sah_builder *b, struct copy_part *part, uint32_t parts)
{
	bvhlab_aabb_empty(&b->root_cbox);
	for (uint32_t t = 0; t < parts; t++) {
		if (part[t].started)
			pthread_join(part[t].tid, NULL);
		bvhlab_aabb_grow(&b->root_cbox, &part[t].cbox);
	}
}

void sah_copy_prims(sah_builder *b, const bvhlab_build_input *input, sah_prim *dst)
{
	uint32_t n = b->prim_count, parts = input->threads ? input->threads : 1;
	struct copy_part part[COPY_PARTS];

	if (parts > COPY_PARTS)
		parts = COPY_PARTS;
	if (parts > n / COPY_MIN)
		parts = n / COPY_MIN ? n / COPY_MIN : 1;
	for (uint32_t t = 0; t < parts; t++) {
		part[t] = (struct copy_part){ .src = input->prim_bounds, .dst = dst,
		                              .from = (uint32_t)((uint64_t)n * t / parts),
		                              .to = (uint32_t)((uint64_t)n * (t + 1) / parts) };
		/* A part whose thread cannot start is copied here instead. */
		if (t > 0)
			part[t].started = pthread_create(&part[t].tid, NULL, copy_part, &part[t]) == 0;
	}
	for (uint32_t t = 0; t < parts; t++)
		if (!part[t].started)
			copy_part(&part[t]);
	merge_parts(b, part, parts);
}
