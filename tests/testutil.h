/*
 * Minimal assertion helpers for bvhlab's tests. A failed check prints the
 * file, line and expression and makes the test exit 1 at the end of main
 * (via test_finish), so one run reports every failure.
 */
#ifndef BVHLAB_TESTUTIL_H
#define BVHLAB_TESTUTIL_H

#include <stdio.h>
#include <stdlib.h>
#include <string.h>

static int test_failures;

#define CHECK(expr) \
	do { \
		if (!(expr)) { \
			fprintf(stderr, "%s:%d: CHECK failed: %s\n", __FILE__, __LINE__, #expr); \
			test_failures++; \
		} \
	} while (0)

#define CHECK_INT(a, b) \
	do { \
		long long a_ = (long long)(a), b_ = (long long)(b); \
		if (a_ != b_) { \
			fprintf(stderr, "%s:%d: %s == %s failed: %lld != %lld\n", __FILE__, \
			        __LINE__, #a, #b, a_, b_); \
			test_failures++; \
		} \
	} while (0)

/* Checks that `text` contains `needle` (error messages are checked this way). */
#define CHECK_CONTAINS(text, needle) \
	do { \
		const char *t_ = (text), *n_ = (needle); \
		if (!t_ || !strstr(t_, n_)) { \
			fprintf(stderr, "%s:%d: expected \"%s\" in \"%s\"\n", __FILE__, __LINE__, \
			        n_, t_ ? t_ : "(null)"); \
			test_failures++; \
		} \
	} while (0)

static inline int test_finish(void)
{
	if (test_failures)
		fprintf(stderr, "%d check(s) failed\n", test_failures);
	return test_failures ? 1 : 0;
}

/* 1 in a ThreadSanitizer build (GCC defines the first, Clang the second). */
#if defined(__SANITIZE_THREAD__)
#define UNDER_TSAN 1
#elif defined(__has_feature)
#if __has_feature(thread_sanitizer)
#define UNDER_TSAN 1
#endif
#endif
#ifndef UNDER_TSAN
#define UNDER_TSAN 0
#endif

/* 1 in an AddressSanitizer build. */
#if defined(__SANITIZE_ADDRESS__)
#define UNDER_ASAN 1
#elif defined(__has_feature)
#if __has_feature(address_sanitizer)
#define UNDER_ASAN 1
#endif
#endif
#ifndef UNDER_ASAN
#define UNDER_ASAN 0
#endif

/*
 * TSan runs ~10x slower and ASan ~3x, and their builds exist to find races
 * and memory errors, which small inputs of the same shapes reach: tests
 * shrink their generated scenes, repeats and shared meshes there, while the
 * release build keeps the full sizes (the suite must stay well under 15 min
 * on a 2-core CI machine).
 */
#define UNDER_SANITIZER (UNDER_TSAN || UNDER_ASAN)
#define SCALE(full, small) (UNDER_SANITIZER ? (small) : (full))

/* Exit code meson treats as "skipped". */
#define TEST_SKIP 77

#endif /* BVHLAB_TESTUTIL_H */
