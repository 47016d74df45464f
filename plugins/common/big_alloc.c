/* Huge-page scratch mappings (see big_alloc.h). */
#include <errno.h>
#include <stdint.h>
#include <sys/mman.h>

#include "big_alloc.h"

#define HUGE_PAGE ((size_t)2 << 20)
#define BIG_HEADER 64

/* The mapping starts on a huge-page boundary after a header that keeps its
 * base and length, just below the pointer, for big_free. */
void *big_alloc(size_t size)
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

void big_free(void *p)
{
	if (!p)
		return;
	const size_t *header = (const size_t *)(const void *)((char *)p - BIG_HEADER);
	munmap((void *)(uintptr_t)header[0], header[1]);
}

uint32_t big_spare_nodes(uint32_t n, size_t bytes)
{
	uint64_t spare = (bytes + 64 + sizeof(bvhlab_node) - 1) / sizeof(bvhlab_node);

	return 2 * (uint64_t)n - 1 + spare > UINT32_MAX ? 0 : (uint32_t)spare;
}

int big_ensure_output(const bvhlab_host *host, bvhlab_build_ctx *ctx, uint32_t n,
                      uint32_t spare, bvhlab_build_output *out)
{
	uint32_t nodes = 2 * n - 1;

	if (spare && out->node_capacity < nodes + spare)
		(void)host->grow_output(ctx, out, nodes + spare, n); /* fine if refused */
	if (out->node_capacity >= nodes && out->index_capacity >= n)
		return 0;
	if (host->grow_output(ctx, out, nodes, n) < 0) {
		host->set_error(ctx, "cannot grow the output to %u nodes", nodes);
		return -ENOMEM;
	}
	return 0;
}
