/*
 * Large scratch arrays for plugins (the SAH kernel's working arrays,
 * lbvh's fallback scratch): private mappings asking for transparent huge
 * pages, so that a build takes one page fault per 2 MiB instead of one per
 * 4 KiB (first touches are a large part of a build), and gives its memory
 * back whole. Zero-filled, 64-byte aligned or better. Also the room a
 * builder asks for past its tree in the output, for scratch the host
 * keeps between builds. A static library
 * linked into each plugin that uses it; nothing here is exported.
 */
#ifndef BVHLAB_BIG_ALLOC_H
#define BVHLAB_BIG_ALLOC_H

#include <stddef.h>
#include <stdint.h>

#include <bvhlab/builder.h>

/* size bytes, or NULL when the mapping fails. */
void *big_alloc(size_t size);
/* Unmaps what big_alloc returned; big_free(NULL) does nothing. */
void big_free(void *p);

/*
 * Scratch the host keeps: nodes for `bytes` past a tree of n primitives
 * (2n - 1 nodes) in the output, which the host keeps between builds, where
 * a fresh mapping would be paged in (and zeroed by the kernel) at every
 * build. 0 when the count would not fit a uint32_t.
 */
uint32_t big_spare_nodes(uint32_t n, size_t bytes);

/* Room for the tree of n primitives, asking for `spare` nodes more (fine
 * if refused): 0, or -ENOMEM after host->set_error. */
int big_ensure_output(const bvhlab_host *host, bvhlab_build_ctx *ctx, uint32_t n,
                      uint32_t spare, bvhlab_build_output *out);

#endif /* BVHLAB_BIG_ALLOC_H */
