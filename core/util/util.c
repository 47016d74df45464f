/*
 * Error text, strings, the clock, sample statistics and large arrays shared
 * by the core's modules.
 */
#include <errno.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <time.h>

#include <sys/mman.h>

#include "util/util.h"

void error_setv(bvhlab_error *err, const char *fmt, va_list ap)
{
	if (!err)
		return;
	int n = vsnprintf(err->message, sizeof(err->message), fmt, ap);
	/* Say so when a message did not fit rather than cutting it silently. */
	if (n >= (int)sizeof(err->message))
		memcpy(err->message + sizeof(err->message) - 4, "...", 4);
}

void error_set(bvhlab_error *err, const char *fmt, ...)
{
	va_list ap;
	va_start(ap, fmt);
	error_setv(err, fmt, ap);
	va_end(ap);
}

void error_prefix(bvhlab_error *err, const char *fmt, ...)
{
	if (!err)
		return;
	char prefix[256], old[sizeof(err->message)];
	va_list ap;
	va_start(ap, fmt);
	vsnprintf(prefix, sizeof(prefix), fmt, ap);
	va_end(ap);
	memcpy(old, err->message, sizeof(old));
	error_set(err, "%s: %s", prefix, old);
}

int util_read_text(const char *path, char **out, const char **why)
{
	FILE *f = fopen(path, "rb");
	*out = NULL;
	if (!f) {
		int e = errno;
		*why = strerror(e);
		return -e;
	}
	struct strbuf sb = {0};
	char chunk[65536];
	size_t n;
	while ((n = fread(chunk, 1, sizeof(chunk), f)) > 0)
		sb_printf(&sb, "%.*s", (int)n, chunk);
	bool failed = ferror(f);
	fclose(f);
	*out = sb_take(&sb);
	if (failed || !*out) {
		free(*out);
		*out = NULL;
		*why = failed ? "read error" : "out of memory";
		return failed ? -EIO : -ENOMEM;
	}
	return 0;
}

double util_now(void)
{
	struct timespec ts;
	clock_gettime(CLOCK_MONOTONIC, &ts);
	return (double)ts.tv_sec + (double)ts.tv_nsec * 1e-9;
}

static bool sb_reserve(struct strbuf *sb, size_t extra)
{
	if (sb->len + extra + 1 <= sb->cap)
		return true;
	size_t cap = sb->cap ? sb->cap : 256;
	while (cap < sb->len + extra + 1)
		cap *= 2;
	char *data = realloc(sb->data, cap);
	if (!data)
		return false;
	sb->data = data;
	sb->cap = cap;
	return true;
}

void sb_printf(struct strbuf *sb, const char *fmt, ...)
{
	if (sb->failed)
		return;
	va_list ap;
	va_start(ap, fmt);
	int n = vsnprintf(NULL, 0, fmt, ap);
	va_end(ap);
	if (n < 0 || !sb_reserve(sb, (size_t)n)) {
		sb->failed = true;
		return;
	}
	va_start(ap, fmt);
	vsnprintf(sb->data + sb->len, (size_t)n + 1, fmt, ap);
	va_end(ap);
	sb->len += (size_t)n;
}

char *sb_take(struct strbuf *sb)
{
	if (sb->failed || !sb_reserve(sb, 0)) {
		free(sb->data);
		*sb = (struct strbuf){0};
		return NULL;
	}
	char *text = sb->data;
	text[sb->len] = '\0';
	*sb = (struct strbuf){0};
	return text;
}

static int cmp_double(const void *a, const void *b)
{
	double x = *(const double *)a, y = *(const double *)b;
	return (x > y) - (x < y);
}

void util_summarise(const double *samples, uint32_t n, double *median, double *min,
                       double *max)
{
	double sorted[n ? n : 1];
	memcpy(sorted, samples, n * sizeof(double));
	qsort(sorted, n, sizeof(double), cmp_double);
	*min = n ? sorted[0] : 0;
	*max = n ? sorted[n - 1] : 0;
	*median = n == 0 ? 0 : n % 2 ? sorted[n / 2] : 0.5 * (sorted[n / 2 - 1] + sorted[n / 2]);
}

char *util_path_normalise(const char *path)
{
	size_t len = strlen(path), n = 0, kept = 0;
	char *out = malloc(len + 2);
	bool abs = path[0] == '/';
	if (!out)
		return NULL;
	if (abs)
		out[n++] = '/';
	for (const char *p = path; *p;) {
		size_t c = strcspn(p, "/");
		if (c == 2 && p[0] == '.' && p[1] == '.' && kept > 0) {
			/* Drop the last kept component (and its slash). */
			while (n > (abs ? 1u : 0u) && out[n - 1] != '/')
				n--;
			if (n > (abs ? 1u : 0u))
				n--;
			kept--;
		} else if (!(c == 0 || (c == 1 && p[0] == '.') || (c == 2 && abs && n == 1 &&
		                                                    p[0] == '.' && p[1] == '.'))) {
			if (n > (abs ? 1u : 0u))
				out[n++] = '/';
			memcpy(out + n, p, c);
			n += c;
			/* A leading ".." of a relative path cannot be dropped later. */
			kept += !(c == 2 && p[0] == '.' && p[1] == '.');
		}
		p += c + (p[c] == '/');
	}
	if (n == 0)
		out[n++] = '.';
	out[n] = '\0';
	return out;
}

char *util_pattern_folder(char *s, size_t head)
{
	size_t n = strlen(s), extra = 0;
	for (size_t k = 0; k < head; k++)
		extra += s[k] == '%';
	char *out = extra ? malloc(n + extra + 1) : s;
	for (size_t k = 0, j = 0; extra && out && k <= n; k++) {
		if (k < head && s[k] == '%')
			out[j++] = '%';
		out[j++] = s[k];
	}
	if (out != s)
		free(s);
	return out;
}

char *util_path_shown(const char *dir, const char *path)
{
	size_t n = strlen(dir);
	if (path[0] != '/' && strncmp(path, dir, n) == 0 && path[n] == '/')
		path += n + 1;
	return util_path_normalise(path);
}

void *util_big_alloc(size_t count, size_t size)
{
	const size_t line = 64, huge = (size_t)2 << 20;
	void *mem = NULL;
	if (count == 0)
		count = 1;
	if (size == 0 || count > SIZE_MAX / size)
		return NULL;
	size_t bytes = count * size;
	if (bytes < huge)
		return posix_memalign(&mem, line, bytes) == 0 ? mem : NULL;
	if (bytes > SIZE_MAX - huge)
		return NULL;
	bytes = (bytes + huge - 1) / huge * huge;
	if (posix_memalign(&mem, huge, bytes) != 0)
		return NULL;
	(void)madvise(mem, bytes, MADV_HUGEPAGE);
	return mem;
}
