/*
 * Large scratch arrays for plugins (the SAH kernel's working arrays,
 * lbvh's fallback scratch): private mappings asking for transparent huge
 * pages, so that a build takes one page fault per 2 MiB instead of one per
 * 4 KiB (first touches are a large part of a build), and gives its memory
 * back whole. Zero-filled, 64-byte aligned or better. A static library
 * linked into each plugin that uses it; nothing here is exported.
 */
#ifndef BVHLAB_BIG_ALLOC_H
#define BVHLAB_BIG_ALLOC_H

#include <stddef.h>

/* size bytes, or NULL when the mapping fails. */
void *big_alloc(size_t size);
/* Unmaps what big_alloc returned; big_free(NULL) does nothing. */
void big_free(void *p);

#endif /* BVHLAB_BIG_ALLOC_H */
