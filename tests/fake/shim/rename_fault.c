/*
 * An LD_PRELOAD shim for the crash-safety test: the process is killed
 * (SIGKILL, as by the OOM killer or a power cut, no handler runs) just
 * before its Nth rename onto a file named results.json, N from
 * $BVHLAB_FAULT_RENAME. At that moment the new document is complete in its
 * temporary file and not yet in place: results.json must still be the
 * previous complete one. A writer that writes results.json in place never
 * renames, is never killed, and the test sees that. $BVHLAB_FAULT_TO names
 * another target (the end of its path), for renames and links alike.
 */
#include <dlfcn.h>
#include <errno.h>
#include <signal.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <unistd.h>

static int renames;

static int ends_with(const char *s, const char *tail)
{
	size_t n = strlen(s), m = strlen(tail);
	return n >= m && strcmp(s + n - m, tail) == 0;
}

/* $BVHLAB_FAULT_TO: the end of the target's name (default /results.json).
 * With $BVHLAB_FAULT_FULL the Nth and every later one fails with ENOSPC
 * (a full disk) instead: 1 when it does. */
static int maybe_die(const char *to)
{
	const char *at = getenv("BVHLAB_FAULT_RENAME"), *tail = getenv("BVHLAB_FAULT_TO");
	if (!at || !ends_with(to, tail ? tail : "/results.json"))
		return 0;
	++renames;
	if (getenv("BVHLAB_FAULT_FULL") && renames >= atoi(at)) {
		errno = ENOSPC;
		return 1;
	}
	if (renames == atoi(at))
		kill(getpid(), SIGKILL);
	return 0;
}

__attribute__((visibility("default"))) int rename(const char *from, const char *to)
{
	if (maybe_die(to))
		return -1;
	int (*real)(const char *, const char *);
	void *sym = dlsym(RTLD_NEXT, "rename");
	memcpy(&real, &sym, sizeof(real));
	return real(from, to);
}

/* Moving aside (--force) links files to their new names. */
__attribute__((visibility("default"))) int link(const char *from, const char *to)
{
	if (maybe_die(to))
		return -1;
	int (*real)(const char *, const char *);
	void *sym = dlsym(RTLD_NEXT, "link");
	memcpy(&real, &sym, sizeof(real));
	return real(from, to);
}
