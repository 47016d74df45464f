/*
 * Plugins that never get as far as a build: one crashes in a library
 * constructor (at dlopen), one in its entry point, one hangs in it. They
 * live in a folder of their own, off the tests' search path, so that
 * `bvhlab list` and the name lookups of other tests never load them.
 */
#include <stdlib.h>

#include <bvhlab/builder.h>

/* A real signal, not a sanitizer report: the host must see the crash. */
__attribute__((no_sanitize("address", "undefined"))) static void segfault(void)
{
	volatile int *volatile p = NULL;
	*p = 1;
}

#ifdef CRASH_IN_CONSTRUCTOR
__attribute__((constructor)) static void on_load(void)
{
	segfault();
}
#endif

BVHLAB_PLUGIN_ENTRY
{
	(void)host_abi_major;
#ifdef HANG_IN_ENTRY
	for (volatile unsigned long n = 0;; n++)
		;
#endif
	segfault();
	return NULL;
}
