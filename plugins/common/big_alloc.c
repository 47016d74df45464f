/* Huge-page scratch mappings (see big_alloc.h). */
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
