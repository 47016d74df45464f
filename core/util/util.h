/* Small helpers private to the core. */
#ifndef BVHLAB_CORE_UTIL_H
#define BVHLAB_CORE_UTIL_H

#include <stdarg.h>
#include <stdbool.h>
#include <stddef.h>
#include <stdint.h>

#include <bvhlab/types.h>

#if defined(__GNUC__)
#define UTIL_PRINTF(a, b) __attribute__((format(printf, a, b)))
#else
#define UTIL_PRINTF(a, b)
#endif

/* printf into err->message (truncated with "..." if it must be); NULL err is fine. */
void error_set(bvhlab_error *err, const char *fmt, ...) UTIL_PRINTF(2, 3);
void error_setv(bvhlab_error *err, const char *fmt, va_list ap);
/* Prepends "prefix: " to the message already in err. */
void error_prefix(bvhlab_error *err, const char *fmt, ...) UTIL_PRINTF(2, 3);

/* A growable string; a failed allocation sticks (failed = true). */
struct strbuf {
	char *data;
	size_t len, cap;
	bool failed;
};

void sb_printf(struct strbuf *sb, const char *fmt, ...) UTIL_PRINTF(2, 3);
/* Returns the text (caller frees), or NULL if any append failed. */
char *sb_take(struct strbuf *sb);

/* The whole file at path into *out (caller frees; NULL on failure): 0, or
 * -errno with *why saying what went wrong ("read error", "out of memory",
 * or fopen's strerror). */
int util_read_text(const char *path, char **out, const char **why);

/* splitmix64: the core's one seeded generator, so every random choice
 * (generators, sampled rays) is reproducible from a seed. */
static inline uint64_t util_splitmix64(uint64_t *state)
{
	uint64_t z = (*state += 0x9e3779b97f4a7c15ull);
	z = (z ^ (z >> 30)) * 0xbf58476d1ce4e5b9ull;
	z = (z ^ (z >> 27)) * 0x94d049bb133111ebull;
	return z ^ (z >> 31);
}

/* The path with "." components and "dir/.." pairs removed, lexically
 * (symbolic links are not looked at): "configs/../../shared/x.obj" becomes
 * "../shared/x.obj". malloc'd, or NULL when out of memory. */
char *util_path_normalise(const char *path);
/* A path the config resolved against its folder dir, as the reports show
 * it: relative to that folder again, normalised. malloc'd, or NULL. */
char *util_path_shown(const char *dir, const char *path);
/* A file pattern (one %d) joined to a folder: every '%' of its first
 * `head` bytes (the folder, no part of the pattern) doubled. Takes s;
 * NULL when out of memory. */
char *util_pattern_folder(char *s, size_t head);

/* Monotonic clock in seconds. */
double util_now(void);

/* The same clock in milliseconds, for messages and test reports. */
static inline double util_now_ms(void)
{
	return util_now() * 1e3;
}

/*
 * count x size bytes, freed with free(); NULL when out of memory or when
 * the product overflows. Under 2 MiB aligned to a cache line; from 2 MiB
 * aligned to 2 MiB and asked for transparent huge pages (a hint), for
 * arrays read in no order: the traversals' wide copies, and the primitive
 * boxes that Morton builders gather in sorted order. On 4 KiB pages an
 * array of hundreds of MiB misses the TLB at almost every such read.
 */
void *util_big_alloc(size_t count, size_t size);

/* Median, min and max of n samples (sorts a copy); all 0 when n is 0. */
void util_summarise(const double *samples, uint32_t n, double *median, double *min,
                    double *max);

#endif
