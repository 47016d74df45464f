/*
 * The kernel's working arrays: their memory, and the copy of the input
 * boxes into them, which a parallel build shares out among its threads
 * (a serial copy of a million records would cap its speedup).
 */
#include <pthread.h>
#include <stdbool.h>
#include <sys/mman.h>

#include "sah_internal.h"

#define HUGE_PAGE ((size_t)2 << 20)
#define BIG_HEADER 64

/*
 * The working arrays are tens of megabytes, allocated anew by every build:
 * from malloc they are fresh 4 KiB pages whose faults cost as much as a
 * tree level. A private mapping asking for transparent huge pages takes
 * one fault per 2 MiB instead (where the system allows it; else the same
 * as malloc). The mapping's start and length sit just below the pointer.
 */
void *sah_big_alloc(size_t size)
{
	size_t len = (size + BIG_HEADER + 2 * HUGE_PAGE - 1) & ~(HUGE_PAGE - 1);
	char *base = mmap(NULL, len, PROT_READ | PROT_WRITE, MAP_PRIVATE | MAP_ANONYMOUS, -1, 0);

	if (base == MAP_FAILED)
		return NULL;
#ifdef MADV_HUGEPAGE
	(void)madvise(base, len, MADV_HUGEPAGE); /* a hint; fine if refused */
#endif
	uintptr_t at = ((uintptr_t)base + BIG_HEADER + HUGE_PAGE - 1) & ~(uintptr_t)(HUGE_PAGE - 1);
	size_t *header = (size_t *)(void *)(at - BIG_HEADER);
	header[0] = (uintptr_t)base;
	header[1] = len;
	return (void *)at;
}

void sah_big_free(void *p)
{
	if (!p)
		return;
	const size_t *header = (const size_t *)(const void *)((char *)p - BIG_HEADER);
	munmap((void *)(uintptr_t)header[0], header[1]);
}

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

	box_empty(&c->cbox);
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
	box_empty(&b->root_cbox);
	for (uint32_t t = 0; t < parts; t++) {
		if (part[t].started)
			pthread_join(part[t].tid, NULL);
		box_grow(&b->root_cbox, &part[t].cbox);
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
